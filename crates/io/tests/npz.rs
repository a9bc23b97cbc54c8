//! NumPy `.npz` archives (formats/npz.rs), written at test time by
//! `numpy.savez` and `numpy.savez_compressed` (`npz/write_files.py`):
//! every array read as `np.load` gives it (`a[x, y, z]`), picked with
//! `--array`, the first by default with a note; lying, corrupt and
//! mangled archives refused in one line.

mod common;

use std::path::Path;
use std::sync::OnceLock;

use common::{check_voxels, mutations_never_panic, read_or_refuse, refused, truncations};
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(&DIR, &["numpy"], "tests/npz/write_files.py")
}

fn array(name: &str) -> ReadOptions {
    ReadOptions {
        array: Some(name.into()),
        ..ReadOptions::default()
    }
}

fn load(path: &Path, opts: &ReadOptions) -> Loaded {
    read(path, opts).unwrap_or_else(|e| panic!("{e}"))
}

fn ramp(i: usize, j: usize, k: usize) -> f32 {
    (i + 10 * j + 100 * k) as f32
}

#[test]
fn savez_and_savez_compressed_arrays_read_as_np_load_gives_them() {
    let Some(dir) = files() else { return };
    let l = load(&dir.join("one.npz"), &ReadOptions::default());
    assert_eq!(l.format, VolumeFormat::Npz);
    check_voxels("one", &l.volume, [4, 3, 5], ramp);
    assert_eq!(l.info.arrays, ["arr_0"]);
    assert_eq!(l.info.stored_type, "<f4");

    let compressed = dir.join("compressed.npz");
    let l = load(&compressed, &ReadOptions::default());
    check_voxels("arr_0", &l.volume, [4, 3, 5], |i, j, k| ramp(i, j, k) + 0.5);
    assert!(
        l.info.notes[0].starts_with(
            "array \"arr_0\" (the first) of the 2 the archive holds: \"arr_0\", \"arr_1\""
        ),
        "{:?}",
        l.info.notes
    );
    assert!(
        l.info.header[0].1.contains("deflated"),
        "{:?}",
        l.info.header
    );
    let l = load(&compressed, &array("arr_1"));
    check_voxels("arr_1", &l.volume, [4, 3, 5], ramp);
    assert_eq!(l.info.header[2].1, "True", "fortran_order");

    let named = dir.join("named.npz");
    let l = load(&named, &array("potential"));
    check_voxels("potential", &l.volume, [4, 3, 5], |i, j, k| -ramp(i, j, k));
    assert_eq!(l.info.array.as_deref(), Some("potential"));
    assert_eq!(l.info.arrays, ["density", "potential", "flat"]);
    let err = read(&named, &array("spin")).unwrap_err();
    assert!(matches!(err, IoError::NoSuchArray { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("the archive holds the arrays \"density\", \"potential\", \"flat\""),
        "{err}"
    );
    // A 2-D array is refused as a .npy file's would be.
    let err = read(&named, &array("flat")).unwrap_err();
    assert!(!err.is_io_failure(), "{err}");

    // Known by content (a zip's first header) under any name.
    let renamed = dir.join("arrays.bin");
    std::fs::copy(dir.join("one.npz"), &renamed).unwrap();
    assert_eq!(
        load(&renamed, &ReadOptions::default()).format,
        VolumeFormat::Npz
    );
}

#[test]
fn an_array_over_the_memory_limit_is_refused_before_it_is_read() {
    let Some(dir) = files() else { return };
    let opts = ReadOptions {
        max_memory: 100_000,
        ..ReadOptions::default()
    };
    let msg = refused(&dir.join("zeros.npz"), &opts);
    assert!(msg.contains("shape"), "{msg}");
    assert!(msg.contains("limit"), "{msg}");
}

#[test]
fn lying_corrupt_and_mangled_archives_are_refused_in_one_line() {
    let Some(dir) = files() else { return };
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("bad.npz");
    let zeros = std::fs::read(dir.join("zeros.npz")).unwrap();
    // The deflated data of 1 MB of zeros flipped: a corrupt stream.
    let mut corrupt = zeros.clone();
    let at = corrupt.len() / 2;
    for b in &mut corrupt[at - 20..at] {
        *b ^= 0x55;
    }
    std::fs::write(&path, &corrupt).unwrap();
    let msg = refused(&path, &ReadOptions::default());
    assert!(msg.contains("\"big\""), "{msg}");
    // Not a zip at all past its magic; a zip of no arrays.
    std::fs::write(&path, b"PK\x03\x04 and then nothing").unwrap();
    assert!(refused(&path, &ReadOptions::default()).contains("not a readable .npz (zip) archive"));
    for name in ["one.npz", "compressed.npz", "named.npz"] {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        for cut in truncations(&bytes, 53) {
            std::fs::write(&path, cut).unwrap();
            read_or_refuse(&path, &ReadOptions::default());
        }
    }
    let files: Vec<_> = ["one.npz", "compressed.npz", "named.npz"]
        .iter()
        .map(|n| dir.join(n))
        .collect();
    mutations_never_panic(&files, "m.npz", 11);
}
