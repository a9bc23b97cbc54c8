//! Fuzzes the reader of FITS images.
//! The first byte chooses `--frame` (bits 0-2) and `--array` (bits 4-5:
//! none, or an EXTNAME of the multi-extension seed, or one it lacks).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("fits", &[]));
    let (control, file) = split_control(data);
    let array = [None, Some("SCI"), Some("SERIES"), Some("THUMB")][usize::from((control >> 4) & 3)];
    harness.read(
        "input.fits",
        file,
        VolumeFormat::Fits,
        frame_choice(control),
        array,
    );
});
