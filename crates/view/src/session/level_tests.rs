//! A pyramid's tabs together: a level read whole by one tab keeps no
//! other tab waiting (`levels.rs`), two tabs needing one level read it
//! once, and a draft of a coarse level is framed as the still
//! (`Pyramid::framed`).

use super::tests::{Plain, Reads, header, request, shared_with};
use super::*;
use crate::mailbox::Slot;
use crate::pyramid::{DRAFT_SHARE, Pyramid};
use std::sync::Mutex;
use std::sync::mpsc as std_mpsc;
use std::time::Duration;
use volray_core::glam::DVec3;
use volray_core::{Blend, VolumeSource};

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
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
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
            streamed: None,
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
