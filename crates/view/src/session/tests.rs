//! A tab's life: the latest request rendered and stale ones dropped, a
//! frame superseded or its tab closed stopped, a frame beyond the memory
//! limit refused with the reason; and the helpers the other tests of the
//! session share (a plain [`Reproduce`], a small view, requests).

use super::*;
use crate::ledger::Costs;
use crate::mailbox::Slot;
use crate::protocol::Quality;
use crate::reproduce::Reproduction;
use crate::state::ViewState;
use volray_core::RenderSettings;
use volray_core::glam::DVec3;

/// Something done on the renderer's thread between taking a request
/// and rendering it.
type Meanwhile = Box<dyn FnOnce() + Send>;

/// Renders states with the library's defaults and their camera; the
/// first state whose azimuth is `meanwhile`'s runs its closure while
/// being reproduced, after its request was taken and before its
/// frame is rendered: what a page does during a frame, without a race.
#[derive(Default)]
pub(super) struct Plain {
    pub(super) meanwhile: std::sync::Mutex<Option<(f64, Meanwhile)>>,
}

impl Reproduce for Plain {
    fn reproduce(&self, state: &ViewState) -> Result<Reproduction, Refusal> {
        if state.zoom > 100.0 {
            return Err(Refusal("too close".into()));
        }
        let mut meanwhile = self.meanwhile.lock().unwrap();
        if meanwhile.as_ref().is_some_and(|(a, _)| *a == state.azimuth) {
            let (_, act) = meanwhile.take().unwrap();
            act();
        }
        let mut settings = RenderSettings {
            width: state.width,
            height: state.height,
            ..RenderSettings::default()
        };
        settings.camera.azimuth = state.azimuth;
        Ok(Reproduction {
            settings,
            command: format!("render --azimuth {}", state.azimuth),
            tf_file: None,
            scene: None,
        })
    }
}

pub(super) fn shared() -> Shared {
    shared_with(Arc::new(Plain::default()), u128::MAX, 1)
}

/// A view of 17³ voxels with `reproduce`, a memory limit and a most
/// tabs.
pub(super) fn shared_with(reproduce: Arc<Plain>, limit: u128, max_sessions: usize) -> Shared {
    let n = 17;
    let h = 2.0 / (n - 1) as f64;
    let volume = Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
        (1.0 - p.length()).max(0.0) as f32
    })
    .unwrap();
    let start = RenderSettings::default();
    let cache_budget = 1 << 20;
    let costs = Costs::new(&volume, &start, NonFinite::Refuse, cache_budget);
    Shared {
        volume: Arc::new(volume),
        non_finite: NonFinite::Refuse,
        cache_budget,
        reproduce,
        pool: Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap(),
        ),
        stats: Arc::new(Stats::default()),
        max_sessions,
        ledger: Ledger::new(limit),
        costs,
        levels: None,
        others: Vec::new(),
        time: None,
        figure: Arc::new(FigureContext::default()),
        copy_above: usize::MAX,
        watch: None,
    }
}

/// A view request for a `side`² frame at `azimuth`.
pub(super) fn request(seq: u64, quality: Quality, side: usize, azimuth: f64) -> Request {
    let mut state = ViewState::default();
    (state.width, state.height, state.azimuth) = (side, side, azimuth);
    Request {
        seq,
        quality,
        state,
        draft_scale: crate::protocol::DRAFT_SCALE,
        probe: None,
    }
}

pub(super) fn header(message: &[u8]) -> serde_json::Value {
    let n = u32::from_le_bytes(message[..4].try_into().unwrap()) as usize;
    serde_json::from_slice(&message[4..4 + n]).unwrap()
}

#[test]
fn the_latest_request_is_rendered_and_stale_ones_are_dropped() {
    let shared = shared();
    let mailbox = Arc::new(Mailbox::default());
    let (tx, mut rx) = mpsc::channel(1);
    // A burst before the renderer starts: only the last is rendered.
    for seq in 0..1000 {
        let state = ViewState {
            width: 32,
            height: 32,
            azimuth: seq as f64,
            ..ViewState::default()
        };
        let quality = if seq == 999 {
            Quality::Full
        } else {
            Quality::Draft
        };
        mailbox.put(
            Slot::Latest,
            Request {
                seq,
                quality,
                state,
                draft_scale: crate::protocol::DRAFT_SCALE,
                probe: None,
            },
        );
    }
    spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
    // One renderer at most: a second tab is refused.
    let refused = spawn(&shared, Arc::new(Mailbox::default()), mpsc::channel(1).0);
    assert!(matches!(refused, Err(SpawnError::TooMany(1))));
    let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
        panic!("no frame")
    };
    let h = header(&message);
    assert_eq!(h["seq"], 999);
    assert_eq!(h["quality"], "full");
    assert_eq!(h["mime"], "image/png");
    assert_eq!(
        (h["width"].as_u64(), h["height"].as_u64()),
        (Some(32), Some(32))
    );
    assert_eq!(h["command"], "render --azimuth 999");
    assert_eq!(shared.stats.sessions(), 1);

    // A draft is half size, a JPEG; a refusal is an error naming the seq.
    let mut state = ViewState {
        width: 33,
        ..ViewState::default()
    };
    mailbox.put(
        Slot::Latest,
        Request {
            seq: 1000,
            quality: Quality::Draft,
            state: state.clone(),
            draft_scale: crate::protocol::DRAFT_SCALE,
            probe: None,
        },
    );
    let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
        panic!("no frame")
    };
    let h = header(&message);
    assert_eq!(
        (h["width"].as_u64(), h["mime"].as_str()),
        (Some(17), Some("image/jpeg"))
    );
    state.zoom = 200.0;
    mailbox.put(
        Slot::Latest,
        Request {
            seq: 1001,
            quality: Quality::Full,
            state,
            draft_scale: crate::protocol::DRAFT_SCALE,
            probe: None,
        },
    );
    let Some(Outgoing::Text(text)) = rx.blocking_recv() else {
        panic!("no error")
    };
    assert_eq!(text, r#"{"type":"error","seq":1001,"message":"too close"}"#);

    // Closing the mailbox ends the thread and frees the tab.
    mailbox.close();
    assert!(rx.blocking_recv().is_none());
    assert_eq!(shared.stats.sessions(), 0);
    assert_eq!(shared.stats.frames(), 2);
    assert_eq!(shared.stats.dropped(), 999);
    assert_eq!(shared.ledger.held(), 0);
}

#[test]
fn a_frame_superseded_while_it_renders_is_stopped_and_the_newer_one_sent() {
    let plain = Arc::new(Plain::default());
    let shared = shared_with(Arc::clone(&plain), u128::MAX, 1);
    let mailbox = Arc::new(Mailbox::default());
    // While the first frame is about to render, the page asks for
    // another view.
    let page = Arc::clone(&mailbox);
    *plain.meanwhile.lock().unwrap() = Some((
        1.0,
        Box::new(move || page.put(Slot::Latest, request(2, Quality::Full, 48, 2.0))),
    ));
    mailbox.put(Slot::Latest, request(1, Quality::Full, 48, 1.0));
    let (tx, mut rx) = mpsc::channel(1);
    spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
    let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
        panic!("no frame")
    };
    // The first frame was stopped, not sent: the next is the newer.
    assert_eq!(header(&message)["seq"], 2);
    assert_eq!(shared.stats.stopped(), 1);
    assert_eq!(shared.stats.frames(), 1);
    mailbox.close();
    assert!(rx.blocking_recv().is_none());
    let status = shared.stats.snapshot(&shared.ledger);
    assert_eq!((status.sessions, status.rendering), (0, 0));
}

#[test]
fn closing_the_tab_stops_its_frame_and_frees_its_renderer() {
    let plain = Arc::new(Plain::default());
    let shared = shared_with(Arc::clone(&plain), u128::MAX, 1);
    let mailbox = Arc::new(Mailbox::default());
    let page = Arc::clone(&mailbox);
    *plain.meanwhile.lock().unwrap() = Some((1.0, Box::new(move || page.close())));
    mailbox.put(Slot::Latest, request(1, Quality::Full, 48, 1.0));
    let (tx, mut rx) = mpsc::channel(1);
    spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
    // The frame is stopped, nothing is sent, and the thread ends.
    assert!(rx.blocking_recv().is_none());
    let status = shared.stats.snapshot(&shared.ledger);
    assert_eq!(
        (
            status.sessions,
            status.rendering,
            status.frames,
            status.stopped
        ),
        (0, 0, 0, 1)
    );
    assert_eq!(shared.ledger.held(), 0);
}

#[test]
fn a_frame_that_does_not_fit_beside_the_other_tabs_is_refused_with_the_reason() {
    let probe = shared();
    let big = RenderSettings {
        width: 200,
        height: 200,
        ..RenderSettings::default()
    };
    let (frame, message) = probe.costs.frame(&probe.volume, &big);
    // Two renderers and one frame fit, but not a second frame beside
    // the first one's message, not yet sent.
    let limit = 2 * probe.costs.tab + frame + message - 1;
    let shared = shared_with(Arc::new(Plain::default()), limit, 2);
    let (a, b) = (Arc::new(Mailbox::default()), Arc::new(Mailbox::default()));
    let (a_tx, mut a_rx) = mpsc::channel(1);
    let (b_tx, mut b_rx) = mpsc::channel(1);
    spawn(&shared, Arc::clone(&a), a_tx).unwrap();
    spawn(&shared, Arc::clone(&b), b_tx).unwrap();
    a.put(Slot::Latest, request(1, Quality::Full, 200, 0.0));
    let Some(in_flight @ Outgoing::Frame(..)) = a_rx.blocking_recv() else {
        panic!("no frame")
    };
    assert_eq!(shared.ledger.held(), 2 * probe.costs.tab + message);
    b.put(Slot::Latest, request(7, Quality::Full, 200, 0.0));
    let Some(Outgoing::Text(text)) = b_rx.blocking_recv() else {
        panic!("not refused")
    };
    let error: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(error["seq"], 7);
    let reason = error["message"].as_str().unwrap();
    assert!(
        reason.starts_with("a 200x200 frame needs up to ")
            && reason.contains("but the open tabs hold"),
        "{reason}"
    );
    assert_eq!(shared.stats.snapshot(&shared.ledger).refused, 1);
    // Once the first frame is sent, the second fits.
    drop(in_flight);
    b.put(Slot::Latest, request(8, Quality::Full, 200, 0.0));
    assert!(matches!(b_rx.blocking_recv(), Some(Outgoing::Frame(..))));
    // A third tab's renderer does not fit beside two.
    let third = spawn(&shared, Arc::new(Mailbox::default()), mpsc::channel(1).0);
    assert!(matches!(third, Err(SpawnError::TooMany(2))));
    a.close();
    b.close();
    assert!(a_rx.blocking_recv().is_none() && b_rx.blocking_recv().is_none());
    assert_eq!(shared.ledger.held(), 0);
}

/// The frame of `request` from a tab of `shared`: its header and image.
pub(super) fn one_frame(
    mailbox: &Mailbox<Request>,
    rx: &mut mpsc::Receiver<Outgoing>,
    request: Request,
) -> (serde_json::Value, Vec<u8>) {
    mailbox.put(Slot::Latest, request);
    match rx.blocking_recv() {
        Some(Outgoing::Frame(message, _)) => {
            let n = u32::from_le_bytes(message[..4].try_into().unwrap()) as usize;
            (header(&message), message[4 + n..].to_vec())
        }
        Some(Outgoing::Text(text)) => panic!("{text}"),
        None => panic!("no frame"),
    }
}

/// 8-bit RGB pixels of a PNG.
pub(super) fn pixels(png: &[u8]) -> Vec<u8> {
    let mut reader = png::Decoder::new(std::io::Cursor::new(png))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    buf
}
