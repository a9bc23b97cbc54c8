//! Out-of-core frames: a volume rendered piece by piece from its source
//! under a memory budget gives the frame one process renders from the
//! whole volume, within 1/255 per channel, for every case the ranks are
//! held to; it reads no piece that is transparent or hidden; no piece it
//! reads is larger than the budget allows; and a failed read is an error.

use std::sync::Arc;
use std::sync::Mutex;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{FrameRequest, Render, Rendered};
use volray_core::{
    Histogram, MemoryBound, NonFinite, RenderSettings, Renderer, SampleType, TransferFunction,
    Volume, VolumeSource,
};
use volray_distributed::streamed::{StreamError, Streamed};

mod common;
use common::{cases, colorful, volume};

/// A volume that records every box read from it.
struct Counted {
    volume: Volume,
    reads: Mutex<Vec<([usize; 3], [usize; 3])>>,
}

impl Counted {
    fn new(volume: Volume) -> Arc<Counted> {
        Arc::new(Counted {
            volume,
            reads: Mutex::new(Vec::new()),
        })
    }

    fn take(&self) -> Vec<([usize; 3], [usize; 3])> {
        std::mem::take(&mut self.reads.lock().unwrap())
    }
}

impl VolumeSource for Counted {
    fn grid(&self) -> GridFrame {
        self.volume.grid()
    }
    fn sample_type(&self) -> SampleType {
        self.volume.sample_type()
    }
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, volray_core::SourceError> {
        self.reads.lock().unwrap().push((lo, hi));
        self.volume.read_box(lo, hi)
    }
}

/// A budget for frames of `settings` of `volume` in about `share` pieces:
/// two frames (the pieces' partial images composited) and a `share`th of
/// the rest of the bound on a frame of all of it, with no cache.
fn budget(volume: &Volume, settings: &RenderSettings, share: u64) -> u64 {
    let b = MemoryBound::for_volume(volume, settings, NonFinite::Refuse, 0);
    (2 * b.frame + (b.total() - b.frame) / u128::from(share)) as u64
}

/// Settings for a frame small beside the volume.
fn small() -> RenderSettings {
    RenderSettings {
        width: 24,
        height: 24,
        ..RenderSettings::default()
    }
}

#[test]
fn frames_rendered_piece_by_piece_equal_the_whole_volumes_within_a_level() {
    let volume = volume();
    let renderer = Renderer::new(&volume).unwrap();
    let mut worst: f32 = 0.0;
    for (name, settings) in cases() {
        // Frames small beside the volume, so that its pieces are what the
        // budget divides.
        let settings = RenderSettings {
            width: 32,
            height: 28,
            ..settings
        };
        let single = renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        let mut seen = Vec::new();
        for share in [1, 2, 4] {
            let budget = budget(&volume, &settings, share);
            let source = Counted::new(volume.clone());
            let streamed = Streamed::new(source.clone(), NonFinite::Refuse, budget);
            let (frame, times) = streamed
                .render(FrameRequest::new(&settings))
                .map(Rendered::image_and_times)
                .unwrap();
            let diff = frame.max_abs_diff(&single).unwrap();
            worst = worst.max(diff);
            assert!(
                diff <= 1.0 / 255.0,
                "{name}, {} pieces: {diff}",
                times.pieces
            );
            // No piece read is over the budget's bound.
            for (lo, hi) in source.take() {
                let dims = std::array::from_fn(|a| hi[a] - lo[a]);
                let piece = Volume::from_fn(dims, volume.spacing(), DVec3::ZERO, |_| 0.0).unwrap();
                assert!(
                    MemoryBound::for_volume(&piece, &settings, NonFinite::Refuse, 0).total()
                        <= u128::from(budget),
                    "{name}: a piece of {dims:?} over {budget} bytes"
                );
            }
            seen.push(times.pieces);
        }
        assert!(
            seen[0] == 1 && seen[1] > 1 && seen[2] > seen[1],
            "{name}: pieces {seen:?}"
        );
    }
    println!("largest difference from the whole volume: {worst:e}");
}

#[test]
fn transparent_pieces_are_not_read_once_their_range_is_known() {
    // One blob in a corner of a 40³ grid, zero elsewhere, under a transfer
    // function with its own domain in which zero is transparent.
    let volume = Volume::from_fn([40; 3], DVec3::ONE, DVec3::ZERO, |p| {
        (1.0 - (p - DVec3::splat(8.0)).length() / 6.0).max(0.0) as f32
    })
    .unwrap();
    let mut tf = colorful();
    tf.domain = Some((0.0, 1.0));
    let settings = RenderSettings {
        width: 48,
        height: 48,
        transfer_function: tf,
        ..RenderSettings::default()
    };
    let single = Renderer::new(&volume)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    let source = Counted::new(volume.clone());
    let budget = budget(&volume, &settings, 10);
    let streamed = Streamed::new(source.clone(), NonFinite::Refuse, budget);
    let (first, t1) = streamed
        .render(FrameRequest::new(&settings))
        .map(Rendered::image_and_times)
        .unwrap();
    // The domain is given: no pass for statistics, every piece read once.
    assert_eq!(t1.statistics_pieces, 0);
    assert_eq!(source.take().len(), t1.read_pieces);
    let (second, t2) = streamed
        .render(FrameRequest::new(&settings))
        .map(Rendered::image_and_times)
        .unwrap();
    let reads = source.take();
    assert_eq!(reads.len(), t2.read_pieces);
    assert!(
        t2.read_pieces >= 1 && t2.read_pieces * 4 <= t2.pieces,
        "read {} of {} pieces",
        t2.read_pieces,
        t2.pieces
    );
    // Only pieces near the blob: every box read starts within its reach.
    assert!(
        reads.iter().all(|(lo, _)| lo.iter().all(|&i| i <= 15)),
        "{reads:?}"
    );
    assert!(first.max_abs_diff(&single).unwrap() <= 1.0 / 255.0);
    assert_eq!(first, second);
}

#[test]
fn pieces_behind_an_opaque_wall_are_not_read() {
    // The default camera looks along -x: a slab at high x is in front,
    // opaque enough to stop every ray; the volume behind it varies, so it
    // is not transparent.
    let volume = Volume::from_fn([64, 32, 32], DVec3::ONE, DVec3::ZERO, |p| {
        if p.x > 52.0 {
            1.0
        } else {
            0.5 + 0.3 * (p.y * 0.3).sin() as f32
        }
    })
    .unwrap();
    let tf = TransferFunction::from_json(
        r#"{"domain": [0, 1], "opacity": [[0, 0], [0.2, 0.3], [1, 1]]}"#,
    )
    .unwrap();
    let settings = RenderSettings {
        width: 40,
        height: 40,
        transfer_function: tf,
        ..RenderSettings::default()
    };
    let single = Renderer::new(&volume)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    let source = Counted::new(volume.clone());
    let budget = budget(&volume, &settings, 6);
    let streamed = Streamed::new(source.clone(), NonFinite::Refuse, budget);
    let (frame, times) = streamed
        .render(FrameRequest::new(&settings))
        .map(Rendered::image_and_times)
        .unwrap();
    assert!(frame.max_abs_diff(&single).unwrap() <= 1.0 / 255.0);
    let reads = source.take();
    assert!(times.pieces >= 4, "{times:?}");
    assert!(
        times.read_pieces < times.pieces,
        "every piece read: {reads:?}"
    );
}

#[test]
fn the_histogram_counted_by_pieces_is_the_whole_volumes() {
    let volume = volume();
    let settings = small();
    let budget = budget(&volume, &settings, 6);
    let streamed = Streamed::new(Arc::new(volume.clone()), NonFinite::Refuse, budget);
    streamed
        .render(FrameRequest::new(&settings))
        .map(Rendered::image_and_times)
        .unwrap();
    assert!(streamed.pieces() > 1);
    let pieces = streamed.histogram(&settings, 64).unwrap().unwrap();
    let whole = Histogram::of(&volume, 64).unwrap();
    assert_eq!((pieces.min, pieces.max), (whole.min, whole.max));
    assert_eq!(pieces.counts, whole.counts);
    assert!((pieces.mean - whole.mean).abs() < 1e-9 * whole.mean.abs().max(1.0));
}

/// A source whose reads past x = 0 fail.
struct Failing(Volume);

impl VolumeSource for Failing {
    fn grid(&self) -> GridFrame {
        self.0.grid()
    }
    fn sample_type(&self) -> SampleType {
        self.0.sample_type()
    }
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, volray_core::SourceError> {
        if lo[0] > 0 {
            return Err(volray_core::SourceError::bad_data(
                "scan.zarr: chunk c/0/0/1 is truncated",
            ));
        }
        self.0.read_box(lo, hi)
    }
}

#[test]
fn a_failed_read_fails_the_frame_with_the_sources_message() {
    let volume = volume();
    let settings = small();
    let budget = budget(&volume, &settings, 6);
    let streamed = Streamed::new(Arc::new(Failing(volume)), NonFinite::Refuse, budget);
    match streamed
        .render(FrameRequest::new(&settings))
        .map(Rendered::image_and_times)
    {
        Err(e) => assert_eq!(
            e,
            StreamError::Read(volray_core::SourceError::bad_data(
                "scan.zarr: chunk c/0/0/1 is truncated"
            ))
        ),
        Ok((_, times)) => panic!("rendered: {times:?}"),
    }
}

#[test]
fn a_budget_too_small_for_any_piece_is_refused() {
    let volume = volume();
    let settings = RenderSettings::default();
    let streamed = Streamed::new(Arc::new(volume), NonFinite::Refuse, 1000);
    match streamed
        .render(FrameRequest::new(&settings))
        .map(Rendered::image_and_times)
    {
        Err(StreamError::TooLarge(m)) => assert!(m.contains("does not fit 1000 bytes"), "{m}"),
        Err(e) => panic!("{e}"),
        Ok((_, times)) => panic!("rendered: {times:?}"),
    }
}

#[test]
fn a_label_volume_in_pieces_has_the_wholes_labels_and_frame() {
    use volray_core::transfer::labels::{LabelStyle, MAX_LABELS, labels_of, transfer_function};
    // Three labelled balls on a background of 0.
    let volume = Volume::from_fn([30, 28, 26], DVec3::ONE, DVec3::ZERO, |p| {
        let balls = [
            (DVec3::new(8.0, 8.0, 8.0), 1.0),
            (DVec3::new(20.0, 18.0, 14.0), 7.0),
        ];
        (balls.iter())
            .find(|(c, _)| (p - *c).length() < 6.0)
            .map_or(if p.z > 22.0 { 3.0 } else { 0.0 }, |(_, l)| *l)
    })
    .unwrap()
    .as_labels();
    let found = labels_of(&volume, MAX_LABELS).unwrap().unwrap();
    assert_eq!(found, vec![0, 1, 3, 7]);
    let settings = RenderSettings {
        transfer_function: transfer_function(&found, &LabelStyle::default()).unwrap(),
        ..small()
    };
    let single = Renderer::new(&volume)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    let budget = budget(&volume, &settings, 5);
    // The source does not say its values are labels: the renderer of pieces is told.
    let plain = Counted::new({
        let mut v = volume.clone();
        v.set_labels(false);
        v
    });
    let streamed = Streamed::new(plain, NonFinite::Refuse, budget).with_labels(true);
    let (frame, times) = streamed
        .render(FrameRequest::new(&settings))
        .map(Rendered::image_and_times)
        .unwrap();
    assert!(times.pieces > 1, "{times:?}");
    assert_eq!(
        streamed.labels(&settings, MAX_LABELS).unwrap().unwrap(),
        Some(found)
    );
    assert!(streamed.labels(&settings, 2).unwrap().unwrap().is_none());
    let diff = frame.max_abs_diff(&single).unwrap();
    assert!(diff <= 1.0 / 255.0, "{diff}");
}

/// A volume that sets a stop flag when its first box is read: a viewer's
/// view moving on while a frame reads its pieces.
struct StopsAfterARead {
    volume: Volume,
    stop: Arc<std::sync::atomic::AtomicBool>,
    reads: std::sync::atomic::AtomicUsize,
}

impl VolumeSource for StopsAfterARead {
    fn grid(&self) -> GridFrame {
        self.volume.grid()
    }
    fn sample_type(&self) -> SampleType {
        self.volume.sample_type()
    }
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, volray_core::SourceError> {
        use std::sync::atomic::Ordering;
        self.reads.fetch_add(1, Ordering::SeqCst);
        self.stop.store(true, Ordering::SeqCst);
        self.volume.read_box(lo, hi)
    }
}

#[test]
fn a_frame_whose_stop_flag_is_set_reads_no_further_piece_and_says_stopped() {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use volray_core::RenderError;
    let volume = volume();
    let settings = RenderSettings {
        transfer_function: TransferFunction {
            domain: Some((0.0, 1.0)),
            ..TransferFunction::default()
        },
        ..small()
    };
    let budget = budget(&volume, &settings, 6);
    let source = Arc::new(StopsAfterARead {
        volume: volume.clone(),
        stop: Arc::new(AtomicBool::new(false)),
        reads: AtomicUsize::new(0),
    });
    let streamed = Streamed::new(source.clone(), NonFinite::Refuse, budget);
    match streamed.render(FrameRequest::new(&settings).stopped_by(&source.stop)) {
        Err(StreamError::Render(RenderError::Stopped)) => {}
        Err(e) => panic!("{e}"),
        Ok(rendered) => panic!("rendered: {:?}", rendered.times),
    }
    assert!(streamed.pieces() > 1);
    assert_eq!(source.reads.load(Ordering::SeqCst), 1);
    // Cleared, the same renderer finishes the frame: the whole volume's.
    source.stop.store(false, Ordering::SeqCst);
    let never = AtomicBool::new(false);
    let request = FrameRequest::new(&settings).stopped_by(&never);
    let (frame, times) = streamed.render(request).unwrap().image_and_times();
    let whole = Renderer::new(&volume)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    assert!(frame.max_abs_diff(&whole).unwrap() <= 1.0 / 255.0);
    assert!(times.pieces > 1);
}

#[test]
fn a_stop_set_during_a_piece_stops_that_piece_within_a_tile_and_reads_no_other() {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::mpsc;
    use volray_core::RenderError;
    let volume = volume();
    let settings = RenderSettings {
        transfer_function: TransferFunction {
            domain: Some((0.0, 1.0)),
            ..TransferFunction::default()
        },
        ..small()
    };
    let source = Counted::new(volume.clone());
    let streamed = Streamed::new(
        source.clone(),
        NonFinite::Refuse,
        budget(&volume, &settings, 6),
    );
    // Another thread sets the stop flag once the first tile is reported,
    // and the report waits for it: one thread renders, so every tile
    // after the first sees the flag.
    let (stop, pixels) = (AtomicBool::new(false), AtomicUsize::new(0));
    let (heard_tx, heard_rx) = mpsc::channel::<()>();
    let (stopped_tx, stopped_rx) = mpsc::channel::<()>();
    let (heard_tx, stopped_rx) = (Mutex::new(Some(heard_tx)), Mutex::new(stopped_rx));
    let report = |n: usize| {
        pixels.fetch_add(n, Ordering::SeqCst);
        if let Some(heard) = heard_tx.lock().unwrap().take() {
            heard.send(()).unwrap();
            stopped_rx.lock().unwrap().recv().unwrap();
        }
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let answer = std::thread::scope(|s| {
        let flag = &stop;
        s.spawn(move || {
            // Err: the frame ended without a report.
            if heard_rx.recv().is_ok() {
                flag.store(true, Ordering::SeqCst);
                stopped_tx.send(()).unwrap();
            }
        });
        let request = FrameRequest::new(&settings)
            .reporting(&report)
            .stopped_by(&stop);
        let answer = pool.install(|| streamed.render(request));
        heard_tx.lock().unwrap().take();
        answer
    });
    match answer {
        Err(StreamError::Render(RenderError::Stopped)) => {}
        Err(e) => panic!("{e}"),
        Ok(rendered) => panic!("rendered: {:?}", rendered.times),
    }
    // Several pieces; one read, and of its four tiles (the first 16² pixels
    // of 24²) the first alone rendered: the piece was stopped, not finished.
    assert!(streamed.pieces() > 1, "{} pieces", streamed.pieces());
    assert_eq!(source.take().len(), 1);
    assert_eq!(pixels.load(Ordering::SeqCst), 16 * 16);
    // Cleared, the same frame is finished: every piece's pixels reported.
    let done = AtomicUsize::new(0);
    let count = |n: usize| {
        done.fetch_add(n, Ordering::SeqCst);
    };
    stop.store(false, Ordering::SeqCst);
    let request = FrameRequest::new(&settings)
        .reporting(&count)
        .stopped_by(&stop);
    let times = streamed.render(request).unwrap().times;
    assert_eq!(done.load(Ordering::SeqCst), times.read_pieces * 24 * 24);
    assert!(times.read_pieces > 1);
}
