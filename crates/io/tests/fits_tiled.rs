//! Tile-compressed FITS images (§10 of the standard) written at test time
//! by astropy's `CompImageHDU` (`tests/fits_tiled/write_files.py`), read
//! against what astropy decompresses them to: Rice at 1, 2 and 4 bytes,
//! GZIP_1 and GZIP_2, tiles cut at the image's edges, BZERO's unsigned
//! convention, floats quantised with subtractive dithering (1 and 2) or
//! none, and floats kept exactly; PLIO and HCOMPRESS refused by name.
//!
//! The writer runs in `target/pyenv` (which `.ci/run` installs); without
//! astropy these tests fail under `CI=true` and are skipped elsewhere.

mod common;

use std::path::Path;
use std::sync::OnceLock;

use volray_io::{ReadOptions, VolumeFormat, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["astropy", "numpy"],
        "tests/fits_tiled/write_files.py",
    )
}

/// The image `name` as volray reads it, against astropy's values (its
/// `.npy`, (z, y, x)): equal, NaN where astropy's are; `exact` or within
/// one part in 10^6 of the value (a float image's values are computed in
/// double precision and rounded once to `f32` by both).
fn same_as_astropy(dir: &Path, name: &str, exact: bool) {
    let l = read(&dir.join(format!("{name}.fits")), &ReadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::Fits);
    let want = read(&dir.join(format!("{name}.npy")), &ReadOptions::default()).unwrap();
    let [z, y, x] = want.volume.dims();
    assert_eq!(l.volume.dims(), [x, y, z], "{name}");
    for k in 0..z {
        for j in 0..y {
            for i in 0..x {
                let (got, w) = (l.volume.get(i, j, k), want.volume.get(k, j, i));
                let ok = if w.is_nan() {
                    got.is_nan()
                } else if exact {
                    got == w
                } else {
                    (got - w).abs() <= 1e-6 * w.abs().max(1.0)
                };
                assert!(ok, "{name}: ({i}, {j}, {k}) = {got}, astropy {w}");
            }
        }
    }
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("is a tile-compressed image") && n.contains("decompressed as read")),
        "{name}: {:?}",
        l.info.notes
    );
}

#[test]
fn integer_images_decompress_to_astropys_values_exactly() {
    let Some(dir) = files() else { return };
    for name in [
        "int16_rice_1",
        "int16_gzip_1",
        "int16_gzip_2",
        "uint16_rice",
        "int32_rice",
        "uint8_rice",
    ] {
        same_as_astropy(dir, name, true);
    }
}

#[test]
fn quantised_floats_undo_the_dithering_as_astropy_does() {
    let Some(dir) = files() else { return };
    for name in ["float_dither1", "float_dither2", "float_nodither"] {
        same_as_astropy(dir, name, false);
    }
    // SUBTRACTIVE_DITHER_2 keeps zeros exact.
    let l = read(&dir.join("float_dither2.fits"), &ReadOptions::default()).unwrap();
    assert_eq!(l.volume.get(0, 0, 1), 0.0);
    same_as_astropy(dir, "float_lossless", true);
}

#[test]
fn plio_and_hcompress_are_refused_by_name() {
    let Some(dir) = files() else { return };
    for (name, method) in [("plio", "PLIO_1"), ("hcompress", "HCOMPRESS_1")] {
        let msg = common::refused(&dir.join(format!("{name}.fits")), &ReadOptions::default());
        assert!(
            msg.contains(&format!(
                "ZCMPTYPE '{method}' is not read (RICE_1, GZIP_1 and GZIP_2 are)"
            )) && msg.contains("funpack"),
            "{msg}"
        );
    }
}

#[test]
fn a_compressed_table_over_the_memory_limit_is_refused_before_it_is_read() {
    let Some(dir) = files() else { return };
    let small = ReadOptions {
        max_memory: 1000,
        ..ReadOptions::default()
    };
    let msg = common::refused(&dir.join("int16_rice_1.fits"), &small);
    assert!(msg.contains("memory limit"), "{msg}");
}

#[test]
fn every_prefix_and_byte_change_of_a_compressed_image_reads_or_is_refused_in_one_line() {
    // The fixture (astropy's RICE_1 of the i16 volume): its table's rows
    // and heap cut anywhere or changed at random, never a panic.
    let bytes = std::fs::read(common::fixture("fits", "compressed.fits")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.fits");
    let mut rng = common::Lcg(43);
    let data = 2 * 2880;
    let mut variants: Vec<Vec<u8>> = (data..bytes.len())
        .step_by(7)
        .map(|n| bytes[..n].to_vec())
        .collect();
    for n in 0..300 {
        // Changes within the table's data, where the decoder reads.
        let mut v = bytes.clone();
        for _ in 0..1 + n % 4 {
            let at = data + rng.below(bytes.len() - data);
            v[at] = rng.below(256) as u8;
        }
        variants.push(v);
    }
    for v in variants {
        std::fs::write(&path, &v).unwrap();
        common::read_or_refuse(&path, &ReadOptions::default());
    }
}
