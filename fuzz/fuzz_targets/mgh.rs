//! Fuzzes the reader of FreeSurfer MGH/MGZ (`.mgh`, or `.mgz`: gzip is told by content).
//! The first byte chooses `--frame` (bits 0-2) and `.mgz` (bit 3).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("mgh", &[]));
    let (control, file) = split_control(data);
    let name = if control & 8 != 0 {
        "input.mgz"
    } else {
        "input.mgh"
    };
    harness.read(name, file, VolumeFormat::Mgh, frame_choice(control), None);
});
