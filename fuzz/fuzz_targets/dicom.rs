//! Fuzzes the reader of DICOM: one `.dcm` file, or a directory holding it.
//! The first byte chooses `--frame` (bits 0-2) and reading the directory (bit 3).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, read_path, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("dicom", &[]));
    let (control, file) = split_control(data);
    let path = harness.put("series/input.dcm", file);
    let target = if control & 8 != 0 {
        harness.dir().join("series")
    } else {
        path
    };
    read_path(&target, VolumeFormat::Dicom, frame_choice(control), None);
});
