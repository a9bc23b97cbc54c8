//! Reads VTK XML image data (`.vti`) written by VTK's own
//! vtkXMLImageDataWriter (see `fixtures/make_vtk_fixtures.py`) in every data
//! mode, encoding, compression, header type and byte order, and checks
//! every value, the geometry, the array choice and `FileInfo`; then checks
//! that broken files made here are refused with specific messages.
//!
//! Every image has 4 x 3 x 5 points, spacing (0.5, 2, 1.5), origin
//! (-1, 2, 3); point arrays hold ramp(i, j, k) = i + 10j + 100k through the
//! script's per-type formula, cell arrays c = i + 10j + 100k + 0.5 on the
//! 3 x 2 x 4 cells. Values are checked at their world positions, so the
//! check does not depend on how the reader lays out a rotated grid.

mod common;

use std::path::PathBuf;

use common::{Grid, header_value, ramp, refused_file, replace, typed, with_array};
use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("vtk", name)
}

fn read_with(name: &str, array: Option<&str>) -> Result<Loaded, IoError> {
    read(&fixture(name), &with_array(array))
}

fn load(name: &str, array: Option<&str>) -> Loaded {
    let l = read_with(name, array).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(l.format, VolumeFormat::Vti);
    l
}

/// The point grid of every fixture.
const POINTS: Grid = Grid {
    n: [4, 3, 5],
    steps: [
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
        DVec3::new(0.0, 0.0, 1.5),
    ],
    origin: DVec3::new(-1.0, 2.0, 3.0),
};

/// Every sample of `grid` at its world position in the volume of `l`.
fn check_world(name: &str, l: &Loaded, grid: &Grid, want: impl Fn(usize, usize, usize) -> f32) {
    common::check_world(name, &l.volume, grid, 1e-9, want);
}

fn check_ramp(name: &str, l: &Loaded) {
    assert_eq!(l.volume.dims(), [4, 3, 5], "{name}");
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 2.0, 1.5), "{name}");
    assert_eq!(l.volume.origin(), POINTS.origin, "{name}");
    check_world(name, l, &POINTS, |i, j, k| typed("f32", ramp(i, j, k)));
}

/// The cell array on the cells of the point grid `points`: 3 x 2 x 4
/// values at the cell centres.
fn check_cells(name: &str, l: &Loaded, points: &Grid) {
    let [s0, s1, s2] = points.steps;
    let cells = Grid {
        n: [3, 2, 4],
        origin: points.origin + (s0 + s1 + s2) * 0.5,
        ..*points
    };
    check_world(name, l, &cells, |i, j, k| ramp(i, j, k) as f32 + 0.5);
    assert!(
        l.info.notes.iter().any(|n| n.contains("3x2x4 cells")),
        "{:?}",
        l.info.notes
    );
}

const VARIANTS: [(&str, &str); 18] = [
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
    ("vti_binary_lz4.vti", "little"),
    ("vti_binary_lz4_u32.vti", "little"),
    ("vti_appended_raw_lz4.vti", "little"),
    ("vti_appended_base64_lzma_u32.vti", "little"),
    ("vti_binary_lzma.vti", "little"),
    ("vti_appended_raw_lzma_u32.vti", "little"),
    ("vti_binary_be_lzma.vti", "big"),
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
        check_world(file, &l, &POINTS, |i, j, k| typed("u8", ramp(i, j, k)));

        let l = load(file, Some("cells"));
        assert_eq!(l.volume.dims(), [3, 2, 4]);
        check_cells(file, &l, &POINTS);

        for (name, n) in [("velocity", 3), ("pair a", 2)] {
            let err = read_with(file, Some(name)).unwrap_err();
            assert!(!err.is_io_failure());
            assert!(
                matches!(&err, IoError::ArrayNotScalar { scalars, .. } if scalars == "ramp, other, cells"),
                "{err}"
            );
            let msg = err.to_string();
            assert!(
                msg.contains(&format!("point array \"{name}\" has {n} components"))
                    && msg.contains("(ramp, other, cells)"),
                "{msg}"
            );
        }
        let err = read_with(file, Some("missing")).unwrap_err();
        assert!(
            matches!(&err, IoError::NoSuchArray { name, .. } if name == "missing"),
            "{err}"
        );
        assert!(
            err.to_string().contains("no array named \"missing\""),
            "{err}"
        );
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
        check_world(name, &l, &POINTS, |i, j, k| typed(name, ramp(i, j, k)));
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
    let rotated = Grid {
        steps: [
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 1.5),
        ],
        ..POINTS
    };
    let l = load("vti_direction.vti", None);
    assert_eq!(l.volume.dims(), [3, 4, 5]);
    check_world("direction", &l, &rotated, |i, j, k| {
        typed("f32", ramp(i, j, k))
    });
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("index axis 0 -> +y, index axis 1 -> -x"))
    );
    let l = load("vti_direction.vti", Some("cells"));
    check_cells("direction cells", &l, &rotated);

    // Extent 2..5, 1..3, 0..4: the first point is at Origin + (2, 1, 0)·Spacing.
    let offset = Grid {
        origin: POINTS.origin + DVec3::new(1.0, 2.0, 0.0),
        ..POINTS
    };
    let l = load("vti_extent.vti", None);
    assert_eq!(l.volume.origin(), offset.origin);
    check_world("extent", &l, &offset, |i, j, k| typed("f32", ramp(i, j, k)));
    let l = load("vti_extent.vti", Some("cells"));
    check_cells("extent cells", &l, &offset);
}

#[test]
fn lz4_with_vtks_default_block_size() {
    let l = load("vti_lz4.vti", None);
    assert_eq!(
        header_value(&l, "VTKFile compressor"),
        "vtkLZ4DataCompressor"
    );
    check_ramp("vti_lz4.vti", &l);
}

// ---- broken files ----

fn error_for(bytes: &[u8]) -> String {
    refused_file("bad.vti", bytes, &ReadOptions::default())
}

fn fixture_text(name: &str) -> Vec<u8> {
    std::fs::read(fixture(name)).unwrap()
}

#[test]
fn truncated_appended_data() {
    let b = fixture_text("vti_appended_raw.vti");
    // The cut removes the end of "cells", the last array; "ramp" (the
    // default) is still whole, so ask for the cells.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cut.vti");
    std::fs::write(&p, &b[..b.len() - 100]).unwrap();
    let opts = with_array(Some("cells"));
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
    // The limit on memory refuses the extent first; without one, the
    // block header's size is checked against the extent before allocating.
    let msg = error_for(&b);
    assert!(msg.contains("exceed the memory limit of"), "{msg}");
    let unlimited = ReadOptions {
        max_memory: u64::MAX,
        ..ReadOptions::default()
    };
    let msg = refused_file("bad.vti", &b, &unlimited);
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

/// `bytes` with header word `index` of the appended array at `offset` set
/// to `value` (`word` bytes, little-endian), in a raw appended file.
fn set_word(bytes: &[u8], offset: usize, word: usize, index: usize, value: u64) -> Vec<u8> {
    let tag = b"<AppendedData encoding=\"raw\">";
    let at = bytes.windows(tag.len()).position(|w| w == tag).unwrap();
    let start = at + bytes[at..].iter().position(|&b| b == b'_').unwrap() + 1;
    let mut out = bytes.to_vec();
    let from = start + offset + index * word;
    out[from..from + word].copy_from_slice(&value.to_le_bytes()[..word]);
    out
}

/// The extent of every fixture with z running 0 to `z`.
fn with_z_extent(bytes: &[u8], z: usize) -> Vec<u8> {
    let b = replace(
        bytes,
        "WholeExtent=\"0 3 0 2 0 4\"",
        &format!("WholeExtent=\"0 3 0 2 0 {z}\""),
    );
    replace(
        &b,
        "Piece Extent=\"0 3 0 2 0 4\"",
        &format!("Piece Extent=\"0 3 0 2 0 {z}\""),
    )
}

/// LZ4 and xz blocks whose header lies about their sizes, or whose bytes
/// are cut or garbled: one line naming the array and block, and nothing
/// allocated for a size only the header claims.
#[test]
fn lying_truncated_and_corrupt_lz4_and_lzma_blocks() {
    // "ramp" is one block of 240 bytes (block size 256) at offset 0.
    for (file, word, codec) in [
        ("vti_appended_raw_lz4.vti", 8, "LZ4 block"),
        ("vti_appended_raw_lzma_u32.vti", 4, "xz stream"),
    ] {
        let b = fixture_text(file);
        // The extent and the header claim 288 bytes; the block holds 240.
        let more = set_word(&with_z_extent(&b, 5), 0, word, 2, 288);
        let more = set_word(&more, 0, word, 1, 288);
        let msg = error_for(&more);
        assert!(
            msg.contains(&format!(
                "DataArray \"ramp\" block 0: {codec} decodes to 240 bytes, but the header declares 288"
            )),
            "{file}: {msg}"
        );
        // They claim 192 bytes; the block holds 240.
        let less = set_word(&with_z_extent(&b, 3), 0, word, 2, 192);
        let msg = error_for(&less);
        assert!(
            msg.contains(&format!(
                "DataArray \"ramp\" block 0: {codec} decodes past the 192 bytes the header declares"
            )),
            "{file}: {msg}"
        );
        // A compressed size larger than the data that follows.
        let msg = error_for(&set_word(&b, 0, word, 3, 1 << 30));
        assert!(
            msg.contains("\"ramp\": compressed block 0 (1073741824 bytes) runs past the end"),
            "{file}: {msg}"
        );
        // A compressed size cut short: the block ends early.
        let msg = error_for(&set_word(&b, 0, word, 3, 40));
        assert!(
            msg.contains("DataArray \"ramp\" block 0: "),
            "{file}: {msg}"
        );
        // The block's bytes garbled (the data follows the 4 header words):
        // xz checks its CRC; LZ4 blocks carry no checksum, so garbled
        // literals decode (the byte flips below still must not panic).
        if codec == "LZ4 block" {
            continue;
        }
        let mut garbled = b.clone();
        let tag = b"<AppendedData encoding=\"raw\">";
        let at = b.windows(tag.len()).position(|w| w == tag).unwrap();
        let start = at + b[at..].iter().position(|&c| c == b'_').unwrap() + 1 + 4 * word;
        for x in &mut garbled[start + 8..start + 24] {
            *x ^= 0x5a;
        }
        let msg = error_for(&garbled);
        assert!(
            msg.contains("DataArray \"ramp\" block 0: corrupt xz stream"),
            "{file}: {msg}"
        );
    }

    // An LZ4 header claiming far more than its bytes can decode to (255:1)
    // is refused before decoding, whatever the memory limit.
    let b = with_z_extent(&fixture_text("vti_appended_raw_lz4.vti"), 99_999);
    let b = set_word(&b, 0, 8, 0, 1);
    let b = set_word(&b, 0, 8, 1, 4_800_000);
    let b = set_word(&b, 0, 8, 2, 4_800_000);
    let unlimited = ReadOptions {
        max_memory: u64::MAX,
        ..ReadOptions::default()
    };
    let msg = refused_file("bad.vti", &b, &unlimited);
    assert!(msg.contains("cannot inflate to the 4800000"), "{msg}");
    // xz has no useful ratio: the claim is refused once the stream ends,
    // its output having grown only to what it holds.
    let b = with_z_extent(&fixture_text("vti_appended_raw_lzma_u32.vti"), 99_999);
    let b = set_word(&b, 0, 4, 1, 4_800_000);
    let b = set_word(&b, 0, 4, 2, 4_800_000);
    let msg = refused_file("bad.vti", &b, &unlimited);
    assert!(
        msg.contains("xz stream decodes to 240 bytes, but the header declares 4800000"),
        "{msg}"
    );
}

/// Deterministic byte flips and truncations of a few fixtures, each read
/// for its point and its cell array: a volume or a one-line message,
/// never a panic.
#[test]
fn no_panic_on_truncation_or_corruption() {
    let fixtures = [
        "vti_binary_zlib.vti",
        "vti_appended_raw_zlib.vti",
        "vti_appended_base64_zlib_u32.vti",
        "vti_binary.vti",
        "vti_pieces.vti",
        "vti_appended_raw_lz4.vti",
        "vti_binary_lzma.vti",
    ]
    .map(fixture);
    common::byte_flips_never_panic(
        &fixtures,
        0xd1b5_4a32_d192_ed03,
        &[ReadOptions::default(), with_array(Some("cells"))],
    );
}
