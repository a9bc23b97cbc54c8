//! Text formats behind gzip, bzip2 or xz (shared/packed.rs): each read
//! compressed gives the volume, geometry and header the plain file gives,
//! known by its content whatever its name; a compressed format volray
//! reads plain only is refused naming the compression and the way round;
//! a compressed file that lies about its size, or is corrupt, is refused
//! in one line before anything large is allocated.

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::{fixture, refused, refused_at};
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

fn load(path: &Path) -> Loaded {
    read(path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn bzip2(bytes: &[u8]) -> Vec<u8> {
    let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// Writes `bytes` as `name` in `dir`.
fn put(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The plain fixture and its compressed copy read alike, but for the note
/// that says how it was read.
fn same_as_plain(plain: &Loaded, packed: &Loaded, codec: &str) {
    assert_eq!(packed.format, plain.format);
    assert_eq!(packed.volume, plain.volume);
    assert_eq!(packed.info.header, plain.info.header);
    assert_eq!(packed.info.length_unit, plain.info.length_unit);
    let note = format!("read through {codec} decompression");
    let extra: Vec<&String> = (packed.info.notes.iter())
        .filter(|n| !plain.info.notes.contains(n))
        .collect();
    assert_eq!(extra.len(), 1, "{:?}", packed.info.notes);
    assert!(extra[0].starts_with(&note), "{extra:?}");
}

#[test]
fn gzipped_and_bzipped_text_files_read_as_the_plain_ones_whatever_their_names() {
    let dir = tempfile::tempdir().unwrap();
    let plain_dir = tempfile::tempdir().unwrap();
    for (source, format) in [
        ("cube/ramp_bohr.cube", VolumeFormat::Cube),
        ("cube/hexagonal.cube", VolumeFormat::Cube),
        ("chgcar/CHGCAR_ortho", VolumeFormat::Chgcar),
        ("chgcar/CHGCAR_spin", VolumeFormat::Chgcar),
        ("vtk/legacy_f32_ascii.vtk", VolumeFormat::VtkLegacy),
        ("vtk/legacy_f32.vtk", VolumeFormat::VtkLegacy),
        ("vtk/legacy_i16.vtk", VolumeFormat::VtkLegacy),
    ] {
        let (kind, name) = source.split_once('/').unwrap();
        let bytes = std::fs::read(fixture(kind, name)).unwrap();
        let packings = [
            ("gzip", gzip(&bytes), "gz"),
            ("bzip2", bzip2(&bytes), "bz2"),
        ];
        for (codec, packed, suffix) in packings {
            // By the name's first word (CHGCAR.gz), by content under a
            // name that says only the compression, and under no hint;
            // against the plain file under the name less its suffix.
            for file in [
                format!("{name}.{suffix}"),
                format!("data.{suffix}"),
                "data".into(),
            ] {
                let bare = file.trim_end_matches(&format!(".{suffix}"));
                let plain = load(&put(plain_dir.path(), bare, &bytes));
                assert_eq!(plain.format, format, "{source}");
                let path = put(dir.path(), &file, &packed);
                let l = read(&path, &ReadOptions::default())
                    .unwrap_or_else(|e| panic!("{source} as {file}: {e}"));
                same_as_plain(&plain, &l, codec);
            }
        }
    }
}

fn xz_files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(&DIR, &["lzma"], "tests/packed/write_xz.py")
}

#[test]
fn xz_files_written_by_python_read_as_the_plain_ones() {
    let Some(dir) = xz_files() else { return };
    for (name, kind, source) in [
        ("ramp.cube.xz", "cube", "ramp_bohr.cube"),
        ("CHGCAR.xz", "chgcar", "CHGCAR_ortho"),
    ] {
        let plain = load(&fixture(kind, source));
        same_as_plain(&plain, &load(&dir.join(name)), "xz");
    }
}

#[test]
fn a_compressed_format_read_plain_only_is_refused_naming_the_way_round() {
    let dir = tempfile::tempdir().unwrap();
    let mha = std::fs::read(fixture("metaimage", "f32.mha")).unwrap();
    let msg = refused_at(
        dir.path(),
        "f32.mha.gz",
        &gzip(&mha),
        &ReadOptions::default(),
    );
    assert!(
        msg.ends_with("a gzip-compressed MetaImage file, which volray reads uncompressed only: decompress it first (gunzip -k FILE)"),
        "{msg}"
    );
    let msg = refused_at(dir.path(), "f32.bz2", &bzip2(&mha), &ReadOptions::default());
    assert!(msg.contains("a bzip2-compressed MetaImage file"), "{msg}");
    assert!(msg.contains("(bunzip2 -k FILE)"), "{msg}");
}

#[test]
fn a_gzip_bomb_behind_a_lying_header_is_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let header = |n: usize| format!("c1\nc2\n 0 0 0 0\n {n} 1 0 0\n {n} 0 1 0\n {n} 0 0 1\n");
    // 1000³ values declared (4 GB as f32) over 20 MB of zeros that gzip
    // squeezes into about 20 kB: more than the stream can hold.
    let mut text = header(1000).into_bytes();
    text.extend(std::iter::repeat_n(b"0 ".as_slice(), 10_000_000).flatten());
    let packed = gzip(&text);
    assert!(packed.len() < 100_000, "{}", packed.len());
    let path = put(dir.path(), "bomb.cube.gz", &packed);
    let msg = refused(&path, &ReadOptions::default());
    let want = format!(
        "1000x1000x1000 points with 1 value(s) each, more than a {}-byte gzip file (at most {} bytes decompressed) can hold",
        packed.len(),
        packed.len() * 1032
    );
    assert!(msg.contains(&want), "{msg}\n  wanted: {want}");
    // 500³ (500 MB as f32) over numbers that compress too little to bound
    // it: refused by the memory limit before anything is allocated.
    let mut text = header(500).into_bytes();
    let mut x = 12345u64;
    for _ in 0..200_000 {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        text.extend(format!("{} ", x >> 40).bytes());
    }
    let path = put(dir.path(), "big.cube.gz", &gzip(&text));
    let opts = ReadOptions {
        max_memory: 64 << 20,
        ..ReadOptions::default()
    };
    let msg = refused(&path, &opts);
    assert!(msg.contains("N1 x N2 x N3"), "{msg}");
    assert!(msg.contains("limit"), "{msg}");
    // A header that fits both meets the stream's end.
    let mut text = header(20).into_bytes();
    text.extend(std::iter::repeat_n(b"0 ".as_slice(), 5000).flatten());
    let path = put(dir.path(), "short.cube.gz", &gzip(&text));
    let msg = refused(&path, &ReadOptions::default());
    assert!(
        msg.contains("after 5000 of the 8000 values of the grid"),
        "{msg}"
    );
}

#[test]
fn truncated_and_corrupt_compressed_files_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(fixture("cube", "ramp_bohr.cube")).unwrap();
    let packed = gzip(&bytes);
    let msg = refused_at(
        dir.path(),
        "cut.cube.gz",
        &packed[..packed.len() / 2],
        &ReadOptions::default(),
    );
    assert!(msg.contains("gzip"), "{msg}");
    let mut corrupt = packed.clone();
    let n = corrupt.len();
    for b in &mut corrupt[20..n - 8] {
        *b ^= 0x5a;
    }
    let msg = refused_at(dir.path(), "bad.cube.gz", &corrupt, &ReadOptions::default());
    assert!(msg.contains("corrupt gzip stream"), "{msg}");
    let packed = bzip2(&bytes);
    let as_cube = ReadOptions {
        format: Some(VolumeFormat::Cube),
        ..ReadOptions::default()
    };
    let msg = refused_at(dir.path(), "cut.bz2", &packed[..packed.len() / 2], &as_cube);
    assert!(msg.contains("bzip2"), "{msg}");
}
