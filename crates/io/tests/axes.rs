//! One axis model for every reader: `ReadOptions::frame` picks the time
//! point and `ReadOptions::channel` the channel, and `FileInfo` counts
//! them apart (`time_points`, `channels`; `frames` = T·C), in files
//! written by the independent tools (`tests/axes/write_files.py`:
//! tifffile, h5py, nibabel, pynrrd in `target/pyenv`).
//!
//! Every file holds the same volumes: the sample at (x, y, z) of time
//! point t, channel c is x + 10y + 100z + 1000c + 10000t, over (6, 5, 4).

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::check_voxels;
use volray_core::VolumeSource;
use volray_io::{IoError, Loaded, ReadOptions, open_lazy, read};

const DIMS: [usize; 3] = [6, 5, 4];

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["numpy", "tifffile", "h5py", "nibabel", "nrrd"],
        "tests/axes/write_files.py",
    )
}

fn pick(frame: Option<usize>, channel: Option<usize>) -> ReadOptions {
    ReadOptions {
        frame,
        channel,
        ..ReadOptions::default()
    }
}

fn load(path: &Path, opts: &ReadOptions) -> Loaded {
    read(path, opts).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Voxel (x, y, z) holds the formula at time point `t`, channel `c`.
fn assert_volume(what: &str, l: &Loaded, t: usize, c: usize) {
    check_voxels(what, &l.volume, DIMS, |x, y, z| {
        (x + 10 * y + 100 * z + 1000 * c + 10000 * t) as f32
    });
}

/// The 2 × 3 files, as paths.
fn two_by_three(dir: &Path) -> Vec<PathBuf> {
    [
        "hyper.tif",
        "ome.ome.tif",
        "axes.h5:/tczyx",
        "axes.h5:/ctzyx",
        "five.nii",
    ]
    .iter()
    .map(|f| dir.join(f))
    .collect()
}

#[test]
fn every_time_point_and_channel_of_every_format_is_its_own_volume() {
    let Some(dir) = files() else { return };
    for path in two_by_three(dir) {
        let what = path.display().to_string();
        for t in 0..2 {
            for c in 0..3 {
                let l = load(&path, &pick(Some(t), Some(c)));
                assert_volume(&format!("{what} t {t} c {c}"), &l, t, c);
                let i = &l.info;
                assert_eq!((i.time_points, i.channels, i.frames), (2, 3, 6), "{what}");
                assert_eq!(
                    (i.time_point, i.channel, i.frame),
                    (t, c, 3 * t + c),
                    "{what}"
                );
            }
        }
        // Without either, time point 0 of channel 0.
        assert_volume(&what, &load(&path, &ReadOptions::default()), 0, 0);
    }
}

#[test]
fn a_dataset_read_box_by_box_picks_the_same_volume() {
    let Some(dir) = files() else { return };
    for name in ["axes.h5:/tczyx", "axes.h5:/ctzyx"] {
        let path = dir.join(name);
        let opts = pick(Some(1), Some(2));
        let lazy = open_lazy(&path, &opts).unwrap().expect("HDF5 opens lazily");
        assert_eq!((lazy.info.time_points, lazy.info.channels), (2, 3));
        let whole = load(&path, &opts).volume;
        let boxed = lazy.source.read_box([0; 3], DIMS).unwrap();
        let want = VolumeSource::read_box(&whole, [0; 3], DIMS).unwrap();
        assert_eq!(boxed, want, "{name}");
    }
}

#[test]
fn channels_without_time_and_time_without_channels() {
    let Some(dir) = files() else { return };
    // a[z, y, x, c]: three channels, one time point.
    let path = dir.join("axes.h5:/zyxc");
    for c in 0..3 {
        let l = load(&path, &pick(None, Some(c)));
        assert_volume("zyxc", &l, 0, c);
        assert_eq!((l.info.time_points, l.info.channels), (1, 3));
    }
    // An NRRD's first axis of kind vector: its channels.
    let path = dir.join("vector.nrrd");
    for c in 0..3 {
        let l = load(&path, &pick(None, Some(c)));
        assert_volume("vector.nrrd", &l, 0, c);
        assert_eq!((l.info.time_points, l.info.channels), (1, 3));
    }
    // An NRRD's last axis of kind time: its time points (of channel 1).
    let path = dir.join("time.nrrd");
    for t in 0..2 {
        let l = load(&path, &pick(Some(t), None));
        assert_volume("time.nrrd", &l, t, 1);
        assert_eq!((l.info.time_points, l.info.channels), (2, 1));
    }
}

#[test]
fn a_time_point_or_channel_out_of_range_is_refused_naming_what_the_file_holds() {
    let Some(dir) = files() else { return };
    for path in two_by_three(dir) {
        let what = path.display().to_string();
        let err = read(&path, &pick(None, Some(3))).unwrap_err();
        assert!(
            matches!(err, IoError::ChannelOutOfRange { channel: 3, .. }),
            "{what}: {err}"
        );
        assert!(
            err.to_string().contains("holds 3 channels"),
            "{what}: {err}"
        );
        let err = read(&path, &pick(Some(2), Some(0))).unwrap_err();
        assert!(
            matches!(err, IoError::FrameOutOfRange { frame: 2, .. }),
            "{what}: {err}"
        );
        assert!(
            err.to_string().contains("holds 2 time points"),
            "{what}: {err}"
        );
    }
    // A format of one channel: channel 1 is refused before it is read.
    let err = read(&dir.join("time.nrrd"), &pick(None, Some(1))).unwrap_err();
    assert!(matches!(err, IoError::ChannelOutOfRange { .. }), "{err}");
}
