//! HDF5 datasets written by h5py (`fixtures/make_hdf5_fixtures.py`), read
//! through `volray_io::read` (pure Rust, in every build).
//!
//! Every volume has shape (4, 3, 5), indexed `a[x, y, z]`, and holds
//! `v = x + 10y + 100z` with a per-dataset offset or scale.

mod common;

use std::path::PathBuf;

use common::{assert_frame_out_of_range, check_voxels, error_about, frame, ramp, refused_at};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

fn fixture(spec: &str) -> PathBuf {
    common::fixture("hdf5", spec)
}

fn load(spec: &str, opts: &ReadOptions) -> Loaded {
    let l = read(&fixture(spec), opts).unwrap_or_else(|e| panic!("{spec}: {e}"));
    assert_eq!(l.format, VolumeFormat::Hdf5);
    l
}

/// The refusal of `spec` (`file.h5` or `file.h5:/dataset`), which
/// names the file.
fn error(spec: &str, opts: &ReadOptions) -> String {
    let file = spec.split(':').next().unwrap();
    let err = error_about(&fixture(spec), opts, &fixture(file));
    assert!(!err.is_io_failure(), "{err}");
    err.to_string()
}

/// Voxel (x, y, z) holds `f(v, x, y, z)` exactly, v = x + 10y + 100z.
fn assert_values(volume: &Volume, f: impl Fn(f64, [usize; 3]) -> f64) {
    check_voxels("", volume, [4, 3, 5], |x, y, z| {
        f(ramp(x, y, z) as f64, [x, y, z]) as f32
    });
}

#[test]
fn the_only_volume_is_found_with_its_geometry() {
    for spec in ["one.h5", "one.h5:/fields/density", "one.h5:fields/density"] {
        let l = load(spec, &ReadOptions::default());
        assert_values(&l.volume, |v, _| v + 0.5);
        assert_eq!(l.volume.spacing(), DVec3::new(0.5, 0.25, 2.0));
        assert_eq!(l.volume.origin(), DVec3::new(1.0, -2.0, 3.0));
        assert_eq!(l.info.length_unit.as_deref(), Some("angstrom"));
        assert_eq!(l.info.stored_type, "float32 (little-endian)");
        assert_eq!((l.info.frames, l.info.frame), (1, 0));
        assert_eq!(
            l.info.header[0],
            ("dataset".into(), "/fields/density".into())
        );
        assert!(l.info.header.contains(&("@unit".into(), "angstrom".into())));
        assert!(
            l.info
                .notes
                .iter()
                .any(|n| n.contains("from attribute(s) spacing, origin")),
            "{:?}",
            l.info.notes
        );
    }
}

#[test]
fn every_sample_type_and_gzip_chunks() {
    let none = ReadOptions::default();
    let l = load("many.h5:/u8", &none);
    assert_values(&l.volume, |_, [x, y, z]| (x + 2 * y + 6 * z) as f64);
    assert!(l.info.notes.iter().any(|n| n.contains("spacing 1, 1, 1")));
    let l = load("many.h5:/i16_be", &none);
    assert_values(&l.volume, |v, _| -v);
    assert_eq!(l.info.stored_type, "int16 (big-endian)");
    assert_values(&load("many.h5:/u32", &none).volume, |v, _| v + 3e9);
    assert_values(&load("many.h5:/i64", &none).volume, |v, _| {
        v - 2f64.powi(40)
    });
    let l = load("many.h5:/f64", &none);
    assert_values(&l.volume, |v, _| v * 1e-3);
    assert_eq!(l.volume.spacing(), DVec3::splat(1.5));
    assert_eq!(l.info.length_unit, None);
    let l = load("many.h5:/gzip_u16", &none);
    assert_values(&l.volume, |v, _| v);
    assert!(
        l.info.header.iter().any(|(k, _)| k == "filters"),
        "{:?}",
        l.info.header
    );
}

#[test]
fn series_frames_with_element_size() {
    for t in 0..3 {
        let l = load("many.h5:/series", &frame(t));
        assert_values(&l.volume, |v, _| v + 1000.0 * t as f64);
        assert_eq!((l.info.frames, l.info.frame), (3, t));
        // element_size_um [1, 0.2, 0.3, 0.4]: the time value is dropped.
        assert_eq!(l.volume.spacing(), DVec3::new(0.2, 0.3, 0.4));
        assert_eq!(l.info.length_unit.as_deref(), Some("um"));
    }
    let file = fixture("many.h5");
    let err = error_about(&fixture("many.h5:/series"), &frame(3), &file);
    assert_frame_out_of_range(
        &err,
        3,
        "HDF5 dataset \"/series\" holds 3 volumes (its first axis), numbered from 0",
    );
}

#[test]
fn bad_datasets_and_paths_are_refused_clearly() {
    let none = ReadOptions::default();
    let msg = error("many.h5", &none);
    assert!(
            msg.contains("HDF5 file holds 8 3-D to 5-D numeric datasets: name one as FILE:/path (/bad_spacing [4, 3, 5], /f64 [4, 3, 5],"),
            "{msg}"
        );
    let msg = error("one.h5:/fields/nothing", &none);
    assert!(
            msg.contains("no dataset \"/fields/nothing\"; its 3-D to 5-D numeric datasets: /fields/density [4, 3, 5]"),
            "{msg}"
        );
    let msg = error("one.h5:/fields/labels", &none);
    assert!(msg.contains("shape [7] has 1 dimension(s)"), "{msg}");
    let msg = error("many.h5:/text", &none);
    assert!(msg.contains("is not numeric"), "{msg}");
    let msg = error("many.h5:/bad_spacing", &none);
    assert!(
        msg.contains("attribute \"spacing\" has 2 values, needs 3"),
        "{msg}"
    );

    // Not an HDF5 file; a missing file is an I/O failure.
    let dir = tempfile::tempdir().unwrap();
    let msg = refused_at(dir.path(), "fake.h5", b"not hdf5 at all", &none);
    assert!(msg.contains("HDF5: cannot open"), "{msg}");
    let err = read(&dir.path().join("gone.h5:/x"), &none).unwrap_err();
    assert!(err.is_io_failure(), "{err}");

    // Truncated: the header survives, the data does not.
    let bytes = std::fs::read(fixture("one.h5")).unwrap();
    refused_at(dir.path(), "cut.h5", &bytes[..bytes.len() / 2], &none);
}
