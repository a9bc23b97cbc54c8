//! A tab whose messages the caller carries (`link.rs`): the frames a page
//! has not acknowledged bounded, their bytes held in the ledger until it
//! does; and a volume its owner changes between frames rendered as it is
//! now (`watch.rs`).

use super::tests::{Plain, header, request, shared_with};
use super::*;
use crate::link::{Host, MAX_IN_FLIGHT, Message};
use crate::watch::Watch;
use std::sync::Mutex;
use std::time::Duration;
use volray_core::glam::DVec3;
use volray_core::{FrameRequest, Render, RenderSettings};

fn host(shared: Shared) -> Host {
    let volume = shared.ledger.reserve("the volume", 0).unwrap();
    Host {
        hello: r#"{"type":"hello"}"#.into(),
        shared,
        volume,
    }
}

/// A view request's JSON, as the page sends it.
fn view(seq: u64, quality: &str, azimuth: f64) -> String {
    let request = request(seq, Quality::Full, 32, azimuth);
    let state = serde_json::to_value(&request.state).unwrap();
    serde_json::json!({"type": "view", "seq": seq, "quality": quality, "state": state}).to_string()
}

fn frame_seq(message: Option<Message>) -> u64 {
    match message {
        Some(Message::Frame(bytes)) => header(&bytes)["seq"].as_u64().unwrap(),
        other => panic!("not a frame: {other:?}"),
    }
}

#[test]
fn a_page_holds_at_most_the_bound_of_frames_unacknowledged_their_bytes_in_the_ledger() {
    let host = host(shared_with(Arc::new(Plain::default()), u128::MAX, 1));
    let tab = Arc::new(host.open().unwrap());
    assert!(matches!(tab.next(), Some(Message::Text(_))), "the hello");
    let idle = host.held();
    // The page asks, takes each frame, and acknowledges none.
    for seq in 0..MAX_IN_FLIGHT as u64 {
        tab.receive(&view(seq, "full", seq as f64)).unwrap();
        assert_eq!(frame_seq(tab.next()), seq);
    }
    assert_eq!(tab.in_flight(), MAX_IN_FLIGHT);
    let held = host.held();
    assert!(held > idle, "the frames' messages held: {held} > {idle}");
    // One more: rendered, but not handed over until one is acknowledged.
    tab.receive(&view(10, "full", 10.0)).unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let taker = Arc::clone(&tab);
    std::thread::spawn(move || tx.send(taker.next()).unwrap());
    // (However long it waits: nothing comes while none is acknowledged.)
    assert!(rx.recv_timeout(Duration::from_millis(300)).is_err());
    assert_eq!(tab.in_flight(), MAX_IN_FLIGHT);
    tab.ack();
    assert_eq!(frame_seq(rx.recv().unwrap()), 10);
    assert_eq!(tab.in_flight(), MAX_IN_FLIGHT);
    // Acknowledged, the frames' bytes are given back.
    tab.ack();
    tab.ack();
    assert_eq!((tab.in_flight(), host.held()), (0, idle));
    // A tab closed while a frame waits for room: `next` ends.
    for seq in 20..20 + MAX_IN_FLIGHT as u64 {
        tab.receive(&view(seq, "full", seq as f64)).unwrap();
        assert_eq!(frame_seq(tab.next()), seq);
    }
    tab.receive(&view(30, "full", 30.0)).unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let taker = Arc::clone(&tab);
    std::thread::spawn(move || tx.send(taker.next()).unwrap());
    tab.close();
    assert_eq!(rx.recv().unwrap(), None);
    assert_eq!(tab.next(), None);
}

/// A volume the test changes between frames: each change a generation.
struct Changing {
    now: Mutex<(u64, Volume)>,
}

impl Watch for Changing {
    fn current(&self, generation: u64) -> Result<Option<(u64, Volume)>, String> {
        let now = self.now.lock().unwrap();
        Ok((now.0 != generation).then(|| now.clone()))
    }
}

/// A 17³ box of zeros, ones within `half` of its centre.
fn cube(half: f64) -> Volume {
    Volume::from_fn([17; 3], DVec3::splat(0.125), DVec3::splat(-1.0), |p| {
        if p.abs().max_element() < half {
            1.0
        } else {
            0.0
        }
    })
    .unwrap()
}

#[test]
fn a_volume_changed_between_frames_is_rendered_as_it_is_now() {
    let mut shared = shared_with(Arc::new(Plain::default()), u128::MAX, 1);
    shared.volume = Arc::new(cube(0.5));
    let changing = Arc::new(Changing {
        now: Mutex::new((0, cube(0.5))),
    });
    let reference = |volume: &Volume| {
        let settings = RenderSettings {
            width: 32,
            height: 32,
            ..RenderSettings::default()
        };
        let image = Renderer::new(volume)
            .unwrap()
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        encode::png(&image, &mut Vec::new()).unwrap()
    };
    let mut host = host(shared);
    host.watch(Arc::clone(&changing) as Arc<dyn Watch>);
    let tab = host.open().unwrap();
    tab.next();
    let png = |message: Option<Message>| match message {
        Some(Message::Frame(bytes)) => {
            let n = u32::from_le_bytes(bytes[..4].try_into().unwrap()) as usize;
            bytes[4 + n..].to_vec()
        }
        other => panic!("not a frame: {other:?}"),
    };
    tab.receive(&view(1, "full", 0.0)).unwrap();
    assert_eq!(png(tab.next()), reference(&cube(0.5)));
    tab.ack();
    // Changed between frames: the next frame shows the change.
    *changing.now.lock().unwrap() = (1, cube(0.25));
    tab.receive(&view(2, "full", 0.0)).unwrap();
    let changed = png(tab.next());
    assert_eq!(changed, reference(&cube(0.25)));
    assert_ne!(changed, reference(&cube(0.5)));
    tab.close();
}
