//! Zarr and OME-Zarr: stores written at test time by zarr-python (v2 and
//! v3 arrays: gzip, zstd, blosc, sharded, a missing chunk) and
//! ome-zarr-py (0.4 on Zarr v2, 0.5 on Zarr v3, two levels with scale and
//! translation), read back and compared value for value with the arrays
//! numpy dumped beside them (`tests/zarr/write_stores.py`); then hostile
//! stores made from them: truncated chunks, shapes that lie, unknown
//! codecs and data types, invalid JSON.
//!
//! The writers run in `target/pyenv` (zarr, ome-zarr and numpy from PyPI,
//! which `.ci/run` installs); without them these tests fail under
//! `CI=true` and are skipped elsewhere.

mod common;

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use volray_core::SourceErrorKind;
use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, open_lazy, read};

/// The directory the writers filled, or `None` (with the reason printed)
/// where they are missing outside CI.
fn stores() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["zarr", "ome_zarr", "numcodecs", "numpy"],
        "tests/zarr/write_stores.py",
    )
}

fn opts(level: Option<usize>, frame: Option<usize>, channel: Option<usize>) -> ReadOptions {
    ReadOptions {
        level,
        frame,
        channel,
        ..ReadOptions::default()
    }
}

fn load(path: &Path, o: &ReadOptions) -> Loaded {
    read(path, o).unwrap_or_else(|e| panic!("{e}"))
}

/// Asserts every value of `loaded` equals the one numpy dumped to `npy`
/// (transposed to x, y, z, which volray's .npy reader takes as a[x, y, z]).
fn assert_same_values(loaded: &Loaded, npy: &Path) {
    let expected = load(npy, &ReadOptions::default()).volume;
    assert_eq!(loaded.volume.dims(), expected.dims(), "{}", npy.display());
    let (got, want) = (loaded.volume.values(), expected.values());
    let differ = got.iter().zip(want.iter()).position(|(a, b)| a != b);
    assert_eq!(differ, None, "{}: first differing index", npy.display());
}

const PLAIN: [&str; 7] = [
    "v2_gzip",
    "v2_forder",
    "v2_blosc",
    "v2_zstd_u16",
    "v3_zstd",
    "v3_gzip_f64",
    "v3_sharded_blosc",
];

#[test]
fn every_value_of_each_plain_zarr_array_equals_the_writers() {
    let Some(dir) = stores() else { return };
    for name in PLAIN {
        let path = dir.join(format!("{name}.zarr"));
        let loaded = load(&path, &ReadOptions::default());
        assert_eq!(loaded.format, VolumeFormat::Zarr, "{name}");
        assert_same_values(&loaded, &dir.join(format!("{name}.npy")));
        assert_eq!(loaded.volume.spacing(), DVec3::ONE, "{name}");
        assert_eq!(loaded.volume.origin(), DVec3::ZERO, "{name}");
        assert_eq!(loaded.info.levels.len(), 1, "{name}");
    }
    // Types volray keeps are kept; float64 becomes float32.
    let kept = |name: &str| {
        load(&dir.join(format!("{name}.zarr")), &ReadOptions::default())
            .volume
            .sample_type()
    };
    assert_eq!(format!("{:?}", kept("v2_gzip")), "I16");
    assert_eq!(format!("{:?}", kept("v3_sharded_blosc")), "U8");
    assert_eq!(format!("{:?}", kept("v3_gzip_f64")), "F32");
    assert_eq!(format!("{:?}", kept("v2_forder")), "I8");
}

#[test]
fn a_missing_chunk_reads_as_the_fill_value() {
    let Some(dir) = stores() else { return };
    for (name, fill, v) in [("v2_gzip", -7.0, "2"), ("v3_zstd", 9.0, "3")] {
        let loaded = load(&dir.join(format!("{name}.zarr")), &ReadOptions::default());
        // The first chunk is (z, y, x) 2 x 3 x 4, never written.
        for (i, j, k) in [(0, 0, 0), (3, 2, 1), (1, 1, 0)] {
            assert_eq!(loaded.volume.get(i, j, k), fill, "{name} at {i},{j},{k}");
        }
        assert_ne!(loaded.volume.get(4, 0, 0), fill, "{name}: the next chunk");
        let format = loaded.info.header.iter().find(|(k, _)| k == "zarr_format");
        assert_eq!(format.map(|(_, f)| f.as_str()), Some(v));
    }
}

#[test]
fn ome_zarr_levels_time_points_and_channels_equal_the_writers_with_their_geometry() {
    let Some(dir) = stores() else { return };
    // Level 0: scale (z, y, x) 2, 0.5, 0.25 at 10, -3, 1.5; level 1 halves y, x.
    let geometry = [
        (
            [8, 6, 4],
            DVec3::new(0.25, 0.5, 2.0),
            DVec3::new(1.5, -3.0, 10.0),
        ),
        (
            [4, 3, 4],
            DVec3::new(0.5, 1.0, 2.0),
            DVec3::new(1.625, -2.75, 10.0),
        ),
    ];
    for (name, version) in [("ome04", "0.4"), ("ome05", "0.5")] {
        let path = dir.join(format!("{name}.zarr"));
        for (level, (dims, spacing, origin)) in geometry.iter().enumerate() {
            for t in 0..2 {
                for c in 0..3 {
                    let loaded = load(&path, &opts(Some(level), Some(t), Some(c)));
                    let npy = dir.join(format!("{name}_{level}_t{t}_c{c}.npy"));
                    assert_same_values(&loaded, &npy);
                    assert_eq!(loaded.volume.dims(), *dims, "{name} level {level}");
                    assert_eq!(loaded.volume.spacing(), *spacing, "{name} level {level}");
                    assert_eq!(loaded.volume.origin(), *origin, "{name} level {level}");
                    let i = &loaded.info;
                    assert_eq!((i.time_points, i.channels), (2, 3));
                    assert_eq!((i.time_point, i.channel), (t, c));
                    assert_eq!((i.frames, i.frame), (6, 3 * t + c));
                    assert_eq!(loaded.info.level, level);
                }
            }
        }
        let loaded = load(&path, &ReadOptions::default());
        assert_same_values(&loaded, &dir.join(format!("{name}_0_t0_c0.npy")));
        assert_eq!(loaded.info.length_unit.as_deref(), Some("micrometer"));
        let version_field = loaded
            .info
            .header
            .iter()
            .find(|(k, _)| k == "OME-Zarr version");
        assert_eq!(version_field.map(|(_, v)| v.as_str()), Some(version));
        let levels = &loaded.info.levels;
        assert_eq!(levels.len(), 2);
        assert_eq!(levels[1].dims, [4, 3, 4]);
        assert_eq!(levels[1].shape, vec![2, 3, 4, 3, 4]);
        assert_eq!(levels[0].chunk_shape, Some(vec![1, 1, 2, 3, 4]));
        assert_eq!(levels[0].spacing, [0.25, 0.5, 2.0]);
        assert_eq!(levels[1].origin, [1.625, -2.75, 10.0]);
    }
}

#[test]
fn every_box_read_lazily_equals_the_same_box_of_the_level_read_whole() {
    let Some(dir) = stores() else { return };
    let cases = [
        ("v3_sharded_blosc", opts(None, None, None)),
        ("v2_blosc", opts(None, None, None)),
        ("v3_gzip_f64", opts(None, None, None)),
        ("ome05", opts(Some(0), Some(1), Some(2))),
        ("ome04", opts(Some(1), Some(0), Some(1))),
    ];
    for (name, o) in cases {
        let path = dir.join(format!("{name}.zarr"));
        let whole = load(&path, &o).volume;
        let lazy = open_lazy(&path, &o)
            .unwrap()
            .expect("a Zarr store opens lazily");
        let source = &lazy.source;
        assert_eq!(source.grid().dims, whole.dims(), "{name}");
        assert_eq!(source.grid().spacing, whole.spacing(), "{name}");
        assert_eq!(source.grid().origin, whole.origin(), "{name}");
        assert_eq!(source.sample_type(), whole.sample_type(), "{name}");
        let d = whole.dims();
        // Every box of at least 2 voxels a side on a coarse lattice of corners.
        let ends = |n: usize| -> Vec<(usize, usize)> {
            let cuts: Vec<usize> = (0..=n).step_by(n.div_ceil(3).max(1)).chain([n]).collect();
            let mut out = Vec::new();
            for &lo in &cuts {
                for &hi in &cuts {
                    if lo + 2 <= hi && hi <= n {
                        out.push((lo, hi));
                    }
                }
            }
            out
        };
        let mut boxes = 0;
        for &(x0, x1) in &ends(d[0]) {
            for &(y0, y1) in &ends(d[1]) {
                for &(z0, z1) in &ends(d[2]) {
                    let (lo, hi) = ([x0, y0, z0], [x1, y1, z1]);
                    let got = source.read_box(lo, hi).unwrap();
                    assert_eq!(got, whole.sub_box(lo, hi), "{name} box {lo:?}..{hi:?}");
                    boxes += 1;
                }
            }
        }
        assert!(boxes >= 8, "{name}: {boxes} boxes");
        let e = source.read_box([0; 3], [d[0] + 1, d[1], d[2]]).unwrap_err();
        assert_eq!(e.kind, SourceErrorKind::OutsideGrid, "{e}");
        assert!(
            e.message.contains(name) && e.message.contains("inside the"),
            "{e}"
        );
    }
    // Formats read whole or mapped are not opened lazily.
    let npy = dir.join("v2_gzip.npy");
    assert!(open_lazy(&npy, &ReadOptions::default()).unwrap().is_none());
}

#[test]
fn info_gives_each_levels_chunks_shards_codecs_and_bytes() {
    let Some(dir) = stores() else { return };
    let path = dir.join("v3_sharded_blosc.zarr");
    let level = &load(&path, &ReadOptions::default()).info.levels[0];
    assert_eq!(level.chunk_shape, Some(vec![2, 3, 4]));
    assert_eq!(level.shard_shape, Some(vec![4, 6, 8]));
    assert!(
        level.codecs.starts_with("sharding_indexed("),
        "{}",
        level.codecs
    );
    assert!(level.codecs.contains("blosc (zstd)"), "{}", level.codecs);
    assert_eq!(level.bytes_in_memory, 6 * 6 * 8);
    // Two shards along z, one along y and x: the two files under c/.
    let shards: u64 = ["c/0/0/0", "c/1/0/0"]
        .iter()
        .map(|s| fs::metadata(path.join(s)).unwrap().len())
        .sum();
    // Not counted on opening; counted on asking, and not past a limit.
    assert_eq!(level.bytes_stored, None);
    assert_eq!(level.count_bytes_stored(2), Some(shards));
    assert_eq!(level.count_bytes_stored(1), None);
    let v2 = load(&dir.join("v2_blosc.zarr"), &ReadOptions::default());
    assert_eq!(v2.info.levels[0].codecs, "blosc (lz4)");
    assert_eq!(v2.info.levels[0].bytes_in_memory, 4 * 5 * 9 * 4);
}

/// The one-line message of reading `path` with `o`, which must fail.
fn refused(path: &Path, o: &ReadOptions) -> (String, IoError) {
    let err = read(path, o).expect_err("must be refused");
    let text = err.to_string();
    assert!(!text.contains('\n'), "{text}");
    assert!(text.starts_with(&path.display().to_string()), "{text}");
    (text, err)
}

#[test]
fn levels_time_points_and_channels_out_of_range_are_refused() {
    let Some(dir) = stores() else { return };
    let path = dir.join("ome04.zarr");
    let (text, _) = refused(&path, &opts(Some(2), None, None));
    assert!(text.ends_with("level 2 is out of range: the image holds 2 levels (multiscales datasets), numbered from 0"), "{text}");
    let (_, err) = refused(&path, &opts(None, Some(2), None));
    assert!(
        matches!(err, IoError::FrameOutOfRange { frame: 2, .. }),
        "{err}"
    );
    let (text, _) = refused(&path, &opts(None, None, Some(3)));
    assert!(
        text.contains("channel 3 is out of range: the image holds 3 channels"),
        "{text}"
    );
    let npy = dir.join("v2_gzip.npy");
    let (_, err) = refused(&npy, &opts(Some(0), None, None));
    assert!(matches!(err, IoError::LevelNotApplicable { .. }), "{err}");
    let (_, err) = refused(&npy, &opts(None, None, Some(1)));
    assert!(matches!(err, IoError::ChannelOutOfRange { .. }), "{err}");
}

/// A copy of store `name` in a new directory, to break.
fn copy_store(dir: &Path, name: &str) -> (tempfile::TempDir, PathBuf) {
    fn copy(from: &Path, to: &Path) {
        fs::create_dir_all(to).unwrap();
        for e in fs::read_dir(from).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_dir() {
                copy(&e.path(), &to.join(e.file_name()));
            } else {
                fs::copy(e.path(), to.join(e.file_name())).unwrap();
            }
        }
    }
    let tmp = tempfile::tempdir().unwrap();
    let to = tmp.path().join(format!("{name}.zarr"));
    copy(&dir.join(format!("{name}.zarr")), &to);
    (tmp, to)
}

/// Replaces `from` by `to` in the file `path`, which must hold it.
fn edit(path: &Path, from: &str, to: &str) {
    let text = fs::read_to_string(path).unwrap();
    assert!(text.contains(from), "{}: no {from}", path.display());
    fs::write(path, text.replacen(from, to, 1)).unwrap();
}

#[test]
fn hostile_stores_are_refused_in_one_line_before_allocating() {
    let Some(dir) = stores() else { return };
    let none = ReadOptions::default();

    // A truncated chunk: gzip's stream ends early.
    let (_t, path) = copy_store(dir, "v2_gzip");
    let chunk = path.join("0.0.1");
    let bytes = fs::read(&chunk).unwrap();
    fs::write(&chunk, &bytes[..bytes.len() / 2]).unwrap();
    let (text, _) = refused(&path, &none);
    assert!(text.contains("cannot read Zarr chunks"), "{text}");

    // A truncated shard: its index at the end is gone.
    let (_t, path) = copy_store(dir, "v3_sharded_blosc");
    let shard = path.join("c/0/0/0");
    let bytes = fs::read(&shard).unwrap();
    fs::write(&shard, &bytes[..bytes.len() - 7]).unwrap();
    let (text, _) = refused(&path, &none);
    assert!(text.contains("cannot read Zarr chunks"), "{text}");

    // A shape that lies: 10^15 values are refused against the limit.
    let (_t, path) = copy_store(dir, "v3_zstd");
    edit(
        &path.join("zarr.json"),
        "\"shape\": [\n    5,\n    6,\n    7\n  ]",
        "\"shape\": [100000, 100000, 100000]",
    );
    let (_, err) = refused(&path, &none);
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    // So is a chunk that lies, in a small array.
    let (_t, path) = copy_store(dir, "v2_zstd_u16");
    edit(
        &path.join(".zarray"),
        "\"chunks\": [\n    2,\n    2,\n    2\n  ]",
        "\"chunks\": [1000000, 1000000, 1000000]",
    );
    let (text, err) = refused(&path, &none);
    assert!(matches!(err, IoError::OverMemoryLimit { .. }), "{err}");
    assert!(text.contains("Zarr chunk shape"), "{text}");

    // An unknown codec, a data type volray does not read, invalid JSON.
    let (_t, path) = copy_store(dir, "v3_zstd");
    edit(
        &path.join("zarr.json"),
        "\"name\": \"zstd\"",
        "\"name\": \"frobnicate\"",
    );
    let (text, _) = refused(&path, &none);
    assert!(text.contains("frobnicate"), "{text}");
    let (_t, path) = copy_store(dir, "v2_zstd_u16");
    edit(&path.join(".zarray"), "\"<u2\"", "\"<f2\"");
    let (text, _) = refused(&path, &none);
    assert!(
        text.contains("Zarr data type \"<f2\" is not supported"),
        "{text}"
    );
    edit(&path.join(".zarray"), "\"<f2\"", "\"<q9\"");
    let (text, _) = refused(&path, &none);
    assert!(text.contains("not a readable Zarr array"), "{text}");
    let (_t, path) = copy_store(dir, "ome05");
    fs::write(path.join("zarr.json"), "{\"node_type\": \"group\", ").unwrap();
    let (text, _) = refused(&path, &none);
    assert!(text.contains("invalid JSON"), "{text}");
    // A level that climbs out of the image.
    let (_t, path) = copy_store(dir, "ome04");
    edit(
        &path.join(".zattrs"),
        "\"path\": \"s1\"",
        "\"path\": \"../s1\"",
    );
    let (text, _) = refused(&path, &none);
    assert!(text.contains("dataset 1 has path \"../s1\""), "{text}");
}

#[test]
fn a_zarr_directory_is_known_by_its_metadata_not_its_name() {
    let Some(dir) = stores() else { return };
    let (_t, path) = copy_store(dir, "v3_zstd");
    let renamed = path.with_file_name("scan");
    fs::rename(&path, &renamed).unwrap();
    assert_eq!(
        load(&renamed, &ReadOptions::default()).format,
        VolumeFormat::Zarr
    );
    // A directory without Zarr metadata is still taken for DICOM.
    let empty = tempfile::tempdir().unwrap();
    let (text, _) = refused(empty.path(), &ReadOptions::default());
    assert!(text.to_lowercase().contains("dicom"), "{text}");
    // A `.zarr` directory missing its metadata says so.
    let bare = empty.path().join("scan.zarr");
    fs::create_dir(&bare).unwrap();
    let (text, _) = refused(&bare, &ReadOptions::default());
    assert!(
        text.ends_with(
            "not a Zarr group or array: no zarr.json (v3), .zarray, .zgroup or .zattrs (v2)"
        ),
        "{text}"
    );
}
