//! Fuzzes the reader of NIfTI-1/2 (`.nii`, gzip or not, and `.hdr` with the fixture `pair.img` beside it),
//! which also reads 5-D files and Analyze 7.5 headers (a `.hdr` without the magic; seeded from fixtures/analyze).
//! The first byte chooses `--frame` (bits 0-2) and `.hdr` (bit 3).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| {
        Harness::new(
            "nifti",
            &[(
                "input.img",
                include_bytes!("../../crates/io/tests/fixtures/nifti/pair.img"),
            )],
        )
    });
    let (control, file) = split_control(data);
    let name = if control & 8 != 0 {
        "input.hdr"
    } else {
        "input.nii"
    };
    harness.read(name, file, VolumeFormat::Nifti, frame_choice(control), None);
});
