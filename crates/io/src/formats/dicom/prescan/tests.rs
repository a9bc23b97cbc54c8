//! Unit tests of the prescan: element headers in each encoding, lengths
//! past their container, nesting and the pixel data.

use super::element::{ITEM, ITEM_END, SEQUENCE_END};
use super::*;

/// A minimal file: preamble, magic, meta group with a transfer syntax,
/// then `dataset`.
fn file(ts: &str, dataset: &[u8]) -> Vec<u8> {
    let mut b = vec![0u8; 128];
    b.extend_from_slice(b"DICM");
    let mut uid = ts.as_bytes().to_vec();
    if uid.len() % 2 == 1 {
        uid.push(0);
    }
    let mut meta = vec![0x02, 0x00, 0x10, 0x00, b'U', b'I'];
    meta.extend_from_slice(&(uid.len() as u16).to_le_bytes());
    meta.extend_from_slice(&uid);
    b.extend_from_slice(&[0x02, 0x00, 0x00, 0x00, b'U', b'L', 4, 0]);
    b.extend_from_slice(&(meta.len() as u32).to_le_bytes());
    b.extend_from_slice(&meta);
    b.extend_from_slice(dataset);
    b
}

fn explicit(group: u16, element: u16, vr: &[u8; 2], value: &[u8]) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&group.to_le_bytes());
    b.extend_from_slice(&element.to_le_bytes());
    b.extend_from_slice(vr);
    b.extend_from_slice(&(value.len() as u16).to_le_bytes());
    b.extend_from_slice(value);
    b
}

fn long(group: u16, element: u16, vr: &[u8; 2], length: u32) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&group.to_le_bytes());
    b.extend_from_slice(&element.to_le_bytes());
    b.extend_from_slice(vr);
    b.extend_from_slice(&[0, 0]);
    b.extend_from_slice(&length.to_le_bytes());
    b
}

fn item_header(tag: (u16, u16), length: u32) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&tag.0.to_le_bytes());
    b.extend_from_slice(&tag.1.to_le_bytes());
    b.extend_from_slice(&length.to_le_bytes());
    b
}

const EXPLICIT: &str = "1.2.840.10008.1.2.1";

#[test]
fn good_file_with_sequences_and_pixel_data() {
    let mut ds = explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes());
    // A sequence of undefined length holding one item of undefined
    // length and one of defined length.
    ds.extend(long(0x5200, 0x9229, b"SQ", UNDEFINED));
    ds.extend(item_header(ITEM, UNDEFINED));
    ds.extend(explicit(0x0028, 0x0030, b"DS", b"1\\1 "));
    ds.extend(item_header(ITEM_END, 0));
    let inner = explicit(0x0020, 0x0032, b"DS", b"0\\0\\0 ");
    ds.extend(item_header(ITEM, inner.len() as u32));
    ds.extend(inner);
    ds.extend(item_header(SEQUENCE_END, 0));
    ds.extend(long(0x7fe0, 0x0010, b"OW", 4));
    ds.extend([1, 0, 2, 0]);
    let f = file(EXPLICIT, &ds);
    let Prescan::Done(scan) = prescan(&f, true, false).unwrap() else {
        panic!("whole file needs no more")
    };
    assert_eq!(scan.transfer_syntax, EXPLICIT);
    assert_eq!(
        scan.pixel_data,
        Some(PixelData {
            element: 0x0010,
            length: Some(4)
        })
    );
    // Stopping at the pixel data reports where its header starts.
    let Prescan::Done(head) = prescan(&f, true, true).unwrap() else {
        panic!()
    };
    assert_eq!(head.end, f.len() - 16);
    // Any prefix that ends before the pixel data needs more bytes.
    for cut in [100, 140, 160, f.len() - 20] {
        assert_eq!(
            prescan(&f[..cut], false, true).unwrap(),
            Prescan::NeedMore,
            "{cut}"
        );
    }
}

#[test]
fn binary_values_must_fill_whole_values() {
    // Explicit VR: FD holds 8-byte values, so 2 bytes (the fuzz
    // finding, tests/fuzz_regressions.rs) or 12 are refused, 16 not.
    for (len, ok) in [(2usize, false), (12, false), (16, true), (0, true)] {
        let mut ds = explicit(0x0008, 0x0060, b"FD", &vec![0; len]);
        ds.extend(explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes()));
        let result = prescan(&file(EXPLICIT, &ds), true, false);
        match result {
            Ok(_) => assert!(ok, "{len}"),
            Err(err) => {
                assert!(!ok, "{len}: {err}");
                assert!(
                    err.contains("(0008,0060)")
                        && err.contains(&format!("declares {len} bytes, not a multiple of 8")),
                    "{err}"
                );
            }
        }
    }
    // Implicit VR: the VR is the dictionary's, Rows (0028,0010) is US.
    let mut ds = item_header((0x0028, 0x0010), 3);
    ds.extend([3, 0, 0]);
    let err = prescan(&file(IMPLICIT_VR_LE, &ds), true, false).unwrap_err();
    assert!(err.contains("is US (2-byte values)"), "{err}");
    let mut ds = item_header((0x0028, 0x0010), 2);
    ds.extend([3, 0]);
    assert!(prescan(&file(IMPLICIT_VR_LE, &ds), true, false).is_ok());
    // A tag the dictionary does not know is UN: any length.
    let mut ds = item_header((0x0009, 0x1001), 3);
    ds.extend([3, 0, 0]);
    assert!(prescan(&file(IMPLICIT_VR_LE, &ds), true, false).is_ok());
}

#[test]
fn header_walk_stops_where_the_header_parse_does() {
    // An extended offset table (7FE0,0001) before the pixel data is
    // read by the header parse, so it is checked, not taken for the
    // pixel data.
    let mut ds = explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes());
    ds.extend(long(0x7fe0, 0x0001, b"OV", 8));
    ds.extend([0; 8]);
    let pixels_at = file(EXPLICIT, &ds).len();
    ds.extend(long(0x7fe0, 0x0010, b"OW", 4));
    ds.extend([1, 0, 2, 0]);
    let f = file(EXPLICIT, &ds);
    let Prescan::Done(head) = prescan(&f, true, true).unwrap() else {
        panic!("whole file needs no more")
    };
    assert_eq!(head.end, pixels_at);
    assert_eq!(
        head.pixel_data,
        Some(PixelData {
            element: 0x0010,
            length: Some(4)
        })
    );
    // The same table declaring more bytes than the file holds.
    let mut ds = long(0x7fe0, 0x0001, b"OV", 0x4000_0000);
    ds.extend([0; 16]);
    let err = prescan(&file(EXPLICIT, &ds), true, true).unwrap_err();
    assert!(err.contains("(7FE0,0001)"), "{err}");
}

#[test]
fn lying_lengths_are_refused() {
    let mut ds = explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes());
    ds.extend(long(0x7fe0, 0x0010, b"OW", 0xfff0_0000));
    ds.extend([0; 16]);
    let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
    assert!(
        err.contains("(7FE0,0010)") && err.contains("declares 4293918720 bytes"),
        "{err}"
    );

    // An item longer than its defined-length sequence.
    let mut ds = long(0x5200, 0x9229, b"SQ", 8);
    ds.extend(item_header(ITEM, 100));
    ds.extend([0; 100]);
    let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
    assert!(err.contains("(FFFE,E000)"), "{err}");

    // A sequence that never ends.
    let mut ds = long(0x5200, 0x9229, b"SQ", UNDEFINED);
    ds.extend(item_header(ITEM, 0));
    let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
    assert!(err.contains("file ends inside"), "{err}");

    // Nesting deeper than the limit.
    let mut ds = Vec::new();
    for _ in 0..40 {
        ds.extend(long(0x5200, 0x9229, b"SQ", UNDEFINED));
        ds.extend(item_header(ITEM, UNDEFINED));
    }
    let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
    assert!(err.contains("nest deeper"), "{err}");

    let mut f = file(EXPLICIT, &[]);
    f[130] = b'X';
    assert!(prescan(&f, true, false).unwrap_err().contains("DICM"));

    // A group length that runs into the data set makes the parser read
    // data set elements as meta elements: the walk follows it there.
    let mut ds = item_header((0x0008, 0x0005), 0xffff_0000);
    ds.extend([16, 0, 0, 0]);
    let mut f = file(IMPLICIT_VR_LE, &ds);
    let err = prescan(&f, true, false).unwrap_err();
    assert!(err.contains("declares 4294901760 bytes"), "{err}");
    let len = u32::from_le_bytes([f[140], f[141], f[142], f[143]]);
    f[140..144].copy_from_slice(&(len + 8).to_le_bytes());
    let err = prescan(&f, true, false).unwrap_err();
    assert!(err.contains("(0008,0005) at byte"), "{err}");
    let mut f = file(EXPLICIT, &[]);
    f[132] = 0x08;
    let err = prescan(&f, true, false).unwrap_err();
    assert!(err.contains("not its 4-byte group length"), "{err}");
}

#[test]
fn implicit_and_big_endian_encodings() {
    // Implicit VR LE: tag, 32-bit length, value.
    let mut ds = Vec::new();
    ds.extend(item_header((0x0028, 0x0010), 2));
    ds.extend(3u16.to_le_bytes());
    ds.extend(item_header((0x7fe0, 0x0010), 6));
    ds.extend([0; 4]);
    let err = prescan(&file(IMPLICIT_VR_LE, &ds), true, false).unwrap_err();
    assert!(err.contains("declares 6 bytes, but only 4 remain"), "{err}");

    // Explicit VR big endian: the US length is big-endian too.
    let mut ds = vec![0x00, 0x28, 0x00, 0x10, b'U', b'S', 0x00, 0x02, 0x00, 0x03];
    ds.extend([0x7f, 0xe0, 0x00, 0x10, b'O', b'W', 0, 0, 0, 0, 0, 2, 0, 1]);
    let Prescan::Done(scan) = prescan(&file(EXPLICIT_VR_BE, &ds), true, false).unwrap() else {
        panic!()
    };
    assert_eq!(scan.pixel_data.unwrap().length, Some(2));
}
