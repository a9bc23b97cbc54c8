//! A pyramid's tabs together: a level read whole by one tab keeps no
//! other tab waiting (`levels.rs`), two tabs needing one level read it
//! once, and a draft of a coarse level is framed as the still
//! (`Pyramid::framed`); and a pyramid's tab alone: its drafts from a
//! coarser level held whole, its still from the level auto chooses, in
//! pieces where it does not fit what the limit has left (`pieces.rs`),
//! and a still in pieces superseded before it starts reading nothing.

use super::levels::LevelTab;
use super::pieces::Pieces;
use super::render::Context;
use super::tests::{Plain, header, one_frame, pixels, request, shared_with};
use super::*;
use crate::mailbox::Slot;
use crate::pyramid::{DRAFT_SHARE, Pyramid};
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;
use std::sync::mpsc as std_mpsc;
use std::time::{Duration, Instant};
use volray_core::glam::DVec3;
use volray_core::{Blend, FrameRequest, Image, Render, RenderSettings, VolumeSource};

/// Long enough for any frame here on a busy machine; reached only when
/// a tab waits for what it should not wait for.
const PATIENCE: Duration = Duration::from_secs(60);

/// Holds a whole read of its level until released: says when the read
/// starts, then waits on the channel.
struct Gate {
    entered: std_mpsc::Sender<()>,
    release: Mutex<std_mpsc::Receiver<()>>,
}

/// A level that logs every box read from it, and whose whole reads wait
/// at `gate`, if any.
struct Gated {
    level: usize,
    source: Arc<dyn VolumeSource>,
    reads: Reads,
    gate: Option<Gate>,
}

impl VolumeSource for Gated {
    fn grid(&self) -> volray_core::sampling::grid::GridFrame {
        self.source.grid()
    }
    fn sample_type(&self) -> volray_core::SampleType {
        self.source.sample_type()
    }
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, volray_core::SourceError> {
        self.reads.lock().unwrap().push((self.level, lo, hi));
        if let Some(gate) = self.gate.as_ref().filter(|_| hi == self.grid().dims) {
            gate.entered.send(()).unwrap();
            gate.release.lock().unwrap().recv().unwrap();
        }
        self.source.read_box(lo, hi)
    }
}

/// `volume` written as an OME-Zarr pyramid of `chunk`³ chunks in `dir`.
fn written(dir: &tempfile::TempDir, volume: &Volume, chunk: usize) -> std::path::PathBuf {
    use volray_io::{OmeZarrOptions, write_ome_zarr};
    let path = dir.path().join("image.ome.zarr");
    let options = OmeZarrOptions {
        chunk,
        shard: 2 * chunk,
        ..OmeZarrOptions::default()
    };
    write_ome_zarr(&path, volume, &options).unwrap();
    path
}

/// The `count` levels of the pyramid at `path`, its stills at `still`,
/// level `gated.0`'s whole reads held at the gate; and the log of what
/// its levels read.
fn pyramid(
    path: &std::path::Path,
    count: usize,
    still: Option<usize>,
    mut gated: Option<(usize, Gate)>,
) -> (Pyramid, Reads) {
    let reads = Reads::default();
    let sources = (0..count)
        .map(|level| {
            let opts = volray_io::ReadOptions {
                level: Some(level),
                ..volray_io::ReadOptions::default()
            };
            let lazy = volray_io::open_lazy(path, &opts).unwrap().unwrap();
            let gate = gated.take_if(|(l, _)| *l == level).map(|(_, g)| g);
            Arc::new(Gated {
                level,
                source: lazy.source,
                reads: Arc::clone(&reads),
                gate,
            }) as Arc<dyn VolumeSource>
        })
        .collect();
    (Pyramid::new(sources, still).unwrap(), reads)
}

/// A blob off the centre of a 64³ cube.
fn blob() -> Volume {
    Volume::from_fn([64; 3], DVec3::ONE, DVec3::ZERO, |p| {
        let d = (p - DVec3::new(31.5, 51.5, 43.5)).length();
        (1.0 - d / 7.0).max(0.0) as f32
    })
    .unwrap()
}

/// The next message of a tab, or `None` after [`PATIENCE`].
fn within_patience(rx: &mut mpsc::Receiver<Outgoing>) -> Option<Outgoing> {
    let until = Instant::now() + PATIENCE;
    while Instant::now() < until {
        match rx.try_recv() {
            Ok(message) => return Some(message),
            Err(mpsc::error::TryRecvError::Empty) => std::thread::sleep(Duration::from_millis(5)),
            Err(mpsc::error::TryRecvError::Disconnected) => return None,
        }
    }
    None
}

/// A frame's header, or the text that came instead.
fn frame_header(message: Option<Outgoing>) -> serde_json::Value {
    match message {
        Some(Outgoing::Frame(message, _)) => header(&message),
        Some(Outgoing::Text(text)) => panic!("{text}"),
        None => panic!("no frame"),
    }
}

#[test]
fn a_tabs_draft_is_not_kept_waiting_while_another_tab_reads_a_level_and_that_level_is_read_once() {
    let dir = tempfile::tempdir().unwrap();
    let path = written(&dir, &blob(), 16);
    let (entered_tx, entered) = std_mpsc::channel();
    let (release, release_rx) = std_mpsc::channel();
    let gate = Gate {
        entered: entered_tx,
        release: Mutex::new(release_rx),
    };
    // The stills show level 0, whose whole read waits at the gate.
    let (pyramid, reads) = pyramid(&path, 3, Some(0), Some((0, gate)));
    let mut shared = shared_with(Arc::new(Plain::default()), 1 << 30, 3);
    shared.cache_budget = 0;
    shared.costs = Costs::new(
        &shared.volume,
        &RenderSettings::default(),
        NonFinite::Refuse,
        0,
    );
    let levels = Arc::new(Levels::new(pyramid));
    shared.levels = Some(Arc::clone(&levels));
    let tab = || {
        let mailbox = Arc::new(Mailbox::default());
        let (tx, rx) = mpsc::channel(1);
        spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
        (mailbox, rx)
    };
    let ((a, mut a_rx), (b, mut b_rx), (c, mut c_rx)) = (tab(), tab(), tab());

    // Tab A's still reads level 0 whole: held at the gate.
    a.put(Slot::Latest, request(1, Quality::Full, 64, 30.0));
    entered.recv_timeout(PATIENCE).expect("level 0 read");

    // Meanwhile tab B drafts from a coarser level, read and rendered.
    b.put(Slot::Latest, request(2, Quality::Draft, 64, 30.0));
    let drafted = within_patience(&mut b_rx);
    if drafted.is_none() {
        release.send(()).unwrap();
        panic!("tab B's draft waited for tab A's read of level 0");
    }
    let h = frame_header(drafted);
    assert!(h["level"]["index"].as_u64().unwrap() > 0, "{h}");

    // Tab C's still needs level 0 too: it waits for A's read, not
    // reading it again.
    c.put(Slot::Latest, request(3, Quality::Full, 64, 40.0));
    let until = Instant::now() + PATIENCE;
    while levels.waiting() == 0 && Instant::now() < until {
        std::thread::sleep(Duration::from_millis(5));
    }
    let waited = levels.waiting();
    release.send(()).unwrap();
    assert_eq!(waited, 1, "tab C waits for level 0");
    for (rx, seq) in [(&mut a_rx, 1), (&mut c_rx, 3)] {
        let h = frame_header(within_patience(rx));
        assert_eq!(
            (h["seq"].as_u64(), h["level"]["index"].as_u64()),
            (Some(seq), Some(0))
        );
    }
    let dims = levels.pyramid.grid(0).dims;
    let whole_reads = (reads.lock().unwrap().iter())
        .filter(|(l, lo, hi)| (*l, *lo, *hi) == (0, [0; 3], dims))
        .count();
    assert_eq!(whole_reads, 1, "level 0 read once");
    for mailbox in [a, b, c] {
        mailbox.close();
    }
    for rx in [&mut a_rx, &mut b_rx, &mut c_rx] {
        assert!(rx.blocking_recv().is_none());
    }
}

/// The centre of the image's bright part (over half its brightest), in
/// pixels from the top left.
fn centroid(image: &Image) -> [f64; 2] {
    let brightness = |[r, g, b, _]: [f32; 4]| f64::from(r + g + b);
    let brightest = image
        .pixels()
        .iter()
        .map(|&p| brightness(p))
        .fold(0.0, f64::max);
    let (mut sum, mut x, mut y) = (0.0, 0.0, 0.0);
    for row in 0..image.height() {
        for col in 0..image.width() {
            let w = (brightness(image.get(col, row)) - brightest / 2.0).max(0.0);
            (sum, x, y) = (sum + w, x + w * col as f64, y + w * row as f64);
        }
    }
    assert!(sum > 0.0, "an empty frame");
    [x / sum, y / sum]
}

#[test]
fn a_draft_of_a_coarse_level_is_framed_as_the_still_so_the_picture_does_not_jump_at_mouse_up() {
    // A blob off centre in a 64³ cube of 8³ chunks: levels of 64³ ... 8³,
    // level k's box 2^k − 1 voxels shorter a side than level 0's.
    let dir = tempfile::tempdir().unwrap();
    let path = written(&dir, &blob(), 8);
    let (pyramid, _) = pyramid(&path, 4, Some(0), None);
    assert_eq!(pyramid.len(), 4);
    let levels = Arc::new(Levels::new(pyramid));
    let pyramid = &levels.pyramid;
    // A maximum intensity projection: no light to shift the blob's
    // brightness one way.
    let settings = RenderSettings {
        width: 128,
        height: 128,
        blend: Blend::Maximum,
        ..RenderSettings::default()
    };
    let costs = Costs::new(&read_whole(pyramid, 0), &settings, NonFinite::Refuse, 0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let stats = Stats::default();
    let never = AtomicBool::new(false);
    let draw = |quality, limit| {
        let ledger = Ledger::new(limit);
        let cx = Context {
            pool: &pool,
            stats: &stats,
            ledger: &ledger,
            costs,
            stop: &never,
            what: "a frame",
        };
        let mut tab = LevelTab {
            levels: Arc::clone(&levels),
            renderers: Vec::new(),
            streamed: Pieces::default(),
        };
        tab.draw(&cx, quality, &settings, &settings).unwrap()
    };
    // A memory limit that holds level 3 whole for the drafts, not level 2.
    let nf = NonFinite::Refuse;
    let limit = DRAFT_SHARE * pyramid.whole_bytes(3, &settings, nf);
    assert!(pyramid.whole_bytes(2, &settings, nf) > limit / DRAFT_SHARE);
    let draft = draw(Quality::Draft, limit);
    let still = draw(Quality::Full, u128::MAX);
    let levels_shown = [&draft, &still].map(|d| d.level.as_ref().unwrap().index);
    assert_eq!(levels_shown, [3, 0]);
    // The blob where the still has it, within half a pixel; framed on its
    // own box, level 3 (56 units a side for 63) draws it 5.9 pixels away
    // (measured with the framing undone).
    let [d, s] = [&draft, &still].map(|d| centroid(&d.image));
    let off = ((d[0] - s[0]).powi(2) + (d[1] - s[1]).powi(2)).sqrt();
    assert!(off < 0.5, "draft {d:?}, still {s:?}: {off:.2} pixels apart");
}

/// Level `level` read whole.
fn read_whole(pyramid: &Pyramid, level: usize) -> Volume {
    let dims = pyramid.grid(level).dims;
    pyramid.source(level).read_box([0; 3], dims).unwrap()
}

/// Every box read from a pyramid's levels: (level, lo, hi).
type Reads = Arc<std::sync::Mutex<Vec<(usize, [usize; 3], [usize; 3])>>>;

/// A level that records every box read from it.
struct Counted {
    level: usize,
    source: Arc<dyn volray_core::VolumeSource>,
    reads: Reads,
}

impl volray_core::VolumeSource for Counted {
    fn grid(&self) -> volray_core::sampling::grid::GridFrame {
        self.source.grid()
    }
    fn sample_type(&self) -> volray_core::SampleType {
        self.source.sample_type()
    }
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, volray_core::SourceError> {
        self.reads.lock().unwrap().push((self.level, lo, hi));
        self.source.read_box(lo, hi)
    }
}

/// A 64³ OME-Zarr pyramid of 16³ chunks (levels 64³, 32³, 16³): its
/// directory and path.
fn pyramid_file() -> (tempfile::TempDir, std::path::PathBuf) {
    use volray_io::{OmeZarrOptions, write_ome_zarr};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blob.ome.zarr");
    let volume = Volume::from_fn([64; 3], DVec3::ONE, DVec3::ZERO, |p| {
        let d = (p - DVec3::new(30.0, 34.0, 28.0)).length();
        ((1.0 - d / 26.0).max(0.0) * (1.0 + 0.3 * (p.x * 0.4).sin())) as f32
    })
    .unwrap();
    let options = OmeZarrOptions {
        chunk: 16,
        shard: 32,
        ..OmeZarrOptions::default()
    };
    write_ome_zarr(&path, &volume, &options).unwrap();
    (dir, path)
}

/// Level `level` of `path` read whole, as `volray render --level N`
/// reads it.
fn read_level(path: &std::path::Path, level: usize) -> Volume {
    let opts = volray_io::ReadOptions {
        level: Some(level),
        ..volray_io::ReadOptions::default()
    };
    volray_io::read(path, &opts).unwrap().volume
}

/// A server of the pyramid at `path` under `limit` bytes, its stills
/// at `still` (`None`: auto), and the log of what its levels read.
fn pyramid_shared(path: &std::path::Path, limit: u128, still: Option<usize>) -> (Shared, Reads) {
    let reads = Reads::default();
    let sources = (0..3)
        .map(|level| {
            let opts = volray_io::ReadOptions {
                level: Some(level),
                ..volray_io::ReadOptions::default()
            };
            let lazy = volray_io::open_lazy(path, &opts).unwrap().unwrap();
            Arc::new(Counted {
                level,
                source: lazy.source,
                reads: Arc::clone(&reads),
            }) as Arc<dyn volray_core::VolumeSource>
        })
        .collect();
    let pyramid = crate::pyramid::Pyramid::new(sources, still).unwrap();
    let mut shared = shared_with(Arc::new(Plain::default()), limit, 1);
    // No brick caches: what a level's renderer holds is its frame's.
    shared.cache_budget = 0;
    let start = RenderSettings::default();
    shared.costs = Costs::new(&shared.volume, &start, NonFinite::Refuse, 0);
    shared.levels = Some(Arc::new(Levels::new(pyramid)));
    (shared, reads)
}

#[test]
fn a_pyramids_drafts_show_a_coarser_level_held_whole_and_its_still_the_level_auto_chooses() {
    let (_dir, path) = pyramid_file();
    let (shared, reads) = pyramid_shared(&path, 1 << 30, None);
    let pyramid = &shared.levels.as_ref().unwrap().pyramid;
    let full = RenderSettings {
        width: 64,
        height: 64,
        ..RenderSettings::default()
    };
    let draft = RenderSettings {
        width: 32,
        height: 32,
        ..full.clone()
    };
    let still = pyramid.auto_level(&full).unwrap();
    let coarse = pyramid.auto_level(&draft).unwrap();
    assert!(coarse > still, "draft {coarse}, still {still}");
    let mailbox = Arc::new(Mailbox::default());
    let (tx, mut rx) = mpsc::channel(1);
    spawn(&shared, Arc::clone(&mailbox), tx).unwrap();

    // A drag: the coarse level, read whole once, then held.
    let (h, _) = one_frame(&mailbox, &mut rx, request(1, Quality::Draft, 64, 30.0));
    assert_eq!(h["level"]["index"], coarse);
    assert_eq!(h["level"]["count"], 3);
    assert_eq!(
        (h["level"]["pieces"].as_u64(), h["level"]["read"].as_u64()),
        (Some(1), Some(1))
    );
    let dims = pyramid.grid(coarse).dims;
    assert_eq!(*reads.lock().unwrap(), [(coarse, [0; 3], dims)]);
    let (h, _) = one_frame(&mailbox, &mut rx, request(2, Quality::Draft, 64, 40.0));
    assert_eq!(
        (h["level"]["index"].as_u64(), h["level"]["read"].as_u64()),
        (Some(coarse as u64), Some(0))
    );
    assert_eq!(reads.lock().unwrap().len(), 1, "a drag reads nothing more");

    // Still: the level auto chooses, whole: the frame `volray render
    // --level N` renders of it, byte for byte.
    let (h, png) = one_frame(&mailbox, &mut rx, request(3, Quality::Full, 64, 40.0));
    assert_eq!(h["level"]["index"], still);
    assert_eq!(h["level"]["pieces"], 1);
    let dims = pyramid.grid(still).dims;
    assert_eq!(reads.lock().unwrap()[1..], [(still, [0; 3], dims)]);
    let volume = read_level(&path, still);
    let mut settings = full.clone();
    settings.camera.azimuth = 40.0;
    let reference = Renderer::new(&volume)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    assert_eq!(png, encode::png(&reference, &mut Vec::new()).unwrap());
    mailbox.close();
    assert!(rx.blocking_recv().is_none());
    drop(shared.levels);
    assert_eq!(shared.ledger.held(), 0, "every level's bytes given back");
}

#[test]
fn a_still_beyond_the_memory_left_is_rendered_in_pieces_never_read_whole_within_a_level() {
    let (_dir, path) = pyramid_file();
    let full = RenderSettings {
        width: 64,
        height: 64,
        ..RenderSettings::default()
    };
    // Level 0's still does not fit: what reading it whole takes, less
    // a byte; the drafts' level fits a quarter of that.
    let (probe, _) = pyramid_shared(&path, u128::MAX, Some(0));
    let pyramid = &probe.levels.as_ref().unwrap().pyramid;
    let nf = NonFinite::Refuse;
    let whole = pyramid.whole_bytes(0, &full, nf) + probe.costs.pieces_frame(&full).0;
    let limit = whole - 1;
    let draft = RenderSettings {
        width: 32,
        height: 32,
        ..full.clone()
    };
    let coarse = pyramid.draft_level(&draft, 0, nf, limit).unwrap().unwrap();
    assert!(coarse > 0);
    let (shared, reads) = pyramid_shared(&path, limit, Some(0));
    let mailbox = Arc::new(Mailbox::default());
    let (tx, mut rx) = mpsc::channel(1);
    spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
    let (h, _) = one_frame(&mailbox, &mut rx, request(1, Quality::Draft, 64, 20.0));
    assert_eq!(h["level"]["index"], coarse);
    let (h, png) = one_frame(&mailbox, &mut rx, request(2, Quality::Full, 64, 20.0));
    assert_eq!(h["level"]["index"], 0);
    let pieces = h["level"]["pieces"].as_u64().unwrap();
    assert!(pieces > 1, "{h}");
    // Level 0 was never read whole; no level read whole was larger
    // than the limit allows.
    let log = reads.lock().unwrap().clone();
    assert!(log.iter().any(|(l, ..)| *l == 0));
    for (level, lo, hi) in log {
        let dims = pyramid.grid(level).dims;
        assert!(
            level != 0 || (lo, hi) != ([0; 3], dims),
            "level 0 read whole"
        );
        if (lo, hi) == ([0; 3], dims) {
            assert!(pyramid.volume_bytes(level) <= limit / crate::pyramid::DRAFT_SHARE);
        }
    }
    // Within a level (1/255) of level 0 rendered whole.
    let volume = read_level(&path, 0);
    let mut settings = full.clone();
    settings.camera.azimuth = 20.0;
    let reference = Renderer::new(&volume)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    let expected = pixels(&encode::png(&reference, &mut Vec::new()).unwrap());
    let got = pixels(&png);
    assert_eq!(got.len(), expected.len());
    let worst = got
        .iter()
        .zip(&expected)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
    assert!(worst <= 1, "{worst}/255");
    mailbox.close();
    assert!(rx.blocking_recv().is_none());
    assert!(shared.ledger.held() <= limit);
}

#[test]
fn a_still_in_pieces_superseded_before_it_starts_reads_nothing_and_the_newer_frame_is_sent() {
    let (_dir, path) = pyramid_file();
    let (probe, _) = pyramid_shared(&path, u128::MAX, Some(0));
    let full = RenderSettings {
        width: 64,
        height: 64,
        ..RenderSettings::default()
    };
    let pyramid = &probe.levels.as_ref().unwrap().pyramid;
    let limit = pyramid.whole_bytes(0, &full, NonFinite::Refuse) - 1;
    let plain = Arc::new(Plain::default());
    let (mut shared, reads) = pyramid_shared(&path, limit, Some(0));
    shared.reproduce = Arc::clone(&plain) as Arc<dyn Reproduce>;
    let mailbox = Arc::new(Mailbox::default());
    let page = Arc::clone(&mailbox);
    *plain.meanwhile.lock().unwrap() = Some((
        1.0,
        Box::new(move || page.put(Slot::Latest, request(2, Quality::Draft, 64, 2.0))),
    ));
    mailbox.put(Slot::Latest, request(1, Quality::Full, 64, 1.0));
    let (tx, mut rx) = mpsc::channel(1);
    spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
    let Some(Outgoing::Frame(message, _)) = rx.blocking_recv() else {
        panic!("no frame")
    };
    let h = header(&message);
    assert_eq!(h["seq"], 2);
    assert!(h["level"]["index"].as_u64().unwrap() > 0);
    assert_eq!(shared.stats.stopped(), 1);
    // Only the draft's level was read: the still stopped before its
    // first piece.
    let log = reads.lock().unwrap().clone();
    assert!(log.iter().all(|(l, ..)| *l > 0), "{log:?}");
    mailbox.close();
    assert!(rx.blocking_recv().is_none());
}
