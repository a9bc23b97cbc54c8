//! Unit tests of `.npy` reading and writing, and of the header parser.

use super::header::parse_header;
use super::*;
use crate::dtype::{DType, Endian, f16_to_f32};
use std::fs;
use std::path::PathBuf;

/// A `.npy` file image: preamble, header padded to 64, data.
fn npy_bytes(version: u8, header: &str, data: &[u8]) -> Vec<u8> {
    let pre = if version == 1 { 10 } else { 12 };
    let mut h = header.to_string();
    let pad = (64 - (pre + h.len() + 1) % 64) % 64;
    h.extend(std::iter::repeat_n(' ', pad));
    h.push('\n');
    let mut out = MAGIC.to_vec();
    out.extend([version, 0]);
    if version == 1 {
        out.extend((h.len() as u16).to_le_bytes());
    } else {
        out.extend((h.len() as u32).to_le_bytes());
    }
    out.extend(h.as_bytes());
    out.extend(data);
    out
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    fs::write(&p, bytes).unwrap();
    p
}

fn npy_err(bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "bad.npy", bytes);
    let err = read_npy(&p).unwrap_err();
    assert!(!err.is_io_failure(), "{err}");
    let msg = err.to_string();
    assert!(msg.starts_with(&p.display().to_string()), "{msg}");
    assert!(!msg.contains('\n'), "{msg}");
    msg
}

fn f32_data(n: usize) -> Vec<u8> {
    (0..n).flat_map(|i| (i as f32).to_le_bytes()).collect()
}

#[test]
fn c_order_is_transposed_fortran_is_not() {
    let dir = tempfile::tempdir().unwrap();
    // File order i = 0..24 for shape (2, 3, 4).
    let c = npy_bytes(
        1,
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }",
        &f32_data(24),
    );
    let v = read_npy(&write(dir.path(), "c.npy", &c)).unwrap();
    assert_eq!(v.dims(), [2, 3, 4]);
    for x in 0..2 {
        for y in 0..3 {
            for z in 0..4 {
                // C order: z fastest.
                assert_eq!(v.get(x, y, z), (z + 4 * (y + 3 * x)) as f32);
            }
        }
    }
    let f = npy_bytes(
        2,
        "{\"shape\": (2,3,4), \"fortran_order\": True, \"descr\": \"<f4\"}",
        &f32_data(24),
    );
    let v = read_npy(&write(dir.path(), "f.npy", &f)).unwrap();
    assert_eq!(v.values(), (0..24).map(|i| i as f32).collect::<Vec<_>>());
}

#[test]
fn write_then_read_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let dims = [3, 4, 5];
    let data: Vec<f32> = (0..60).map(|i| i as f32 * 0.5 - 7.25).collect();
    let v = Volume::new(dims, data).unwrap();
    let p = dir.path().join("out.npy");
    write_npy(&p, &v).unwrap();
    let bytes = fs::read(&p).unwrap();
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!((10 + header_len) % 64, 0);
    assert_eq!(bytes.len(), 10 + header_len + 60 * 4);
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let text = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(text.ends_with('\n'));
    assert_eq!(
        text.trim_end(),
        "{'descr': '<f4', 'fortran_order': True, 'shape': (3, 4, 5), }"
    );
    let back = read_npy(&p).unwrap();
    assert_eq!(back, v);
}

#[test]
fn every_descr_decodes() {
    let dir = tempfile::tempdir().unwrap();
    let vals: [f64; 8] = [0.0, 1.0, 2.0, 3.0, 100.0, 120.0, 126.0, 127.0];
    let neg: [f64; 8] = [-1.0, -2.0, 0.0, 5.0, -100.0, 7.0, -127.0, 1.0];
    type Enc = fn(f64) -> Vec<u8>;
    let cases: Vec<(&str, Enc, &[f64; 8])> = vec![
        ("|u1", |v| vec![v as u8], &vals),
        ("|i1", |v| vec![v as i8 as u8], &neg),
        ("<i2", |v| (v as i16).to_le_bytes().to_vec(), &neg),
        (">i2", |v| (v as i16).to_be_bytes().to_vec(), &neg),
        ("<u2", |v| (v as u16).to_le_bytes().to_vec(), &vals),
        (">u2", |v| (v as u16).to_be_bytes().to_vec(), &vals),
        ("<i4", |v| (v as i32).to_le_bytes().to_vec(), &neg),
        (">u4", |v| (v as u32).to_be_bytes().to_vec(), &vals),
        ("<i8", |v| (v as i64).to_le_bytes().to_vec(), &neg),
        (">i8", |v| (v as i64).to_be_bytes().to_vec(), &neg),
        ("<u8", |v| (v as u64).to_le_bytes().to_vec(), &vals),
        ("<f4", |v| (v as f32).to_le_bytes().to_vec(), &neg),
        (">f4", |v| (v as f32).to_be_bytes().to_vec(), &neg),
        ("<f8", |v| v.to_le_bytes().to_vec(), &neg),
        (">f8", |v| v.to_be_bytes().to_vec(), &neg),
        ("=f8", |v| v.to_ne_bytes().to_vec(), &neg),
    ];
    for (descr, enc, values) in cases {
        let data: Vec<u8> = values.iter().flat_map(|&v| enc(v)).collect();
        let header = format!("{{'descr': '{descr}', 'fortran_order': True, 'shape': (2, 2, 2), }}");
        let p = write(dir.path(), "t.npy", &npy_bytes(1, &header, &data));
        let v = read_npy(&p).unwrap_or_else(|e| panic!("{descr}: {e}"));
        let want: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        assert_eq!(v.values(), want, "{descr}");
    }
}

#[test]
fn bool_and_half_decode() {
    let dir = tempfile::tempdir().unwrap();
    let h = "{'descr': '|b1', 'fortran_order': True, 'shape': (2, 2, 2), }";
    let p = write(
        dir.path(),
        "b.npy",
        &npy_bytes(1, h, &[0, 1, 2, 0, 255, 0, 0, 1]),
    );
    assert_eq!(
        *read_npy(&p).unwrap().values(),
        [0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0]
    );

    let halves: [u16; 8] = [
        0x0000, 0x3c00, 0xc000, 0x7bff, 0x0001, 0x3555, 0x7c00, 0x8000,
    ];
    let data: Vec<u8> = halves.iter().flat_map(|h| h.to_be_bytes()).collect();
    let h = "{'descr': '>f2', 'fortran_order': True, 'shape': (2, 2, 2), }";
    let p = write(dir.path(), "h.npy", &npy_bytes(3, h, &data));
    let v = read_npy(&p).unwrap();
    let want = [
        0.0,
        1.0,
        -2.0,
        65504.0,
        2f32.powi(-24),
        0.333_251_95,
        f32::INFINITY,
        -0.0,
    ];
    assert_eq!(*v.values(), want);
    assert!(v.values()[7].is_sign_negative());
    assert!(f16_to_f32(0x7e00).is_nan());
}

#[test]
fn header_errors_never_panic() {
    let good = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), }";
    let msg = npy_err(b"");
    assert!(msg.contains("too short"), "{msg}");
    let msg = npy_err(b"\x93NUMPX\x01\x00\x10\x00{}");
    assert!(msg.contains("\\x93NUMPY"), "{msg}");
    let msg = npy_err(b"\x93NUMPY\x04\x00\x10\x00");
    assert!(msg.contains("version 4.0"), "{msg}");
    let msg = npy_err(b"\x93NUMPY\x02\x00\x10\x00");
    assert!(msg.contains("truncated"), "{msg}");
    // Header length larger than the file.
    let mut b = npy_bytes(1, good, &f32_data(8));
    b.truncate(40);
    let msg = npy_err(&b);
    assert!(msg.contains("truncated"), "{msg}");
    // Header length over the limit.
    let msg = npy_err(b"\x93NUMPY\x02\x00\x00\x00\x20\x00    ");
    assert!(msg.contains("limit"), "{msg}");

    let msg = npy_err(&npy_bytes(
        1,
        "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 2), }",
        &f32_data(8),
    ));
    assert!(msg.contains("shape (4, 2)"), "{msg}");
    assert!(msg.contains("3-D"), "{msg}");
    let msg = npy_err(&npy_bytes(
        1,
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2, 1), }",
        &f32_data(8),
    ));
    assert!(msg.contains("(2, 2, 2, 1)"), "{msg}");

    for descr in ["'<c8'", "'|O'", "'<U3'", "'<f16'", "'f4'", "[('a', '<f4')]"] {
        let h = format!("{{'descr': {descr}, 'fortran_order': False, 'shape': (2, 2, 2), }}");
        let msg = npy_err(&npy_bytes(1, &h, &f32_data(8)));
        assert!(msg.contains("unsupported .npy dtype descr"), "{msg}");
        assert!(msg.contains(descr), "{msg}");
    }

    // A shape that lies about the data size, either way.
    let big = "{'descr': '<f4', 'fortran_order': False, 'shape': (100, 100, 100), }";
    let msg = npy_err(&npy_bytes(1, big, &f32_data(8)));
    assert!(msg.contains("4000000 bytes"), "{msg}");
    assert!(msg.contains("32 bytes of data"), "{msg}");
    let msg = npy_err(&npy_bytes(1, good, &f32_data(9)));
    assert!(msg.contains("36 bytes of data"), "{msg}");
    let huge =
        "{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296, 4294967296), }";
    let msg = npy_err(&npy_bytes(1, huge, &f32_data(8)));
    assert!(msg.contains("too large"), "{msg}");
    let enormous = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2, 99999999999999999999999999999999999999999), }";
    let msg = npy_err(&npy_bytes(1, enormous, &f32_data(8)));
    assert!(
        msg.contains("malformed") || msg.contains("too large"),
        "{msg}"
    );

    // Thin arrays are valid .npy but not volumes.
    let thin = "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2, 4), }";
    let msg = npy_err(&npy_bytes(1, thin, &f32_data(8)));
    assert!(msg.contains("at least 2 points"), "{msg}");
    let empty = "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 2, 4), }";
    npy_err(&npy_bytes(1, empty, &[]));
}

#[test]
fn malformed_dicts_are_refused() {
    let bad_headers = [
        "",
        "not a dict",
        "{'descr': '<f4', 'fortran_order': False}",
        "{'descr': '<f4', 'fortran_order': 0, 'shape': (2, 2, 2)}",
        "{'descr': '<f4', 'fortran_order': False, 'shape': [2, 2, 2]}",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2, -2, 2)}",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), 'x': 1}",
        "{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2)}",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2)} extra",
        "{'descr': '<f4' 'fortran_order': False, 'shape': (2, 2, 2)}",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2",
        "{'descr': '<f4, 'fortran_order': False, 'shape': (2, 2, 2)}",
        "{'descr': '<f4', 'fortran_order': Maybe, 'shape': (2, 2, 2)}",
        "{1: '<f4'}",
    ];
    for h in bad_headers {
        npy_err(&npy_bytes(1, h, &f32_data(8)));
    }
    let deep = format!("{}{}", "[".repeat(10_000), "]".repeat(10_000));
    npy_err(&npy_bytes(2, &deep, &f32_data(8)));
    npy_err(&npy_bytes(1, "{'descr': '\u{e9}f4'}", &[]));
}

#[test]
fn header_variants_numpy_might_write_are_accepted() {
    for h in [
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), }",
        "{'descr':'<f4','fortran_order':False,'shape':(2,2,2)}",
        "{'shape': (2L, 2L, 2L), 'descr': '<f4', 'fortran_order': False}",
        "{ 'descr' : \"<f4\" ,\n 'fortran_order' : False , 'shape' : ( 2 , 2 , 2 , ) , }",
    ] {
        assert_eq!(
            parse_header(h),
            Ok((Elem::Plain(DType::F32, Endian::Little), false, [2, 2, 2])),
            "{h}"
        );
    }
}

#[test]
fn garbage_never_panics() {
    // Mutations of a valid file: every truncation and many single-byte changes.
    let dir = tempfile::tempdir().unwrap();
    let good = npy_bytes(
        1,
        "{'descr': '<i2', 'fortran_order': False, 'shape': (2, 2, 2), }",
        &[1u8; 16],
    );
    let p = dir.path().join("m.npy");
    for cut in 0..good.len() {
        fs::write(&p, &good[..cut]).unwrap();
        assert!(read_npy(&p).is_err(), "cut at {cut}");
    }
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..2000 {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let mut b = good.clone();
        let i = (seed % b.len() as u64) as usize;
        b[i] = (seed >> 32) as u8;
        fs::write(&p, &b).unwrap();
        let _ = read_npy(&p);
    }
}

#[test]
fn descr_names_are_canonical() {
    assert_eq!(descr_name(Elem::Plain(DType::F32, Endian::Big)), ">f4");
    assert_eq!(descr_name(Elem::Plain(DType::U16, Endian::Little)), "<u2");
    assert_eq!(descr_name(Elem::Plain(DType::I32, Endian::Little)), "<i4");
    assert_eq!(descr_name(Elem::Bool), "|b1");
    assert_eq!(descr_name(Elem::F16(Endian::Little)), "<f2");
}
