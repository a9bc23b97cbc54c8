//! Fuzzes the DICOMDIR record walker and the file-set reader: the input
//! is the `DICOMDIR` of a file-set whose images are those of the
//! checked-in `dicom/cd` fixture (two series), read as its directory.
//! The first byte chooses the series (bits 0-1: none, 1, 2, a UID) and
//! whether the DICOMDIR itself is named as the input (bit 2).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, read_with, split_control};
use volray_io::{ReadOptions, VolumeFormat};

static HARNESS: OnceLock<Harness> = OnceLock::new();

macro_rules! image {
    ($path:literal) => {
        (
            $path,
            include_bytes!(concat!("../../crates/io/tests/fixtures/dicom/cd/", $path)) as &[u8],
        )
    };
}

const IMAGES: [(&str, &[u8]); 7] = [
    image!("PT000000/ST000000/SE000000/IM000000"),
    image!("PT000000/ST000000/SE000000/IM000001"),
    image!("PT000000/ST000000/SE000000/IM000002"),
    image!("PT000000/ST000000/SE000000/IM000003"),
    image!("PT000000/ST000000/SE000000/IM000004"),
    image!("PT000000/ST000000/SE000001/IM000000"),
    image!("PT000000/ST000000/SE000001/IM000001"),
];

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| {
        let h = Harness::new("dicomdir", &[]);
        for (path, bytes) in IMAGES {
            h.put(&format!("cd/{path}"), bytes);
        }
        h
    });
    let (control, file) = split_control(data);
    let dicomdir = harness.put("cd/DICOMDIR", file);
    let series = match control & 3 {
        0 => None,
        1 => Some("1".to_string()),
        2 => Some("2".to_string()),
        _ => Some("1.2.3".to_string()),
    };
    let target = if control & 4 != 0 {
        dicomdir
    } else {
        harness.dir().join("cd")
    };
    let opts = ReadOptions {
        format: Some(VolumeFormat::Dicom),
        series,
        ..ReadOptions::default()
    };
    read_with(&target, &opts);
});
