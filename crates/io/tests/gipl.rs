//! GIPL images (formats/gipl.rs), written at test time by SimpleITK
//! (ITK's GiplImageIO, `gipl/write_files.py`) and read back by it as the
//! oracle: every value, spacing and origin, in five sample types and
//! gzip; then lying and mangled headers, refused in one line.

mod common;

use std::path::Path;
use std::sync::OnceLock;

use common::{mutations_never_panic, read_or_refuse, refused, truncations};
use volray_core::glam::DVec3;
use volray_io::{ReadOptions, VolumeFormat, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(&DIR, &["numpy", "SimpleITK"], "tests/gipl/write_files.py")
}

fn vec3(v: &serde_json::Value) -> DVec3 {
    DVec3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

#[test]
fn simpleitk_gipl_images_read_as_simpleitk_reads_them() {
    let Some(dir) = files() else { return };
    for (name, stored) in [
        ("i16.gipl", "i16"),
        ("u8.gipl", "u8"),
        ("f32.gipl", "f32"),
        ("f64.gipl.gz", "f64"),
        ("u16.gipl", "u16"),
    ] {
        let text = std::fs::read_to_string(dir.join(format!("{name}.json"))).unwrap();
        let want: serde_json::Value = serde_json::from_str(&text).unwrap();
        let l = read(&dir.join(name), &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(l.format, VolumeFormat::Gipl, "{name}");
        assert!(
            l.info.stored_type.starts_with(stored),
            "{name}: {}",
            l.info.stored_type
        );
        let v = &l.volume;
        assert_eq!(v.dims(), [4, 3, 5], "{name}");
        assert!(
            (v.spacing() - vec3(&want["spacing"])).length() < 1e-9,
            "{name}"
        );
        assert!(
            (v.origin() - vec3(&want["origin"])).length() < 1e-9,
            "{name}"
        );
        let values = want["values"].as_array().unwrap();
        for k in 0..5 {
            for j in 0..3 {
                for i in 0..4 {
                    let w = values[i + 4 * (j + 3 * k)].as_f64().unwrap() as f32;
                    assert_eq!(v.get(i, j, k), w, "{name} at ({i}, {j}, {k})");
                }
            }
        }
    }
    // Known by its magic number under any name.
    let renamed = dir.join("image.bin");
    std::fs::copy(dir.join("i16.gipl"), &renamed).unwrap();
    let l = read(&renamed, &ReadOptions::default()).unwrap();
    assert_eq!(l.format, VolumeFormat::Gipl);
}

#[test]
fn lying_and_mangled_gipl_headers_are_refused_in_one_line() {
    let Some(dir) = files() else { return };
    let good = std::fs::read(dir.join("i16.gipl")).unwrap();
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("bad.gipl");
    let refuse = |bytes: &[u8], want: &str| {
        std::fs::write(&path, bytes).unwrap();
        let msg = refused(&path, &ReadOptions::default());
        assert!(msg.contains(want), "{msg}\n  wanted: {want}");
    };
    let mut huge = good.clone();
    huge[0..6].copy_from_slice(&[0xff, 0xff, 0xff, 0xff, 0xff, 0xff]);
    refuse(
        &huge,
        "the header declares 65535 x 65535 x 65535 x 1 samples of i16",
    );
    refuse(&good[..good.len() - 2], "but the file is a 374-byte file");
    let mut binary = good.clone();
    binary[8..10].copy_from_slice(&1u16.to_be_bytes());
    refuse(&binary, "image type 1 (binary)");
    let mut complex = good.clone();
    complex[8..10].copy_from_slice(&192u16.to_be_bytes());
    refuse(&complex, "image type 192 (complex)");
    let mut spacing = good.clone();
    spacing[10..14].copy_from_slice(&(-1.0f32).to_be_bytes());
    refuse(&spacing, "pixdim 1 is -1: a spacing must be positive");
    let mut magic = good.clone();
    magic[252] = 0;
    refuse(&magic, "no GIPL magic number at byte 252");
    for cut in truncations(&good, 29) {
        std::fs::write(&path, cut).unwrap();
        read_or_refuse(&path, &ReadOptions::default());
    }
    let files: Vec<_> = ["i16.gipl", "f64.gipl.gz"]
        .iter()
        .map(|n| dir.join(n))
        .collect();
    mutations_never_panic(&files, "m.gipl", 13);
}
