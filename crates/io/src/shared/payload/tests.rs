//! Unit tests of locating, checking and decoding data regions, and of
//! numbered file names.

use super::read::read_regions;
use super::*;
use crate::dtype::{DType, Endian};
use std::io::Write;
use std::path::Path;

fn layout(dtype: DType, encoding: Encoding) -> Layout {
    Layout {
        dtype,
        endian: Endian::Little,
        encoding,
        inflated_skip: 0,
    }
}

fn region_of(dir: &Path, name: &str, bytes: &[u8]) -> Region {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    Region::locate(&path, 0, 0, Skip::Forward(0), 0, "skip").unwrap()
}

#[test]
fn printf_templates() {
    assert_eq!(format_number("s%03d.raw", 7).unwrap(), "s007.raw");
    assert_eq!(format_number("s%d.raw", -12).unwrap(), "s-12.raw");
    assert_eq!(format_number("%-4d|", 5).unwrap(), "5   |");
    assert_eq!(format_number("%4d|", 5).unwrap(), "   5|");
    assert_eq!(format_number("%+05i", 5).unwrap(), "+0005");
    assert_eq!(format_number("100%%_%d", 1).unwrap(), "100%_1");
    assert!(format_number("a%s", 1).unwrap_err().contains("%s"));
    assert!(
        format_number("a%d%d", 1)
            .unwrap_err()
            .contains("more than one")
    );
    assert!(format_number("plain", 1).unwrap_err().contains("no %d"));
    assert!(format_number("%999999999999d", 1).is_err());
}

#[test]
fn number_ranges() {
    assert_eq!(number_range(1, 5, 1), Some(5));
    assert_eq!(number_range(0, 8, 2), Some(5));
    assert_eq!(number_range(0, 9, 2), Some(5));
    assert_eq!(number_range(5, 1, -1), Some(5));
    assert_eq!(number_range(3, 3, 1), Some(1));
    assert_eq!(number_range(1, 5, 0), None);
    assert_eq!(number_range(1, 5, -1), None);
    assert_eq!(number_range(i64::MIN, i64::MAX, 1), None);
    assert_eq!(number_range(i64::MIN, i64::MAX, 2), Some(1 << 63));
}

#[test]
fn line_and_byte_skips() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d");
    std::fs::write(&path, b"head\nline one\nline two\nXYdata").unwrap();
    let r = Region::locate(&path, 5, 2, Skip::Forward(2), 0, "line skip").unwrap();
    assert_eq!((r.start, r.len), (25, 4));
    let r = Region::locate(&path, 0, 0, Skip::BeforeEnd(0), 4, "byte skip").unwrap();
    assert_eq!((r.start, r.len), (25, 4));
    let r = Region::locate(&path, 0, 0, Skip::BeforeEnd(2), 2, "byte skip").unwrap();
    assert_eq!((r.start, r.len), (25, 2));
    let err = Region::locate(&path, 5, 4, Skip::Forward(0), 0, "line skip").unwrap_err();
    assert!(
        err.to_string()
            .contains("4 lines to skip but the file ends after 2"),
        "{err}"
    );
    let err = Region::locate(&path, 0, 0, Skip::Forward(30), 0, "byte skip").unwrap_err();
    assert!(
        err.to_string()
            .contains("passes the end of the file (29 bytes)"),
        "{err}"
    );
    let err = Region::locate(&path, 20, 0, Skip::BeforeEnd(0), 10, "byte skip").unwrap_err();
    assert!(err.to_string().contains("only 9 bytes follow"), "{err}");
}

#[test]
fn raw_sizes_are_checked_and_frames_selected() {
    let dir = tempfile::tempdir().unwrap();
    let bytes: Vec<u8> = (0..12u16).flat_map(|v| v.to_le_bytes()).collect();
    let r = region_of(dir.path(), "r", &bytes);
    let l = layout(DType::U16, Encoding::Raw);
    let mut notes = Vec::new();
    check_region(&r, 12, &l, &mut notes).unwrap();
    assert!(notes.is_empty());
    check_region(&r, 11, &l, &mut notes).unwrap();
    assert!(
        notes[0].ends_with("2 bytes after the data ignored"),
        "{notes:?}"
    );
    let err = check_region(&r, 13, &l, &mut notes).unwrap_err();
    assert!(
        err.to_string().contains("13 samples of u16 (26 bytes)"),
        "{err}"
    );

    // Frames of 2 along a fastest axis of 3: samples 3..5 and 9..11 are frame 1.
    let select = FrameSelect {
        stride: 1,
        count: 3,
        index: 1,
    };
    let got = read_regions(std::slice::from_ref(&r), 12, &l, select)
        .unwrap()
        .to_f32_vec();
    assert_eq!(got, [1.0, 4.0, 7.0, 10.0]);
    let select = FrameSelect {
        stride: 6,
        count: 2,
        index: 1,
    };
    let got = read_regions(&[r.clone(), r], 12, &l, select)
        .unwrap()
        .to_f32_vec();
    assert_eq!(
        got,
        [
            6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0
        ]
    );
}

#[test]
fn compressed_streams_must_inflate_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let data: Vec<u8> = (0..100u8).collect();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    gz.write_all(&data).unwrap();
    let gz = gz.finish().unwrap();
    let r = region_of(dir.path(), "g", &gz);
    let mut l = layout(DType::U8, Encoding::Gzip);
    let got = read_regions(std::slice::from_ref(&r), 100, &l, FrameSelect::ALL)
        .unwrap()
        .to_f32_vec();
    assert_eq!(got, (0..100).map(|v| v as f32).collect::<Vec<_>>());
    let err = read_regions(std::slice::from_ref(&r), 101, &l, FrameSelect::ALL).unwrap_err();
    assert!(
        err.to_string()
            .contains("inflates to 100 bytes, but the header declares 101"),
        "{err}"
    );
    let err = read_regions(std::slice::from_ref(&r), 99, &l, FrameSelect::ALL).unwrap_err();
    assert!(
        err.to_string().contains("inflates past the 99 bytes"),
        "{err}"
    );
    l.inflated_skip = 10;
    let got = read_regions(std::slice::from_ref(&r), 90, &l, FrameSelect::ALL)
        .unwrap()
        .to_f32_vec();
    assert_eq!(got[0], 10.0);

    // zlib, and gzip found by its magic where zlib is declared.
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(&data).unwrap();
    let z = z.finish().unwrap();
    let rz = region_of(dir.path(), "z", &z);
    let lz = layout(DType::U8, Encoding::Zlib);
    assert_eq!(
        read_regions(&[rz], 100, &lz, FrameSelect::ALL)
            .unwrap()
            .to_f32_vec()[99],
        99.0
    );
    assert_eq!(
        read_regions(std::slice::from_ref(&r), 100, &lz, FrameSelect::ALL)
            .unwrap()
            .to_f32_vec()[99],
        99.0
    );

    // A lying size beyond deflate's ratio is refused before reading.
    let mut notes = Vec::new();
    let err = check_region(&r, usize::MAX / 2, &lz, &mut notes).unwrap_err();
    assert!(
        err.to_string().contains("cannot inflate to more than"),
        "{err}"
    );
    let corrupt = region_of(dir.path(), "c", &gz[..gz.len() / 2]);
    let err = read_regions(
        &[corrupt],
        100,
        &layout(DType::U8, Encoding::Gzip),
        FrameSelect::ALL,
    )
    .unwrap_err();
    assert!(!err.is_io_failure(), "{err}");
}

#[test]
fn text_and_hex() {
    let dir = tempfile::tempdir().unwrap();
    let r = region_of(dir.path(), "t", b" 1, 2.5\n-3e2\t4 trailing words");
    let l = layout(DType::F32, Encoding::Text);
    assert_eq!(
        read_regions(std::slice::from_ref(&r), 4, &l, FrameSelect::ALL)
            .unwrap()
            .to_f32_vec(),
        [1.0, 2.5, -300.0, 4.0]
    );
    let err = read_regions(std::slice::from_ref(&r), 5, &l, FrameSelect::ALL).unwrap_err();
    assert!(
        err.to_string()
            .ends_with("t: line 2 of the data: text value 5 is \"trailing\", not a number"),
        "{err}"
    );
    let short = region_of(dir.path(), "s", b"1 2 3");
    let err = read_regions(std::slice::from_ref(&short), 4, &l, FrameSelect::ALL).unwrap_err();
    assert!(
        err.to_string().ends_with(
            "s: file ends at line 1 of the data after 3 of the 4 values of the text data"
        ),
        "{err}"
    );
    let mut notes = Vec::new();
    let err = check_region(&short, 4, &l, &mut notes).unwrap_err();
    assert!(err.to_string().contains("cannot hold that many"), "{err}");

    let h = region_of(dir.path(), "h", b"0100 ff\n7f 0080");
    let mut lh = layout(DType::I16, Encoding::Hex);
    lh.endian = Endian::Big;
    assert_eq!(
        read_regions(&[h], 3, &lh, FrameSelect::ALL)
            .unwrap()
            .to_f32_vec(),
        [256.0, -129.0, 128.0]
    );
    let bad = region_of(dir.path(), "b", b"01zz");
    let err = read_regions(&[bad], 1, &lh, FrameSelect::ALL).unwrap_err();
    assert!(err.to_string().contains("'z', not a hex digit"), "{err}");
}
