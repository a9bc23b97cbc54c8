//! One tab's renderer: a thread of its own that owns a
//! [`Renderer`] of the volume (so that the bricks classified for this
//! tab's transfer function are kept from frame to frame, whatever other
//! tabs do), takes the latest request from a single-slot [`Mailbox`],
//! renders it, encodes it, and hands the message to the tab's socket
//! through a channel of one, so that a slow page slows the renderer
//! instead of queueing frames.
//!
//! A frame is rendered with the mailbox's stop flag
//! (`Renderer::render_stoppable`): a newer request for the tab, or the
//! tab closing, stops it within a tile's work, and the thread goes on to
//! the newer request or ends. Before a frame is rendered its bytes are
//! reserved from the server's [`Ledger`]; a frame that does not fit
//! beside what the other tabs hold is answered with the reason, not
//! queued.
//!
//! When the tab goes away the mailbox closes, the thread ends and the
//! renderer with its caches is freed, and its reservation given back.

use crate::encode::{self, DRAFT_QUALITY};
use crate::ledger::{Costs, Ledger, Overdrawn, Reservation};
use crate::mailbox::Mailbox;
use crate::protocol::{Basis, FrameHeader, Quality, Request, ServerMessage, frame_message};
use crate::reproduce::{Refusal, Reproduce};
use crate::stats::Stats;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;
use tokio::sync::mpsc;
use volray_core::camera::View;
use volray_core::{NonFinite, RenderError, RenderSettings, Renderer, Volume};

/// What the renderer thread sends to the tab's socket.
#[derive(Debug)]
pub enum Outgoing {
    /// A frame: header and image, and the bytes reserved for the message
    /// until it is sent.
    Frame(Vec<u8>, Reservation),
    /// A JSON message (an error).
    Text(String),
}

/// What every tab's renderer shares.
pub struct Shared {
    pub volume: Arc<Volume>,
    pub non_finite: NonFinite,
    /// The bytes each tab's renderer may keep in brick caches.
    pub cache_budget: usize,
    pub reproduce: Arc<dyn Reproduce>,
    pub pool: Arc<rayon::ThreadPool>,
    pub stats: Arc<Stats>,
    /// The most tabs rendering at once (each has a thread).
    pub max_sessions: usize,
    /// The memory limit, and what the tabs and frames reserve from it.
    pub ledger: Arc<Ledger>,
    pub costs: Costs,
}

/// A tab that could not be given a renderer.
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("{0} tabs are open, the most this server renders at once: close one and reload")]
    TooMany(usize),
    #[error("{0}")]
    Memory(#[from] Overdrawn),
    #[error("cannot start a renderer thread: {0}")]
    Thread(#[from] std::io::Error),
}

/// A frame that could not be made.
#[derive(Debug, thiserror::Error)]
enum FrameError {
    #[error("{0}")]
    Refused(#[from] Refusal),
    #[error("{0}")]
    Memory(#[from] Overdrawn),
    #[error("{0}")]
    Render(#[from] RenderError),
    #[error("{0}")]
    Encode(#[from] encode::EncodeError),
}

/// Starts a tab's renderer thread, which serves `mailbox` until it closes
/// or the socket's end of `out` goes away; refused when
/// [`Shared::max_sessions`] are running or the tab's renderer does not
/// fit the memory limit beside the others.
pub fn spawn(
    shared: &Shared,
    mailbox: Arc<Mailbox<Request>>,
    out: mpsc::Sender<Outgoing>,
) -> Result<(), SpawnError> {
    let open =
        (shared.stats.open(shared.max_sessions)).ok_or(SpawnError::TooMany(shared.max_sessions))?;
    let held = shared
        .ledger
        .reserve("another tab's renderer", shared.costs.tab)?;
    let volume = Arc::clone(&shared.volume);
    let reproduce = Arc::clone(&shared.reproduce);
    let pool = Arc::clone(&shared.pool);
    let stats = Arc::clone(&shared.stats);
    let ledger = Arc::clone(&shared.ledger);
    let costs = shared.costs;
    let non_finite = shared.non_finite;
    let cache_budget = shared.cache_budget;
    std::thread::Builder::new()
        .name("view-render".into())
        .spawn(move || {
            // Given back when the renderer is freed, after it.
            let (_open, _held) = (open, held);
            let renderer = match Renderer::with_non_finite(&volume, non_finite) {
                Ok(r) => r.with_cache_budget(cache_budget),
                Err(e) => {
                    let message = ServerMessage::Error {
                        seq: None,
                        message: e.to_string(),
                    };
                    let _ = out.blocking_send(Outgoing::Text(message.to_json()));
                    return;
                }
            };
            let tab = Tab {
                renderer,
                reproduce: &*reproduce,
                pool: &pool,
                stats: &stats,
                ledger: &ledger,
                costs,
            };
            while let Some(request) = mailbox.take() {
                let frame = tab.frame(&request, mailbox.stop_flag());
                mailbox.finished();
                let outgoing = match frame {
                    Ok((message, reservation)) => {
                        stats.frame_rendered();
                        Outgoing::Frame(message, reservation)
                    }
                    // Superseded (the newer request is taken next) or
                    // closed (`take` says so): nothing to send.
                    Err(FrameError::Render(RenderError::Stopped)) => {
                        stats.frame_stopped();
                        continue;
                    }
                    Err(e) => {
                        if matches!(e, FrameError::Memory(_)) {
                            stats.frame_refused();
                        }
                        Outgoing::Text(
                            ServerMessage::Error {
                                seq: Some(request.seq),
                                message: e.to_string(),
                            }
                            .to_json(),
                        )
                    }
                };
                if out.blocking_send(outgoing).is_err() {
                    break;
                }
            }
            stats.add_dropped(mailbox.dropped());
        })?;
    Ok(())
}

/// A tab's renderer and what it reports to.
struct Tab<'a> {
    renderer: Renderer<'a>,
    reproduce: &'a dyn Reproduce,
    pool: &'a rayon::ThreadPool,
    stats: &'a Stats,
    ledger: &'a Arc<Ledger>,
    costs: Costs,
}

impl Tab<'_> {
    /// The frame `request` asks for, as a binary message, and the bytes
    /// reserved for the message until it is sent; stopped when `stop` is
    /// set.
    fn frame(
        &self,
        request: &Request,
        stop: &AtomicBool,
    ) -> Result<(Vec<u8>, Reservation), FrameError> {
        let reproduction = self.reproduce.reproduce(&request.state)?;
        let basis = basis(&self.renderer, &reproduction.settings)?;
        let settings = match request.quality {
            Quality::Draft => RenderSettings {
                width: draft_side(reproduction.settings.width),
                height: draft_side(reproduction.settings.height),
                ..reproduction.settings
            },
            Quality::Full | Quality::Save => reproduction.settings,
        };
        let (bytes, message_bytes) = self.costs.frame(self.renderer.volume(), &settings);
        let what = format!("a {}x{} frame", settings.width, settings.height);
        let mut reserved = self.ledger.reserve(&what, bytes)?;
        let start = Instant::now();
        let image = {
            let _rendering = self.stats.rendering();
            let renderer = &self.renderer;
            // A fresh frame buffer each time (not one kept across frames):
            // what a tab holds between frames is then its caches alone.
            self.pool
                .install(|| renderer.render_stoppable(&settings, &|_| {}, stop))?
        };
        let rendered = Instant::now();
        let mut rgb = Vec::new();
        let (mime, bytes) = match request.quality {
            Quality::Draft => ("image/jpeg", encode::jpeg(&image, DRAFT_QUALITY, &mut rgb)?),
            Quality::Full | Quality::Save => ("image/png", encode::png(&image, &mut rgb)?),
        };
        drop((image, rgb));
        let header = FrameHeader {
            seq: request.seq,
            quality: request.quality,
            mime,
            width: settings.width,
            height: settings.height,
            render_ms: (rendered - start).as_secs_f64() * 1e3,
            encode_ms: rendered.elapsed().as_secs_f64() * 1e3,
            command: reproduction.command,
            tf_file: reproduction.tf_file,
            basis,
        };
        // The pixels are given back here; the message's bytes when sent.
        Ok((
            frame_message(&header, &bytes),
            reserved.split_off(message_bytes),
        ))
    }
}

/// A draft frame's side: half the full frame's, at least one pixel.
pub fn draft_side(full: usize) -> usize {
    full.div_ceil(2)
}

/// The screen axes of the full-size view of `settings`, for panning.
fn basis(renderer: &Renderer, settings: &RenderSettings) -> Result<Basis, RenderError> {
    let frame = renderer.prepare(settings)?;
    let (reference, right, up, units_per_pixel) = match frame.view {
        View::Orthographic(v) => (v.centre, v.right, v.up, v.pixel_size),
        View::Perspective(v) => (
            v.reference,
            v.right,
            v.up,
            v.pixel_size * (v.reference - v.eye).length(),
        ),
    };
    Ok(Basis {
        reference: reference.to_array(),
        right: right.to_array(),
        up: up.to_array(),
        pixels_per_unit: 1.0 / units_per_pixel,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mailbox::Slot;
    use crate::protocol::Quality;
    use crate::reproduce::Reproduction;
    use crate::state::ViewState;
    use crate::state::tests::sample;
    use volray_core::glam::DVec3;

    /// Something done on the renderer's thread between taking a request
    /// and rendering it.
    type Meanwhile = Box<dyn FnOnce() + Send>;

    /// Renders states with the library's defaults and their camera; the
    /// first state whose azimuth is `meanwhile`'s runs its closure while
    /// being reproduced, after its request was taken and before its
    /// frame is rendered: what a page does during a frame, without a race.
    #[derive(Default)]
    struct Plain {
        meanwhile: std::sync::Mutex<Option<(f64, Meanwhile)>>,
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
            })
        }
    }

    fn shared() -> Shared {
        shared_with(Arc::new(Plain::default()), u128::MAX, 1)
    }

    /// A view of 17³ voxels with `reproduce`, a memory limit and a most
    /// tabs.
    fn shared_with(reproduce: Arc<Plain>, limit: u128, max_sessions: usize) -> Shared {
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
        }
    }

    /// A view request for a `side`² frame at `azimuth`.
    fn request(seq: u64, quality: Quality, side: usize, azimuth: f64) -> Request {
        let mut state = sample();
        (state.width, state.height, state.azimuth) = (side, side, azimuth);
        Request {
            seq,
            quality,
            state,
        }
    }

    fn header(message: &[u8]) -> serde_json::Value {
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
            let mut state = sample();
            state.width = 32;
            state.height = 32;
            state.azimuth = seq as f64;
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
        let mut state = sample();
        state.width = 33;
        mailbox.put(
            Slot::Latest,
            Request {
                seq: 1000,
                quality: Quality::Draft,
                state: state.clone(),
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

    #[test]
    fn the_basis_spans_the_screen() {
        let shared = shared();
        let renderer = Renderer::new(&shared.volume).unwrap();
        let settings = RenderSettings {
            width: 100,
            height: 100,
            ..RenderSettings::default()
        };
        let b = basis(&renderer, &settings).unwrap();
        // The default view looks along −x: right is +y, up +z; the 2-unit
        // face spans 100 pixels.
        assert_eq!(b.right, [0.0, 1.0, 0.0]);
        assert_eq!(b.up, [0.0, 0.0, 1.0]);
        assert!((b.pixels_per_unit - 50.0).abs() < 1e-9);
        assert!(DVec3::from(b.reference).length() < 1e-12);
    }
}
