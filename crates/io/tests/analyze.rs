//! Reads Analyze 7.5 `.hdr`/`.img` pairs written by nibabel (see
//! `fixtures/make_analyze_fixtures.py`): values, and the geometry nibabel
//! gives a header without orientation (x flipped, origin at the centre
//! voxel, or at SPM's originator); then broken variants, each refused in
//! one line naming Analyze 7.5.

mod common;

use std::path::{Path, PathBuf};

use common::{Grid, has_note, header_value, ramp, refused, typed};
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

const SHAPE: [usize; 3] = [12, 10, 8];

/// nibabel's `get_base_affine` for these files.
const CENTRED: [[f64; 4]; 3] = [
    [-1.5, 0.0, 0.0, 8.25],
    [0.0, 2.0, 0.0, -9.0],
    [0.0, 0.0, 0.75, -2.625],
];
/// Spm99AnalyzeImage's affine with originator 3 4 5.
const SPM: [[f64; 4]; 3] = [
    [-1.5, 0.0, 0.0, 3.0],
    [0.0, 2.0, 0.0, -6.0],
    [0.0, 0.0, 0.75, -3.0],
];

fn fixture(name: &str) -> PathBuf {
    common::fixture("analyze", name)
}

fn load(name: &str) -> Loaded {
    let l = read(&fixture(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::Analyze, "{name}");
    l
}

#[test]
fn pairs_of_each_type_read_with_nibabels_affine() {
    let grid = Grid::from_affine(SHAPE, &CENTRED);
    for (name, file, type_name) in [
        ("u8", "u8.hdr", "uint8 (little-endian)"),
        ("i16", "i16.hdr", "int16 (little-endian)"),
        ("f32", "f32.hdr", "float32 (little-endian)"),
        ("i16", "i16_be.hdr", "int16 (big-endian)"),
    ] {
        let l = load(file);
        // x flipped: the volume starts at the file's last i.
        assert_eq!(l.volume.dims(), SHAPE, "{file}");
        assert_eq!(l.volume.spacing(), DVec3::new(1.5, 2.0, 0.75), "{file}");
        assert_eq!(l.volume.origin(), DVec3::new(-8.25, -9.0, -2.625), "{file}");
        common::check_world(file, &l.volume, &grid, 1e-9, |i, j, k| {
            typed(name, ramp(i, j, k))
        });
        assert_eq!(l.info.stored_type, type_name, "{file}");
        assert_eq!(header_value(&l, "sizeof_hdr"), "348");
        assert_eq!(header_value(&l, "originator"), "0 0 0 0 0");
        assert_eq!(l.info.header.last().unwrap().0, "smin");
        assert!(
            has_note(&l, "Analyze 7.5 (no NIfTI magic)"),
            "{:?}",
            l.info.notes
        );
        assert!(
            has_note(&l, "carries no orientation")
                && has_note(&l, "origin at the centre voxel (5.5, 4.5, 3.5)"),
            "{:?}",
            l.info.notes
        );
    }
}

#[test]
fn spm_originator_gives_the_origin() {
    let l = load("spm_origin.hdr");
    common::check_world(
        "spm_origin",
        &l.volume,
        &Grid::from_affine(SHAPE, &SPM),
        1e-9,
        |i, j, k| typed("f32", ramp(i, j, k)),
    );
    assert_eq!(header_value(&l, "originator"), "3 4 5 0 0");
    assert!(has_note(&l, "SPM's originator 3 4 5"), "{:?}", l.info.notes);
}

#[test]
fn found_by_content_and_named_in_messages() {
    let head = std::fs::read(fixture("i16_be.hdr")).unwrap();
    assert_eq!(VolumeFormat::sniff(&head), Some(VolumeFormat::Analyze));
    // A NIfTI pair's .hdr is still NIfTI.
    let nifti = std::fs::read(common::fixture("nifti", "pair.hdr")).unwrap();
    assert_eq!(VolumeFormat::sniff(&nifti), Some(VolumeFormat::Nifti));
    assert_eq!("analyze".parse::<VolumeFormat>(), Ok(VolumeFormat::Analyze));
    assert_eq!(VolumeFormat::Analyze.description(), "Analyze 7.5");
}

/// Copies the `f32` pair into `dir` as `name`.hdr/.img with the header
/// edited by `edit` and the image cut to `img_len` bytes; returns the .hdr.
fn broken(dir: &Path, name: &str, edit: impl Fn(&mut Vec<u8>), img_len: usize) -> PathBuf {
    let mut hdr = std::fs::read(fixture("f32.hdr")).unwrap();
    edit(&mut hdr);
    let img = std::fs::read(fixture("f32.img")).unwrap();
    let h = dir.join(format!("{name}.hdr"));
    std::fs::write(&h, &hdr).unwrap();
    std::fs::write(
        dir.join(format!("{name}.img")),
        &img[..img_len.min(img.len())],
    )
    .unwrap();
    h
}

/// The refusal of the pair at `hdr` for what its .img holds: about the .img.
fn refused_img(hdr: &Path) -> String {
    let err = common::error_about(hdr, &ReadOptions::default(), &hdr.with_extension("img"));
    assert!(!err.is_io_failure(), "{err}");
    err.to_string()
}

fn put_i16(b: &mut [u8], at: usize, v: i16) {
    b[at..at + 2].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn lying_truncated_and_huge_headers_are_refused_naming_analyze() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let none = ReadOptions::default();
    let msg = refused_img(&broken(d, "short", |_| {}, 3000));
    assert!(
        msg.contains("file is 3000 bytes, but the Analyze 7.5 header"),
        "{msg}"
    );
    assert!(msg.contains("implies 3840"), "{msg}");
    let msg = refused_img(&broken(d, "lying", |b| put_i16(b, 46, 9), 9999));
    assert!(msg.contains("implies 4320"), "{msg}");
    let huge = |b: &mut Vec<u8>| {
        for a in 1..=4 {
            put_i16(b, 40 + 2 * a, 32767);
        }
        put_i16(b, 40, 4);
    };
    let msg = refused_img(&broken(d, "huge", huge, 9999));
    assert!(msg.contains("implies 4611123094243246084"), "{msg}");
    // dim[0] 9 is no Analyze header by content: named, it is refused.
    let named = ReadOptions {
        format: Some(VolumeFormat::Analyze),
        ..ReadOptions::default()
    };
    let msg = refused(&broken(d, "dim0", |b| put_i16(b, 40, 9), 9999), &named);
    assert!(msg.contains("Analyze 7.5 field \"dim[0]\" is 9"), "{msg}");
    let msg = refused(
        &broken(
            d,
            "zoom",
            |b| b[80..84].copy_from_slice(&0f32.to_le_bytes()),
            9999,
        ),
        &none,
    );
    assert!(
        msg.contains("Analyze 7.5 field \"pixdim[1]\" is 0"),
        "{msg}"
    );
    let msg = refused(&broken(d, "rgb", |b| put_i16(b, 70, 128), 9999), &none);
    assert!(
        msg.contains("Analyze 7.5 field \"datatype\" is 128 (RGB24)"),
        "{msg}"
    );
    // An Analyze header is always a pair: a name without .hdr has no .img.
    let lone = d.join("lone.bin");
    std::fs::copy(fixture("f32.hdr"), &lone).unwrap();
    let msg = refused(&lone, &none);
    assert!(
        msg.contains("an Analyze 7.5 header says the data is in a separate .img file"),
        "{msg}"
    );
}

/// Deterministic byte flips and truncations of the headers (with their
/// .img beside them), read with and without a frame: never a panic.
#[test]
fn no_panic_on_truncation_or_corruption() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = common::Lcg(0x2545_f491_4f6c_dd1d);
    for name in ["u8", "i16_be", "spm_origin"] {
        let hdr = std::fs::read(fixture(&format!("{name}.hdr"))).unwrap();
        std::fs::copy(fixture(&format!("{name}.img")), dir.path().join("x.img")).unwrap();
        let path = dir.path().join("x.hdr");
        for _ in 0..200 {
            let bytes = common::mutate(&hdr, &mut rng, 3);
            std::fs::write(&path, &bytes).unwrap();
            for opts in [ReadOptions::default(), common::frame(1)] {
                // Refusals may be about the .img (what it holds).
                if let Err(e) = read(&path, &opts) {
                    let msg = e.to_string();
                    assert!(!e.is_io_failure() && !msg.contains('\n'), "{msg}");
                    assert!(msg.starts_with(&dir.path().display().to_string()), "{msg}");
                }
            }
        }
    }
}
