//! Reads VTK XML image data (`.vti`) written by VTK's own
//! vtkXMLImageDataWriter (see `fixtures/make_vtk_fixtures.py`) in every data
//! mode, encoding, compression, header type and byte order, and checks
//! every value, the geometry, the array choice and `FileInfo`; then checks
//! that broken files made here are refused with specific messages.
//!
//! Every image has 4 x 3 x 5 points, spacing (0.5, 2, 1.5), origin
//! (-1, 2, 3); point arrays hold v(i, j, k) = i + 10j + 100k through the
//! script's per-type formula, cell arrays c = i + 10j + 100k + 0.5 on the
//! 3 x 2 x 4 cells. Values are checked at their world positions, so the
//! check does not depend on how the reader lays out a rotated grid.

use std::path::{Path, PathBuf};

use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/vtk")
        .join(name)
}

fn v(i: usize, j: usize, k: usize) -> i64 {
    (i + 10 * j + 100 * k) as i64
}

/// The value the script stored for type `name` at v (`TYPES` in the script).
fn typed(name: &str, v: i64) -> f32 {
    match name {
        "u8" => (v % 256) as u8 as f32,
        "i8" => (v % 256 - 128) as i8 as f32,
        "u16" => (v + 60000) as u16 as f32,
        "i16" => (v - 1000) as i16 as f32,
        "u32" => (v + 3_000_000_000) as u32 as f32,
        "i32" => (v - 2_000_000) as i32 as f32,
        "u64" => (v as u64 + (1 << 40)) as f32,
        "i64" => (v - (1 << 40)) as f32,
        "f32" => v as f32 + 0.25,
        "f64" => (v as f64 - 0.125) as f32,
        _ => unreachable!("{name}"),
    }
}

fn read_with(name: &str, array: Option<&str>) -> Result<Loaded, IoError> {
    let opts = ReadOptions {
        array: array.map(str::to_string),
        ..ReadOptions::default()
    };
    read(&fixture(name), &opts)
}

fn load(name: &str, array: Option<&str>) -> Loaded {
    let l = read_with(name, array).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(l.format, VolumeFormat::Vti);
    l
}

/// A grid of `n` samples per axis whose sample (i, j, k) sits at
/// `origin + i·steps[0] + j·steps[1] + k·steps[2]` must hold `want(i, j, k)`
/// at that world position in the volume.
fn check_world(
    name: &str,
    l: &Loaded,
    n: [usize; 3],
    steps: [DVec3; 3],
    origin: DVec3,
    want: impl Fn(usize, usize, usize) -> f32,
) {
    let vol = &l.volume;
    assert_eq!(vol.len(), n[0] * n[1] * n[2], "{name}");
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let world =
                    origin + steps[0] * i as f64 + steps[1] * j as f64 + steps[2] * k as f64;
                let g = (world - vol.origin()) / vol.spacing();
                let idx = [g.x, g.y, g.z].map(|x| {
                    let r = x.round();
                    assert!(
                        (x - r).abs() < 1e-9,
                        "{name}: ({i}, {j}, {k}) at {world} is off the grid"
                    );
                    r as usize
                });
                assert_eq!(
                    vol.get(idx[0], idx[1], idx[2]),
                    want(i, j, k),
                    "{name} at ({i}, {j}, {k})"
                );
            }
        }
    }
}

const STEPS: [DVec3; 3] = [
    DVec3::new(0.5, 0.0, 0.0),
    DVec3::new(0.0, 2.0, 0.0),
    DVec3::new(0.0, 0.0, 1.5),
];
const ORIGIN: DVec3 = DVec3::new(-1.0, 2.0, 3.0);

fn check_ramp(name: &str, l: &Loaded) {
    assert_eq!(l.volume.dims(), [4, 3, 5], "{name}");
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 2.0, 1.5), "{name}");
    assert_eq!(l.volume.origin(), ORIGIN, "{name}");
    check_world(name, l, [4, 3, 5], STEPS, ORIGIN, |i, j, k| {
        typed("f32", v(i, j, k))
    });
}

fn check_cells(name: &str, l: &Loaded, steps: [DVec3; 3], origin: DVec3) {
    let centre = origin + (steps[0] + steps[1] + steps[2]) * 0.5;
    check_world(name, l, [3, 2, 4], steps, centre, |i, j, k| {
        v(i, j, k) as f32 + 0.5
    });
    assert!(
        l.info.notes.iter().any(|n| n.contains("3x2x4 cells")),
        "{:?}",
        l.info.notes
    );
}

fn header_value<'a>(l: &'a Loaded, key: &str) -> &'a str {
    l.info
        .header
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no header field {key}: {:?}", l.info.header))
}

const VARIANTS: [(&str, &str); 11] = [
    ("vti_ascii.vti", "little"),
    ("vti_binary.vti", "little"),
    ("vti_binary_u32.vti", "little"),
    ("vti_binary_zlib.vti", "little"),
    ("vti_binary_zlib_u32.vti", "little"),
    ("vti_appended_raw.vti", "little"),
    ("vti_appended_raw_zlib.vti", "little"),
    ("vti_appended_base64.vti", "little"),
    ("vti_appended_base64_zlib_u32.vti", "little"),
    ("vti_appended_raw_be.vti", "big"),
    ("vti_binary_be_zlib.vti", "big"),
];

#[test]
fn every_data_mode_encoding_and_compression() {
    for (file, endian) in VARIANTS {
        let l = load(file, None);
        check_ramp(file, &l);
        assert_eq!(
            l.info.stored_type,
            format!("Float32 ({endian}-endian)"),
            "{file}"
        );
        assert_eq!(
            l.info.arrays,
            ["ramp", "other", "velocity", "pair a", "cells"],
            "{file}"
        );
        assert_eq!(l.info.array.as_deref(), Some("ramp"));
        assert_eq!(header_value(&l, "VTKFile type"), "ImageData");
        assert_eq!(header_value(&l, "ImageData WholeExtent"), "0 3 0 2 0 4");
        assert_eq!(header_value(&l, "PointData Scalars"), "ramp");
        assert!(
            l.info
                .notes
                .iter()
                .any(|n| n.contains("\"ramp\" (the active scalars)")),
            "{:?}",
            l.info.notes
        );

        let l = load(file, Some("other"));
        assert_eq!(l.info.stored_type, format!("UInt8 ({endian}-endian)"));
        check_world(file, &l, [4, 3, 5], STEPS, ORIGIN, |i, j, k| {
            typed("u8", v(i, j, k))
        });

        let l = load(file, Some("cells"));
        assert_eq!(l.volume.dims(), [3, 2, 4]);
        check_cells(file, &l, STEPS, ORIGIN);

        for (name, n) in [("velocity", 3), ("pair a", 2)] {
            let err = read_with(file, Some(name)).unwrap_err();
            assert!(!err.is_io_failure());
            let msg = err.to_string();
            assert!(
                msg.contains(&format!("point array \"{name}\" has {n} components"))
                    && msg.contains("(ramp, other, cells)"),
                "{msg}"
            );
        }
        let msg = read_with(file, Some("missing")).unwrap_err().to_string();
        assert!(msg.contains("no array named \"missing\""), "{msg}");
    }
    // What varies between the files shows in the header.
    let l = load("vti_binary_zlib_u32.vti", None);
    assert_eq!(
        header_value(&l, "VTKFile compressor"),
        "vtkZLibDataCompressor"
    );
    assert_eq!(header_value(&l, "VTKFile header_type"), "UInt32");
    let l = load("vti_appended_base64.vti", None);
    assert_eq!(header_value(&l, "AppendedData encoding"), "base64");
}

#[test]
fn every_sample_type() {
    for name in [
        "u8", "i8", "u16", "i16", "u32", "i32", "u64", "i64", "f32", "f64",
    ] {
        let l = load("vti_types.vti", Some(name));
        check_world(name, &l, [4, 3, 5], STEPS, ORIGIN, |i, j, k| {
            typed(name, v(i, j, k))
        });
    }
    // No active scalars: the first one-component point array.
    let l = load("vti_types.vti", None);
    assert_eq!(l.info.array.as_deref(), Some("u8"));
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("first one-component array"))
    );
}

#[test]
fn several_pieces_are_assembled() {
    let l = load("vti_pieces.vti", None);
    check_ramp("vti_pieces.vti", &l);
    let pieces: Vec<&str> = l
        .info
        .header
        .iter()
        .filter(|(k, _)| k == "Piece Extent")
        .map(|(_, v)| v.as_str())
        .collect();
    assert_eq!(pieces, ["0 3 0 2 0 1", "0 3 0 2 1 2", "0 3 0 2 2 4"]);
}

#[test]
fn direction_matrix_and_extent_offsets() {
    // Direction "0 -1 0 1 0 0 0 0 1" (row-major): i along +y, j along -x.
    let steps = [
        DVec3::new(0.0, 0.5, 0.0),
        DVec3::new(-2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 1.5),
    ];
    let l = load("vti_direction.vti", None);
    assert_eq!(l.volume.dims(), [3, 4, 5]);
    check_world("direction", &l, [4, 3, 5], steps, ORIGIN, |i, j, k| {
        typed("f32", v(i, j, k))
    });
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("index axis 0 -> +y, index axis 1 -> -x"))
    );
    let l = load("vti_direction.vti", Some("cells"));
    check_cells("direction cells", &l, steps, ORIGIN);

    // Extent 2..5, 1..3, 0..4: the first point is at Origin + (2, 1, 0)·Spacing.
    let first = ORIGIN + DVec3::new(1.0, 2.0, 0.0);
    let l = load("vti_extent.vti", None);
    assert_eq!(l.volume.origin(), first);
    check_world("extent", &l, [4, 3, 5], STEPS, first, |i, j, k| {
        typed("f32", v(i, j, k))
    });
    let l = load("vti_extent.vti", Some("cells"));
    check_cells("extent cells", &l, STEPS, first);
}

#[test]
fn lz4_is_refused_clearly() {
    let err = read_with("vti_lz4.vti", None).unwrap_err();
    assert!(!err.is_io_failure());
    assert!(
        err.to_string()
            .contains("compressor=\"vtkLZ4DataCompressor\""),
        "{err}"
    );
}

// ---- broken files ----

fn error_for(bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.vti");
    std::fs::write(&p, bytes).unwrap();
    let err = read(&p, &ReadOptions::default()).unwrap_err();
    assert!(!err.is_io_failure(), "{err}");
    let msg = err.to_string();
    assert!(!msg.contains('\n'), "{msg}");
    assert!(msg.starts_with(&p.display().to_string()), "{msg}");
    msg
}

fn fixture_text(name: &str) -> Vec<u8> {
    std::fs::read(fixture(name)).unwrap()
}

fn replace(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let at = bytes
        .windows(from.len())
        .position(|w| w == from.as_bytes())
        .unwrap_or_else(|| panic!("{from} not found"));
    [&bytes[..at], to.as_bytes(), &bytes[at + from.len()..]].concat()
}

#[test]
fn truncated_appended_data() {
    let b = fixture_text("vti_appended_raw.vti");
    // The cut removes the end of "cells", the last array; "ramp" (the
    // default) is still whole, so ask for the cells.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cut.vti");
    std::fs::write(&p, &b[..b.len() - 100]).unwrap();
    let opts = ReadOptions {
        array: Some("cells".into()),
        ..ReadOptions::default()
    };
    let msg = read(&p, &opts).unwrap_err().to_string();
    assert!(
        msg.contains("appended DataArray \"cells\": the file ends inside its data"),
        "{msg}"
    );
    assert!(read(&p, &ReadOptions::default()).is_ok());

    let b = fixture_text("vti_appended_raw_zlib.vti");
    std::fs::write(&p, &b[..b.len() - 60]).unwrap();
    let msg = read(&p, &opts).unwrap_err().to_string();
    assert!(
        msg.contains("\"cells\": compressed block 0") && msg.contains("runs past the end"),
        "{msg}"
    );
}

#[test]
fn lying_extents_are_refused_before_allocating() {
    // The whole extent and the piece claim 10^15 points; the data's own
    // header says 240 bytes.
    let b = fixture_text("vti_appended_raw.vti");
    let b = replace(
        &b,
        "WholeExtent=\"0 3 0 2 0 4\"",
        "WholeExtent=\"0 99999 0 99999 0 99999\"",
    );
    let b = replace(
        &b,
        "Piece Extent=\"0 3 0 2 0 4\"",
        "Piece Extent=\"0 99999 0 99999 0 99999\"",
    );
    let msg = error_for(&b);
    assert!(
        msg.contains("header declares 240 bytes, but its extent and type need 4000000000000"),
        "{msg}"
    );

    // Compressed: the block header's sizes disagree with the extent.
    let b = fixture_text("vti_binary_zlib.vti");
    let b = replace(
        &b,
        "WholeExtent=\"0 3 0 2 0 4\"",
        "WholeExtent=\"0 3 0 2 0 5\"",
    );
    let b = replace(
        &b,
        "Piece Extent=\"0 3 0 2 0 4\"",
        "Piece Extent=\"0 3 0 2 0 5\"",
    );
    let msg = error_for(&b);
    assert!(
        msg.contains(
            "compression header declares 1 blocks of 256 bytes (last 240), not the 288 bytes"
        ),
        "{msg}"
    );

    // ASCII: more values than the text can hold.
    let b = fixture_text("vti_ascii.vti");
    let b = replace(
        &b,
        "WholeExtent=\"0 3 0 2 0 4\"",
        "WholeExtent=\"0 999 0 999 0 999\"",
    );
    let b = replace(
        &b,
        "Piece Extent=\"0 3 0 2 0 4\"",
        "Piece Extent=\"0 999 0 999 0 999\"",
    );
    let msg = error_for(&b);
    assert!(
        msg.contains("needs 1000000000 values, but its text is only"),
        "{msg}"
    );

    // A piece that does not cover the whole extent.
    let b = fixture_text("vti_appended_raw.vti");
    let b = replace(
        &b,
        "WholeExtent=\"0 3 0 2 0 4\"",
        "WholeExtent=\"0 3 0 2 0 9\"",
    );
    let msg = error_for(&b);
    assert!(
        msg.contains("the pieces hold 60 values but WholeExtent 0 3 0 2 0 9 needs 120"),
        "{msg}"
    );
}

#[test]
fn malformed_files() {
    let raw = fixture_text("vti_appended_raw.vti");
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (replace(&raw, "type=\"ImageData\"", "type=\"PolyData\""), "VTKFile type=\"PolyData\": volray reads ImageData"),
        (replace(&raw, "byte_order=\"LittleEndian\"", "byte_order=\"Middle\""), "byte_order=\"Middle\""),
        (replace(&raw, "header_type=\"UInt64\"", "header_type=\"UInt16\""), "header_type=\"UInt16\""),
        (replace(&raw, "type=\"Float32\" Name=\"ramp\"", "type=\"Float128\" Name=\"ramp\""), "DataArray \"ramp\" type=\"Float128\""),
        (replace(&raw, "Spacing=\"0.5 2 1.5\"", "Spacing=\"0.5 2\""), "Spacing=\"0.5 2\": expected 3 numbers"),
        (replace(&raw, "Spacing=\"0.5 2 1.5\"", "Spacing=\"0.5 0 1.5\""), "spacings must be finite and non-zero"),
        (replace(&raw, "WholeExtent=\"0 3 0 2 0 4\"", "WholeExtent=\"0 3 2 0 0 4\""), "is empty or inverted"),
        (replace(&raw, "Piece Extent=\"0 3 0 2 0 4\"", "Piece Extent=\"0 3 0 2 0 5\""), "Piece 0 Extent 0 3 0 2 0 5 lies outside WholeExtent"),
        (replace(&raw, "offset=\"0\"", "offset=\"999999\""), "offset=999999 lies beyond the end of the file"),
        (replace(&raw, "<AppendedData encoding=\"raw\">", "<Appended encoding=\"raw\">"), "XML error"),
        (replace(&raw, "format=\"appended\" RangeMin=\"0.25\"", "format=\"weird\" RangeMin=\"0.25\""), "format=\"weird\""),
        (b"<?xml version=\"1.0\"?>\n<Other/>\n".to_vec(), "no <VTKFile> element"),
        (b"<VTKFile type=\"ImageData\"></VTKFile>".to_vec(), "no <ImageData> element"),
        (b"<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 1 0 1 0 1\"></ImageData></VTKFile>".to_vec(), "ImageData has no Piece"),
    ];
    for (bytes, want) in cases {
        let msg = error_for(&bytes);
        assert!(msg.contains(want), "{msg} (wanted {want})");
    }

    // Corrupt base64 and corrupt zlib.
    let b = fixture_text("vti_binary.vti");
    let b = replace(&b, "8AAAAAAAAAAAAIA+", "8AAAAAAAAAAAA!A+");
    let msg = error_for(&b);
    assert!(msg.contains("DataArray \"ramp\": bad base64 data"), "{msg}");
    let b = fixture_text("vti_binary_zlib.vti");
    let b = replace(&b, "=eF4", "=AF4");
    let msg = error_for(&b);
    assert!(
        msg.contains("DataArray \"ramp\" block 0: corrupt zlib stream"),
        "{msg}"
    );

    // ASCII with a bad number, too few and too many values.
    let a = fixture_text("vti_ascii.vti");
    let msg = error_for(&replace(&a, "0.25 1.25", "0.25 x"));
    assert!(
        msg.contains("value 1 is \"x\": not a Float32 number"),
        "{msg}"
    );
    let msg = error_for(&replace(&a, "0.25 1.25", "0.25"));
    assert!(
        msg.contains("holds 59 values, but its extent needs 60"),
        "{msg}"
    );
    let msg = error_for(&replace(&a, "0.25 1.25", "0.25 1.25 7"));
    assert!(msg.contains("holds more than the 60 values"), "{msg}");
}

/// Deterministic byte flips and truncations of a few fixtures: each read
/// either succeeds or fails with a one-line message; none panics.
#[test]
fn no_panic_on_truncation_or_corruption() {
    let dir = tempfile::tempdir().unwrap();
    let mut seed = 0xd1b5_4a32_d192_ed03u64;
    for name in [
        "vti_binary_zlib.vti",
        "vti_appended_raw_zlib.vti",
        "vti_appended_base64_zlib_u32.vti",
        "vti_binary.vti",
        "vti_pieces.vti",
    ] {
        let good = std::fs::read(fixture(name)).unwrap();
        let p = dir.path().join(name);
        let mut variants: Vec<Vec<u8>> = (0..good.len())
            .step_by(good.len() / 25 + 1)
            .map(|n| good[..n].to_vec())
            .collect();
        for _ in 0..30 {
            let mut b = good.clone();
            for _ in 0..3 {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                let at = (seed % b.len() as u64) as usize;
                b[at] = (seed >> 32) as u8;
            }
            variants.push(b);
        }
        for b in variants {
            std::fs::write(&p, &b).unwrap();
            for array in [None, Some("cells".to_string())] {
                let opts = ReadOptions {
                    array,
                    ..ReadOptions::default()
                };
                if let Err(e) = read(&p, &opts) {
                    let msg = e.to_string();
                    assert!(
                        !msg.contains('\n') && msg.starts_with(&p.display().to_string()),
                        "{msg}"
                    );
                }
            }
        }
    }
}
