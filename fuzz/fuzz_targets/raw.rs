//! Fuzzes the raw reader with the layout taken from the input's first
//! 25 bytes: the sample type and byte order (byte 0: its low 4 bits
//! index `DTYPES`, bit 4 is big-endian), the dims (three
//! little-endian `u32`s) and the spacing (three little-endian `f32`s, as
//! `--spacing` would give them, unchecked). The rest is the file.
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, read_with};
use volray_io::{DType, Endian, RawOptions, ReadOptions, VolumeFormat};

static HARNESS: OnceLock<Harness> = OnceLock::new();

const DTYPES: [DType; 11] = [
    DType::U8,
    DType::I8,
    DType::U16,
    DType::I16,
    DType::U32,
    DType::I32,
    DType::U64,
    DType::I64,
    DType::F16,
    DType::F32,
    DType::F64,
];

fuzz_target!(|data: &[u8]| {
    if data.len() < 25 {
        return;
    }
    let (layout, file) = data.split_at(25);
    let u32_at = |i: usize| u32::from_le_bytes(layout[i..i + 4].try_into().unwrap());
    let f32_at = |i: usize| f64::from(f32::from_le_bytes(layout[i..i + 4].try_into().unwrap()));
    let raw = RawOptions {
        dims: [u32_at(1), u32_at(5), u32_at(9)].map(|d| d as usize),
        dtype: DTYPES[usize::from(layout[0] & 15) % DTYPES.len()],
        endian: if layout[0] & 16 != 0 {
            Endian::Big
        } else {
            Endian::Little
        },
        spacing: [f32_at(13), f32_at(17), f32_at(21)].into(),
    };
    let harness = HARNESS.get_or_init(|| Harness::new("raw", &[]));
    let path = harness.put("input.raw", file);
    let opts = ReadOptions {
        format: Some(VolumeFormat::Raw),
        raw: Some(raw),
        ..ReadOptions::default()
    };
    read_with(&path, &opts);
});
