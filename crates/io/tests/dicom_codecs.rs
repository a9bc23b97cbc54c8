//! Compressed DICOM pixel data — JPEG (baseline, extended, lossless,
//! SV1), JPEG-LS and JPEG 2000 — written by independent encoders
//! (libjpeg-turbo, CharLS, OpenJPEG) and encapsulated by pydicom
//! (`fixtures/make_dicom_codec_fixtures.py`), read through
//! `volray_io::read`; and slice gaps from rounded positions.
//!
//! Every series is 16 columns (x) by 12 rows (y) by 5 slices (z) of CT
//! geometry: IPP (-10, 20, 30 + 2.5z), PixelSpacing 0.8\0.6, axial, so
//! voxel (i, j, k) is pixel (x = i, y = j) of slice z = k. Lossless series
//! must equal the script's formula (which pydicom's decoders reproduced
//! exactly) after the rescale (intercept -1024); lossy ones must lie within
//! a few stored units of what pydicom's decoders made of the same stream
//! (`<series>_expected.npy`).

mod common;

use std::fs;
use std::path::PathBuf;

use common::{Lcg, assert_note, mutate, read_or_refuse, refused};
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

const X: usize = 16;
const Y: usize = 12;
const Z: usize = 5;

fn fixture(name: &str) -> PathBuf {
    common::fixture("dicom", name)
}

fn load(name: &str) -> Loaded {
    let l = read(&fixture(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::Dicom);
    l
}

/// The stored value of sample type `kind` at pixel (x, y) of slice z (the
/// script's `KINDS`).
fn stored(kind: &str, x: usize, y: usize, z: usize) -> f64 {
    let r = (x + 10 * y + 100 * z) as f64;
    match kind {
        "u8" => (5 * x + 8 * y + 20 * z + 10) as f64,
        "u12" => 7.0 * r + 100.0,
        "s16" => 3.0 * r - 800.0,
        _ => unreachable!("{kind}"),
    }
}

/// Checks the CT grid and that voxel (i, j, k) holds
/// `expected(i, j, k) - 1024` within `tolerance`.
fn check(l: &Loaded, expected: impl Fn(usize, usize, usize) -> f64, tolerance: f64) {
    let v = &l.volume;
    assert_eq!(v.dims(), [X, Y, Z]);
    assert!((v.spacing() - DVec3::new(0.6, 0.8, 2.5)).length() < 1e-12);
    assert_eq!(v.origin(), DVec3::new(-10.0, 20.0, 30.0));
    let at = v.world_position(X - 1, Y - 1, Z - 1);
    assert!((at - DVec3::new(-1.0, 28.8, 40.0)).length() < 1e-9, "{at}");
    let mut worst = 0f64;
    for k in 0..Z {
        for j in 0..Y {
            for i in 0..X {
                let want = expected(i, j, k) - 1024.0;
                let got = f64::from(v.get(i, j, k));
                worst = worst.max((got - want).abs());
                assert!(
                    (got - want).abs() <= tolerance,
                    "voxel ({i}, {j}, {k}) = {got}, want {want} ± {tolerance}"
                );
            }
        }
    }
    if tolerance == 0.0 {
        assert_eq!(worst, 0.0);
    }
}

/// What pydicom's decoders made of lossy series `name`, as stored values
/// (slices x rows x columns, read through volray's own .npy reader, whose
/// first axis is x: index (z, y, x)).
fn pydicom_decoded(name: &str) -> impl Fn(usize, usize, usize) -> f64 {
    let l = read(
        &fixture(&format!("{name}_expected.npy")),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(l.volume.dims(), [Z, Y, X]);
    move |i, j, k| f64::from(l.volume.get(k, j, i))
}

#[test]
fn lossless_jpeg_series_equal_the_written_values() {
    for (name, kind, syntax) in [
        (
            "jpeg_lossless",
            "s16",
            "JPEG Lossless, 1.2.840.10008.1.2.4.57",
        ),
        (
            "jpeg_sv1",
            "u12",
            "JPEG Lossless SV1, 1.2.840.10008.1.2.4.70",
        ),
        (
            "jpeg_sv1_8bit",
            "u8",
            "JPEG Lossless SV1, 1.2.840.10008.1.2.4.70",
        ),
    ] {
        let l = load(name);
        check(&l, |i, j, k| stored(kind, i, j, k), 0.0);
        assert!(
            l.info.stored_type.contains(syntax),
            "{}",
            l.info.stored_type
        );
    }
}

#[test]
fn lossy_jpeg_is_within_two_of_pydicoms_decoding() {
    // jpeg-decoder and libjpeg's inverse DCTs round differently.
    let l = load("jpeg_baseline");
    check(&l, pydicom_decoded("jpeg_baseline"), 2.0);
    assert!(
        l.info
            .stored_type
            .contains("JPEG Baseline, 1.2.840.10008.1.2.4.50")
    );
    let l = load("jpeg_extended_8bit");
    check(&l, pydicom_decoded("jpeg_extended_8bit"), 2.0);
    assert!(
        l.info
            .stored_type
            .contains("JPEG Extended, 1.2.840.10008.1.2.4.51")
    );
}

#[test]
fn jpeg_2000_series_equal_the_written_values_or_pydicoms_decoding() {
    for (name, kind) in [("j2k_lossless", "s16"), ("j2k_lossless_u8", "u8")] {
        let l = load(name);
        check(&l, |i, j, k| stored(kind, i, j, k), 0.0);
    }
    let l = load("j2k_lossy");
    check(&l, pydicom_decoded("j2k_lossy"), 0.0);
}

#[test]
fn multi_frame_files_with_one_or_several_fragments_per_frame() {
    let l = load("jpeg_frames.dcm");
    check(&l, |i, j, k| stored("u8", i, j, k), 0.0);
    let l = load("jpeg_split.dcm");
    check(&l, |i, j, k| stored("s16", i, j, k), 0.0);
    let l = load("j2k_split.dcm");
    check(&l, |i, j, k| stored("u12", i, j, k), 0.0);
}

#[test]
fn twelve_bit_dct_jpeg_is_within_one_of_what_pydicoms_decoder_makes() {
    // libjpeg-turbo's 12-bit encoder wrote it; pylibjpeg-libjpeg decoded
    // it (integer IDCT); volray's own decoder rounds a double-precision
    // IDCT once (T.81 A.3.3).
    let l = load("jpeg_extended");
    check(&l, pydicom_decoded("jpeg_extended"), 1.0);
    assert!(
        l.info
            .stored_type
            .contains("JPEG Extended, 1.2.840.10008.1.2.4.51")
    );
}

#[test]
fn jpeg_ls_series_equal_the_written_values_or_charls_decoding() {
    let l = load("jpegls");
    check(&l, |i, j, k| stored("s16", i, j, k), 0.0);
    assert!(
        l.info
            .stored_type
            .contains("JPEG-LS Lossless, 1.2.840.10008.1.2.4.80")
    );
    let l = load("jpegls_frames.dcm");
    check(&l, |i, j, k| stored("u12", i, j, k), 0.0);
    let l = load("jpegls_u8");
    check(&l, |i, j, k| stored("u8", i, j, k), 0.0);
    // Near-lossless (NEAR 2): exactly CharLS's decoding (through pyjpegls).
    let l = load("jpegls_near");
    check(&l, pydicom_decoded("jpegls_near"), 0.0);
    // Flat patches (run mode), edges, noise and extremes (escape codes),
    // lossless and NEAR 3.
    for name in ["jpegls_textured", "jpegls_textured_near", "jpegls_noise_u8"] {
        let l = load(name);
        check(&l, pydicom_decoded(name), 0.0);
    }
}

/// The first slice file of compressed series `name` with its (single)
/// fragment replaced by `edit` of it: the item's length rewritten, the
/// Basic Offset Table item (empty or one offset, 0) kept.
fn with_fragment(name: &str, edit: impl Fn(&[u8]) -> Vec<u8>) -> Vec<u8> {
    let dir = fixture(name);
    let mut files: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let bytes = fs::read(&files[0]).unwrap();
    // (7FE0,0010) OB, undefined length; then the offset table item.
    let tag = [
        0xE0, 0x7F, 0x10, 0x00, b'O', b'B', 0, 0, 0xFF, 0xFF, 0xFF, 0xFF,
    ];
    let at = bytes.windows(12).position(|w| w == tag).unwrap() + 12;
    let item = |i: usize| {
        assert_eq!(bytes[i..i + 4], [0xFE, 0xFF, 0x00, 0xE0]);
        u32::from_le_bytes(bytes[i + 4..i + 8].try_into().unwrap()) as usize
    };
    let fragment_at = at + 8 + item(at);
    let len = item(fragment_at);
    let start = fragment_at + 8;
    let mut stream = edit(&bytes[start..start + len]);
    if stream.len() % 2 == 1 {
        stream.push(0);
    }
    let mut out = bytes[..fragment_at + 4].to_vec();
    out.extend((stream.len() as u32).to_le_bytes());
    out.extend(&stream);
    out.extend(&bytes[start + len..]);
    out
}

/// `with_fragment` written alone (a single-slice file) in a temporary
/// directory beside a second, intact slice, so the reader decodes it.
fn refused_series(name: &str, edit: impl Fn(&[u8]) -> Vec<u8>) -> String {
    let dir = tempfile::tempdir().unwrap();
    let mut files: Vec<PathBuf> = fs::read_dir(fixture(name))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    fs::copy(&files[1], dir.path().join("b.dcm")).unwrap();
    fs::write(dir.path().join("a.dcm"), with_fragment(name, edit)).unwrap();
    refused(dir.path(), &ReadOptions::default())
}

const CODEC_SERIES: [&str; 9] = [
    "jpeg_baseline",
    "jpeg_extended",
    "jpeg_lossless",
    "jpeg_sv1_8bit",
    "j2k_lossless",
    "j2k_lossy",
    "jpegls",
    "jpegls_near",
    "jpegls_textured",
];

#[test]
fn stream_sizes_that_disagree_with_the_header_are_refused_before_decoding() {
    // JPEG: the frame header's X (columns) 16 -> 17 (SOFn: FF Cn, Lf, P, Y, X).
    for name in ["jpeg_baseline", "jpeg_lossless"] {
        let msg = refused_series(name, |s| {
            let mut s = s.to_vec();
            let sof = (2..s.len())
                .find(|&i| s[i - 1] == 0xFF && matches!(s[i], 0xC0 | 0xC3))
                .unwrap();
            s[sof + 7] = 17;
            s
        });
        assert!(
            msg.contains("the JPEG stream of frame 0 is 17x12 with 1 component(s), but the header declares Columns 16 x Rows 12 with SamplesPerPixel 1"),
            "{msg}"
        );
    }
    // JPEG 2000: SIZ's Ysiz (rows) 12 -> 4000 (SOC, SIZ, Lsiz, Rsiz, Xsiz, Ysiz).
    let msg = refused_series("j2k_lossless", |s| {
        let mut s = s.to_vec();
        s[12..16].copy_from_slice(&4000u32.to_be_bytes());
        s
    });
    assert!(
        msg.contains("the JPEG 2000 stream of frame 0 is 16x4000 with 1 component(s)"),
        "{msg}"
    );
    // 16-bit samples where BitsAllocated is 8.
    let msg = refused_series("jpeg_sv1_8bit", |s| {
        let mut s = s.to_vec();
        let sof = (2..s.len())
            .find(|&i| s[i - 1] == 0xFF && s[i] == 0xC3)
            .unwrap();
        s[sof + 3] = 16;
        s
    });
    assert!(
        msg.contains("the JPEG stream of frame 0 holds 16-bit samples, but BitsAllocated is 8"),
        "{msg}"
    );
}

#[test]
fn truncated_and_corrupt_codestreams_give_one_line_errors() {
    for name in CODEC_SERIES {
        // Cut after the headers, inside the entropy-coded data.
        let msg = refused_series(name, |s| s[..s.len() * 2 / 3].to_vec());
        assert!(
            msg.contains("cannot decode the pixel data ("),
            "{name}: {msg}"
        );
        assert!(msg.contains("frame 0"), "{name}: {msg}");
        // Cut inside the headers.
        let msg = refused_series(name, |s| s[..12].to_vec());
        assert!(msg.contains("frame 0"), "{name}: {msg}");
    }
    // Every prefix and random byte changes of each stream: read or
    // refused in one line, never a panic (the decoders run under
    // catch_unwind).
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Lcg(25);
    for name in CODEC_SERIES {
        let stream = {
            let cell = std::cell::RefCell::new(Vec::new());
            with_fragment(name, |s| {
                cell.replace(s.to_vec());
                s.to_vec()
            });
            cell.into_inner()
        };
        let mut variants: Vec<Vec<u8>> = (2..stream.len())
            .step_by(3)
            .map(|n| stream[..n].to_vec())
            .collect();
        for n in 1..=40 {
            variants.push(mutate(&stream, &mut rng, 1 + n % 6));
        }
        let mut files: Vec<PathBuf> = fs::read_dir(fixture(name))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        fs::copy(&files[1], dir.path().join("b.dcm")).unwrap();
        for v in variants {
            fs::write(dir.path().join("a.dcm"), with_fragment(name, |_| v.clone())).unwrap();
            read_or_refuse(dir.path(), &ReadOptions::default());
        }
    }
}

#[test]
fn compressed_volumes_over_max_memory_are_refused_before_decoding() {
    let small = ReadOptions {
        max_memory: 1000,
        ..ReadOptions::default()
    };
    for name in ["jpeg_split.dcm", "j2k_lossless"] {
        let msg = refused(&fixture(name), &small);
        assert!(msg.contains("1000"), "{name}: {msg}");
    }
    // The same with room for them.
    let room = ReadOptions {
        max_memory: 100_000,
        ..ReadOptions::default()
    };
    assert!(read(&fixture("jpeg_split.dcm"), &room).is_ok());
}

#[test]
fn rounded_positions_are_read_at_the_mean_gap_with_a_note() {
    // z = 10.0, 11.2, 12.3, 13.5, 14.6, 15.8 (1.15 mm steps rounded to
    // one decimal): gaps 1.1 and 1.2 mm, mean 1.16 mm.
    let l = load("rounded");
    let v = &l.volume;
    assert_eq!(v.dims(), [X, Y, 6]);
    assert!((v.spacing() - DVec3::new(0.6, 0.8, 1.16)).length() < 1e-12);
    assert_eq!(v.origin(), DVec3::new(-10.0, 20.0, 10.0));
    for k in 0..6 {
        for j in 0..Y {
            for i in 0..X {
                assert_eq!(v.get(i, j, k), (i + 10 * j + 100 * k) as f32);
            }
        }
    }
    assert_note(
        &l,
        "slice gaps vary from 1.1 to 1.2 mm around their mean 1.16 mm; the largest deviation is the gap of 1.1 mm between mr3.dcm and mr4.dcm, 0.06 mm (5.17 % of the mean) off it, within the tolerance of 0.158 mm (5 % of the mean gap plus 0.1 mm for positions written to 1 decimal(s)): read at the mean gap",
    );
}

#[test]
fn a_gap_three_percent_short_is_read_at_the_mean_gap_naming_it() {
    // z = 0, 2, 4, 5.94, 7.94, 9.94: the gap 4 -> 5.94 is 3 % short,
    // within the 5 % a scanner's rounding may leave (a 20 % gap is
    // refused: tests/dicom.rs).
    let l = load("uneven");
    assert_eq!(l.volume.dims()[2], 6);
    assert!((l.volume.spacing().z - 9.94 / 5.0).abs() < 1e-12);
    assert_note(
        &l,
        "the largest deviation is the gap of 1.94 mm between mr2.dcm and mr3.dcm",
    );
}
