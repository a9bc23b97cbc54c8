//! Reads CCP4/MRC maps written by mrcfile (see
//! `fixtures/make_mrc_fixtures.py`) and checks every voxel against the
//! formula the fixture was made from, the geometry against the header,
//! and what `FileInfo` reports. Malformed variants are made here by
//! patching the header of a good file.

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use common::{
    check_resampled, check_voxels, has_note, header_value, read_or_refuse, refused, truncations,
};
use volray_core::Volume;
use volray_core::glam::{DMat3, DVec3};
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("mrc", name)
}

fn load(path: &Path) -> Result<Loaded, IoError> {
    read(path, &ReadOptions::default())
}

fn ramp(c: usize, r: usize, s: usize) -> f32 {
    (c + 10 * r + 100 * s) as f32
}

fn assert_close(a: DVec3, b: DVec3) {
    assert!((a - b).length() < 1e-6, "{a} vs {b}");
}

/// Every voxel of a 4x3x5 map (columns along x) against `formula`.
fn check_values(v: &Volume, formula: impl Fn(usize, usize, usize) -> f32) {
    check_voxels("", v, [4, 3, 5], formula);
}

#[test]
fn float32_with_origin() {
    let l = load(&fixture("mode2_f32.mrc")).unwrap();
    assert_eq!(l.format, VolumeFormat::Mrc);
    check_values(&l.volume, |c, r, s| ramp(c, r, s) + 0.5);
    assert_close(l.volume.spacing(), DVec3::new(0.5, 0.25, 0.75));
    assert_close(l.volume.origin(), DVec3::new(1.5, -2.0, 3.0));
    assert_eq!(l.info.stored_type, "float32 (MODE 2, little-endian)");
    assert_eq!(l.info.length_unit.as_deref(), Some("angstrom"));
    assert_eq!((l.info.frames, l.info.frame), (1, 0));
    assert_eq!(header_value(&l, "NX NY NZ"), "4 3 5");
    assert_eq!(header_value(&l, "MODE"), "2");
    assert_eq!(header_value(&l, "CELLA"), "2 0.75 3.75");
    assert_eq!(header_value(&l, "MAP"), "'MAP '");
    assert_eq!(header_value(&l, "MACHST"), "44 44 00 00");
    assert_eq!(header_value(&l, "NVERSION"), "20141");
    assert_eq!(header_value(&l, "LABEL 1"), "volray float32 ramp");
    let keys: Vec<&str> = l.info.header.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        &keys[..4],
        ["NX NY NZ", "MODE", "NXSTART NYSTART NZSTART", "MX MY MZ"]
    );
    assert!(
        has_note(&l, "origin from ORIGIN (1.5, -2, 3) angstrom"),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn int8_origin_from_nstart() {
    let l = load(&fixture("mode0_i8.mrc")).unwrap();
    check_values(&l.volume, |c, r, s| (c + 2 * r + 6 * s) as f32 - 40.0);
    assert_close(l.volume.spacing(), DVec3::new(1.0, 2.0, 3.0));
    assert_close(l.volume.origin(), DVec3::new(2.0, -2.0, 9.0));
    assert_eq!(l.info.stored_type, "int8 (MODE 0, little-endian)");
    assert!(
        has_note(&l, "origin from NCSTART NRSTART NSSTART 2 -1 3"),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn big_endian_int16() {
    let l = load(&fixture("mode1_i16_be.mrc")).unwrap();
    check_values(&l.volume, |c, r, s| -7.0 * ramp(c, r, s));
    assert_eq!(l.info.stored_type, "int16 (MODE 1, big-endian)");
    assert_eq!(header_value(&l, "MACHST"), "11 11 00 00");
    assert_close(l.volume.spacing(), DVec3::ONE);
}

#[test]
fn uint16_after_an_extended_header() {
    let l = load(&fixture("mode6_u16_ext.mrc")).unwrap();
    check_values(&l.volume, |c, r, s| 100.0 * ramp(c, r, s));
    assert_eq!(header_value(&l, "NSYMBT"), "80");
    assert_eq!(header_value(&l, "EXTTYP"), "'MRCO'");
    assert!(has_note(
        &l,
        "extended header of 80 bytes (EXTTYP 'MRCO') skipped"
    ));
}

#[test]
fn float16() {
    let l = load(&fixture("mode12_f16.mrc")).unwrap();
    check_values(&l.volume, |c, r, s| ramp(c, r, s) / 4.0);
    assert_eq!(l.info.stored_type, "float16 (MODE 12, little-endian)");
}

#[test]
fn imod_unsigned_bytes() {
    let l = load(&fixture("imod_unsigned.mrc")).unwrap();
    check_values(&l.volume, |c, r, s| (200 + c + r + s) as f32);
    assert_eq!(l.info.stored_type, "uint8 (MODE 0, little-endian)");
    assert_eq!(header_value(&l, "imodStamp"), "1146047817");
    assert!(has_note(&l, "unsigned bytes"), "{:?}", l.info.notes);
}

#[test]
fn mapc_mapr_maps_permutation() {
    let l = load(&fixture("permuted.mrc")).unwrap();
    let v = &l.volume;
    // Columns (2) along Z, rows (4) along X, sections (3) along Y.
    assert_eq!(v.dims(), [4, 3, 2]);
    assert_close(v.spacing(), DVec3::new(0.5, 1.0, 1.5));
    assert_close(v.origin(), DVec3::new(2.0 * 0.5, 3.0 * 1.0, 1.0 * 1.5));
    check_voxels("", v, [4, 3, 2], |x, y, z| ramp(z, x, y));
    assert!(has_note(&l, "columns, rows and sections run along Z, X, Y"));
    assert!(has_note(&l, "samples reordered"));
}

#[test]
fn whole_skewed_cell_is_resampled() {
    let l = load(&fixture("hexagonal.ccp4")).unwrap();
    let a = DVec3::new(1.0, 0.0, 0.0);
    let b = DVec3::new(-0.5, 0.75f64.sqrt(), 0.0);
    let c = DVec3::Z * 8.0 / 4.0;
    let to_grid = DMat3::from_cols(a, b, c).inverse();
    let v = &l.volume;
    let (lo, hi) = v.bounds();
    assert_close(lo, DVec3::new(-3.0, 0.0, 0.0));
    assert_close(hi, DVec3::new(6.0, 6.0 * 0.75f64.sqrt(), 8.0));
    let inside = check_resampled(v, to_grid, [5.0, 5.0, 3.0], 1e-3, |g| {
        g.x + 10.0 * g.y + 100.0 * g.z
    });
    assert!(inside > 50, "{inside}");
    assert!(has_note(&l, "angle(X, Y) 120.000"), "{:?}", l.info.notes);
}

/// A copy of fixture `name` with `patch` applied, in a temporary directory.
fn patched(name: &str, patch: impl FnOnce(&mut Vec<u8>)) -> (tempfile::TempDir, PathBuf) {
    let mut bytes = std::fs::read(fixture(name)).unwrap();
    patch(&mut bytes);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

fn put_i32(bytes: &mut [u8], word: usize, v: i32) {
    bytes[4 * (word - 1)..4 * word].copy_from_slice(&v.to_le_bytes());
}

fn put_f32(bytes: &mut [u8], word: usize, v: f32) {
    bytes[4 * (word - 1)..4 * word].copy_from_slice(&v.to_le_bytes());
}

/// The refusal of fixture `name` with `patch` applied.
fn error_of(name: &str, patch: impl FnOnce(&mut Vec<u8>)) -> String {
    let (_dir, path) = patched(name, patch);
    refused(&path, &ReadOptions::default())
}

#[test]
fn missing_stamps_are_noted_and_worked_around() {
    // Old files: no MAP stamp, no machine stamp. The byte order comes from
    // MODE and the sizes; ORIGIN is not trusted, so NXSTART (0) gives the
    // origin.
    let (_dir, path) = patched("mode2_f32.mrc", |b| b[208..216].fill(0));
    let l = load(&path).unwrap();
    check_values(&l.volume, |c, r, s| ramp(c, r, s) + 0.5);
    assert_close(l.volume.origin(), DVec3::ZERO);
    assert!(has_note(&l, "no 'MAP ' stamp"), "{:?}", l.info.notes);
    assert!(has_note(
        &l,
        "00 00 00 00 is not a known machine stamp: read little-endian"
    ));

    // A big-endian file stamped little-endian: MODE says otherwise.
    let (_dir, path) = patched("mode1_i16_be.mrc", |b| {
        b[212..214].copy_from_slice(&[0x44, 0x44])
    });
    let l = load(&path).unwrap();
    check_values(&l.volume, |c, r, s| -7.0 * ramp(c, r, s));
    assert!(
        has_note(&l, "only make sense big-endian"),
        "{:?}",
        l.info.notes
    );

    // IMOD's inverted-origin flag.
    let (_dir, path) = patched("mode2_f32.mrc", |b| {
        put_i32(b, 39, 1_146_047_817);
        put_i32(b, 40, 1 | 4);
    });
    let l = load(&path).unwrap();
    assert_close(l.volume.origin(), DVec3::new(-1.5, 2.0, -3.0));

    // Zero cell: voxel size 1 with a note; zero angles read as 90.
    let (_dir, path) = patched("mode2_f32.mrc", |b| {
        for w in 11..=16 {
            put_f32(b, w, 0.0);
        }
    });
    let l = load(&path).unwrap();
    assert_close(l.volume.spacing(), DVec3::ONE);
    assert!(has_note(&l, "gives no voxel size along X: 1 angstrom used"));
    assert!(has_note(&l, "CELLB is 0 0 0: read as 90 90 90"));
}

#[test]
fn malformed_headers_are_refused_clearly() {
    let e = error_of("mode2_f32.mrc", |b| b.truncate(1000));
    assert!(
        e.ends_with("file is 1000 bytes, shorter than the 1024-byte MRC header"),
        "{e}"
    );
    let e = error_of("mode2_f32.mrc", |b| b.truncate(1024 + 100));
    assert!(
        e.ends_with("NX NY NZ 4 3 5 of MODE 2 (4 bytes each) need 240 bytes after the 1024-byte header, but the file is 1124 bytes"),
        "{e}"
    );
    // A lying size: refused before any allocation.
    let e = error_of("mode2_f32.mrc", |b| put_i32(b, 1, 2_000_000_000));
    assert!(e.contains("NX NY NZ 2000000000 3 5 of MODE 2"), "{e}");
    let e = error_of("mode2_f32.mrc", |b| {
        for w in 1..=3 {
            put_i32(b, w, i32::MAX);
        }
    });
    assert!(
        e.contains("need 39614081201791936601413124092 bytes after the 1024-byte header"),
        "{e}"
    );
    let e = error_of("mode2_f32.mrc", |b| put_i32(b, 24, 1 << 30));
    assert!(e.contains("(with NSYMBT 1073741824)"), "{e}");
    let e = error_of("mode2_f32.mrc", |b| put_i32(b, 24, -80));
    assert!(
        e.ends_with("NSYMBT -80: the extended header cannot have a negative size"),
        "{e}"
    );
    let e = error_of("mode2_f32.mrc", |b| put_i32(b, 2, 0));
    assert!(e.ends_with("NX NY NZ are 4 0 5: 0 is not a size"), "{e}");
    for (mode, want) in [
        (3, "MODE 3: complex (Fourier transform) data"),
        (4, "MODE 4: complex (Fourier transform) data"),
        (101, "MODE 101: 4-bit samples"),
        (16, "MODE 16: not a real-valued MRC mode"),
    ] {
        let e = error_of("mode2_f32.mrc", |b| put_i32(b, 4, mode));
        assert!(e.contains(want), "{e}");
    }
    let e = error_of("mode2_f32.mrc", |b| put_i32(b, 18, 1));
    assert!(
        e.ends_with("MAPC MAPR MAPS are 1 1 3: not an order of the axes 1, 2, 3"),
        "{e}"
    );
    let e = error_of("mode2_f32.mrc", |b| put_f32(b, 16, 200.0));
    assert!(e.contains("the angle 200 cannot be a cell angle"), "{e}");
    // A skewed cell of which the map covers only part: its box is read
    // (tests/crystal_maps.rs), unless resampling it would exceed the
    // memory limit.
    let mut bytes = fs::read(fixture("mode2_f32.mrc")).unwrap();
    put_f32(&mut bytes, 16, 100.0);
    put_i32(&mut bytes, 8, 8);
    let dir = tempfile::tempdir().unwrap();
    let part = dir.path().join("part.mrc");
    fs::write(&part, &bytes).unwrap();
    let l = load(&part).unwrap();
    assert!(l.info.nan_is_empty);
    let opts = ReadOptions {
        max_memory: 400,
        ..ReadOptions::default()
    };
    let err = read(&part, &opts).unwrap_err();
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    // A map that is one section thin cannot be a volume.
    let e = error_of("mode2_f32.mrc", |b| put_i32(b, 3, 1));
    assert!(e.contains("at least 2 points"), "{e}");
}

/// Header words set to extreme values, and truncations of the files:
/// each read either succeeds or fails with a one-line error naming the
/// file; none panics or allocates past the file's size.
#[test]
fn hostile_headers_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    // Every word of one file, the size and geometry words of a skewed one.
    for (name, words, values) in [
        ("mode2_f32.mrc", 56, &[-1, i32::MAX, i32::MIN][..]),
        ("hexagonal.ccp4", 24, &[0, 0x7f80_0000][..]),
    ] {
        let good = std::fs::read(fixture(name)).unwrap();
        let path = dir.path().join(name);
        let check = |bytes: &[u8]| {
            std::fs::write(&path, bytes).unwrap();
            read_or_refuse(&path, &ReadOptions::default());
        };
        for word in 1..=words {
            for &v in values {
                let mut b = good.clone();
                put_i32(&mut b, word, v);
                check(&b);
            }
        }
        for cut in truncations(&good, 97) {
            check(cut);
        }
    }
}
