//! Fuzzes the reader of OpenDX fields (and, behind a gzip, bzip2 or xz
//! magic, the decompressing stream they are read through).
//! The first byte chooses `--frame` (bits 0-2).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("dx", &[]));
    let (control, file) = split_control(data);
    harness.read(
        "input.dx",
        file,
        VolumeFormat::Dx,
        frame_choice(control),
        None,
    );
});
