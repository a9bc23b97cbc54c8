//! Multi-page TIFF stacks written by tifffile and Pillow
//! (`fixtures/make_tiff_fixtures.py`), read through `volray_io::read`.
//!
//! Every stack is 4 columns (x) by 3 rows (y) by 5 pages (z) holding
//! `v = x + 10y + 100z` with a per-file offset or scale.

mod common;

use std::path::PathBuf;

use common::{
    assert_frame_out_of_range, check_voxels, frame, header_value, ramp, refused, refused_at,
};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

/// The expected value of voxel (x, y, z) given `v = x + 10y + 100z`.
type Formula = fn(f64, [usize; 3]) -> f64;

fn fixture(name: &str) -> PathBuf {
    common::fixture("tiff", name)
}

fn load(name: &str) -> Loaded {
    load_with(name, &ReadOptions::default())
}

fn load_with(name: &str, opts: &ReadOptions) -> Loaded {
    let loaded = read(&fixture(name), opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(loaded.format, VolumeFormat::Tiff);
    loaded
}

/// The refusal of fixture `name`.
fn error(name: &str, opts: &ReadOptions) -> String {
    refused(&fixture(name), opts)
}

/// Asserts that voxel (x, y, z) of a 4x3x5 volume holds `f(v)` with
/// `v = x + 10y + 100z`, exactly.
fn assert_values(v: &Volume, f: impl Fn(f64, [usize; 3]) -> f64) {
    check_voxels("voxel", v, [4, 3, 5], |x, y, z| {
        f(ramp(x, y, z) as f64, [x, y, z]) as f32
    });
}

#[test]
fn imagej_stack_with_spacing_origin_and_unit() {
    let l = load("imagej_u16.tif");
    assert_values(&l.volume, |v, _| v + 1000.0);
    // XResolution 2 and YResolution 4 pixels per um, spacing=2.5.
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 0.25, 2.5));
    // xorigin=2, yorigin=1, zorigin=0.5 pixels: world origin is -o·spacing.
    assert_eq!(l.volume.origin(), DVec3::new(-1.0, -0.25, -1.25));
    assert_eq!(l.info.length_unit.as_deref(), Some("um"));
    assert_eq!(l.info.stored_type, "uint16 (little-endian, uncompressed)");
    assert_eq!((l.info.frames, l.info.frame), (1, 0));
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("from ImageJ metadata")),
        "{:?}",
        l.info.notes
    );
    let header: Vec<&str> = l.info.header.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(header[0], "pages");
    assert_eq!(l.info.header[0].1, "5");
    assert!(header.contains(&"ImageWidth"), "{header:?}");
    let description = header_value(&l, "ImageDescription");
    assert!(
        description.starts_with("ImageJ=1.11a; images=5"),
        "{description:?}"
    );
}

#[test]
fn imagej_float_stack_with_deflate_pages() {
    let l = load("imagej_f32_zlib.tif");
    assert_values(&l.volume, |v, _| 0.5 * v - 3.0);
    assert_eq!(l.volume.spacing(), DVec3::new(1.0, 1.0, 0.75));
    assert_eq!(l.volume.origin(), DVec3::ZERO);
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    assert_eq!(l.info.stored_type, "float32 (little-endian, deflate)");
}

#[test]
fn imagej_hyperstack_time_points_and_channels_apart() {
    // TZCYX = (2, 5, 2, 3, 4): --frame picks the time point, --channel
    // the channel; volume t·2 + c of the 4.
    for (t, c) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        let l = load_with("imagej_hyper.tif", &common::at(t, c));
        assert_values(&l.volume, |v, _| v + 1000.0 * c as f64 + 10000.0 * t as f64);
        assert_eq!((l.info.frames, l.info.frame), (4, 2 * t + c));
        assert_eq!((l.info.time_points, l.info.channels), (2, 2));
        assert!(
            l.info
                .notes
                .iter()
                .any(|s| s.contains(&format!("time point {t} of 2, channel {c} of 2 read"))),
            "{:?}",
            l.info.notes
        );
    }
    // Without --frame and --channel the first volume is read.
    let l = load("imagej_hyper.tif");
    assert_values(&l.volume, |v, _| v);
    let err = read(&fixture("imagej_hyper.tif"), &frame(2)).unwrap_err();
    assert_frame_out_of_range(
        &err,
        2,
        "the stack holds 2 time points (ImageJ frames) of 2 channels (ImageJ channels), numbered from 0",
    );
}

#[test]
fn plain_stacks_of_every_sample_type() {
    let cases: [(&str, &str, Formula); 7] = [
        (
            "plain_i16_be.tif",
            "int16 (big-endian, uncompressed)",
            |v, _| -v,
        ),
        (
            "plain_i8.tif",
            "int8 (little-endian, uncompressed)",
            |_, [x, y, z]| (x + y + z) as f64 - 5.0,
        ),
        (
            "plain_i32.tif",
            "int32 (little-endian, uncompressed)",
            |v, _| v - 100000.0,
        ),
        (
            "plain_u32.tif",
            "uint32 (little-endian, uncompressed)",
            |v, _| v + 3_000_000_000.0,
        ),
        (
            "plain_u64.tif",
            "uint64 (little-endian, uncompressed)",
            |v, _| v + 2f64.powi(40),
        ),
        (
            "plain_f16.tif",
            "float16 (little-endian, uncompressed)",
            |v, _| v / 4.0,
        ),
        (
            "plain_f64_be.tif",
            "float64 (big-endian, uncompressed)",
            |v, _| v * 1e-3,
        ),
    ];
    for (name, stored, f) in cases {
        let l = load(name);
        assert_values(&l.volume, f);
        assert_eq!(l.info.stored_type, stored, "{name}");
        assert_eq!(l.volume.spacing(), DVec3::ONE, "{name}");
        assert_eq!(l.volume.origin(), DVec3::ZERO, "{name}");
        assert_eq!(l.info.length_unit, None, "{name}");
        assert!(
            l.info
                .notes
                .iter()
                .any(|n| n.contains("the resolution tags name no unit")),
            "{name}: {:?}",
            l.info.notes
        );
    }
}

#[test]
fn tiled_bigtiff_and_lzw_stacks() {
    assert_values(&load("tiled_u16.tif").volume, |v, _| v);
    let l = load("bigtiff_f32.tif");
    assert_values(&l.volume, |v, _| v + 0.25);
    let l = load("pillow_lzw_u16.tif");
    assert_values(&l.volume, |v, _| v);
    assert_eq!(l.info.stored_type, "uint16 (little-endian, LZW)");
}

#[test]
fn reduced_resolution_pages_are_skipped() {
    let l = load("thumbnail_u8.tif");
    assert_values(&l.volume, |_, [x, y, z]| (x + 10 * y + 40 * z) as f64);
    assert!(
        l.info.notes.iter().any(
            |n| n.contains("1 reduced-resolution or mask page(s) skipped") && n.contains("pages 5")
        ),
        "{:?}",
        l.info.notes
    );
    assert_eq!(l.info.header[0], ("pages".to_string(), "6".to_string()));
}

#[test]
fn unsupported_stacks_are_refused_clearly() {
    let none = ReadOptions::default();
    let msg = error("rgb_u8.tif", &none);
    assert!(msg.contains("TIFF page 0: RGB pixels"), "{msg}");
    let msg = error("mixed_sizes.tif", &none);
    assert!(
        msg.contains("TIFF page 2 is 4x2 pixels but page 0 is 4x3"),
        "{msg}"
    );
    // One page is an image (tests/flat.rs): read, not a volume.
    let msg = error("single_page.tif", &none);
    assert!(
        msg.contains("a 2-D image (4 x 3 samples), not a volume"),
        "{msg}"
    );
}

#[test]
fn damaged_files_give_clean_errors() {
    let dir = tempfile::tempdir().unwrap();
    let none = ReadOptions::default();
    let good = std::fs::read(fixture("imagej_u16.tif")).unwrap();

    // Bad magic, forced to TIFF.
    let mut bytes = good.clone();
    bytes[..2].copy_from_slice(b"XX");
    let msg = refused_at(dir.path(), "magic.tif", &bytes, &none);
    assert!(msg.contains("TIFF header"), "{msg}");

    // Cut short in the pixel data and in the header.
    for len in [good.len() - 40, 12, 3] {
        refused_at(dir.path(), &format!("cut{len}.tif"), &good[..len], &none);
    }

    // Pages that claim 60000 x 60000 pixels in a 1 KB file are refused
    // before decoding (here by the decoder's strip-size check; compressed
    // pages by the reader's decoded-size bound, tested in the module).
    let huge = patch_dimensions(&good, 60000);
    let msg = refused_at(dir.path(), "huge.tif", &huge, &none);
    assert!(msg.contains(": TIFF "), "{msg}");
}

#[test]
fn mutated_files_never_panic() {
    // Every fixture with bytes overwritten at random: a volume or a
    // one-line bad-input error, never a panic.
    let files: Vec<PathBuf> = std::fs::read_dir(fixture(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    common::mutations_never_panic(&files, "m.tif", 11);
}

/// Rewrites the ImageWidth (256) and ImageLength (257) SHORT/LONG values of
/// every IFD of a little-endian classic TIFF to `side`.
fn patch_dimensions(tiff: &[u8], side: u32) -> Vec<u8> {
    let mut out = tiff.to_vec();
    let u16_at = |b: &[u8], i: usize| u16::from_le_bytes([b[i], b[i + 1]]);
    let u32_at = |b: &[u8], i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    assert_eq!(&tiff[..4], b"II*\0");
    let mut ifd = u32_at(tiff, 4) as usize;
    while ifd != 0 {
        let n = u16_at(tiff, ifd) as usize;
        for e in 0..n {
            let at = ifd + 2 + 12 * e;
            let tag = u16_at(tiff, at);
            if tag == 256 || tag == 257 {
                out[at + 2..at + 4].copy_from_slice(&4u16.to_le_bytes()); // LONG
                out[at + 4..at + 8].copy_from_slice(&1u32.to_le_bytes());
                out[at + 8..at + 12].copy_from_slice(&side.to_le_bytes());
            }
        }
        ifd = u32_at(tiff, ifd + 2 + 12 * n) as usize;
    }
    out
}
