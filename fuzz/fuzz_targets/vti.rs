//! Fuzzes the reader of VTK XML image data `.vti`.
//! The first byte chooses `--array` (bits 4-7).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, array_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("vti", &[]));
    let (control, file) = split_control(data);
    harness.read(
        "input.vti",
        file,
        VolumeFormat::Vti,
        None,
        array_choice(control),
    );
});
