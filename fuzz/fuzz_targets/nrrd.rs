//! Fuzzes the reader of NRRD, attached (`.nrrd`) and detached (`.nhdr`, with the fixtures' data files beside it).
//! The first byte chooses `--frame` (bits 0-2) and `.nhdr` (bit 3).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| {
        Harness::new(
            "nrrd",
            &[
                (
                    "f64_be.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/f64_be.raw"),
                ),
                (
                    "gz_skip.raw.gz",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/gz_skip.raw.gz"),
                ),
                (
                    "i32_gz.raw.gz",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/i32_gz.raw.gz"),
                ),
                (
                    "list_0.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/list_0.raw"),
                ),
                (
                    "list_1.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/list_1.raw"),
                ),
                (
                    "list_2.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/list_2.raw"),
                ),
                (
                    "list_3.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/list_3.raw"),
                ),
                (
                    "list_4.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/list_4.raw"),
                ),
                (
                    "skips.dat",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/skips.dat"),
                ),
                (
                    "sl002.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/sl002.raw"),
                ),
                (
                    "sl004.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/sl004.raw"),
                ),
                (
                    "sl006.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/sl006.raw"),
                ),
                (
                    "sl008.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/sl008.raw"),
                ),
                (
                    "sl010.raw",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/sl010.raw"),
                ),
                (
                    "tail.dat",
                    include_bytes!("../../crates/io/tests/fixtures/nrrd/tail.dat"),
                ),
            ],
        )
    });
    let (control, file) = split_control(data);
    let name = if control & 8 != 0 {
        "input.nhdr"
    } else {
        "input.nrrd"
    };
    harness.read(name, file, VolumeFormat::Nrrd, frame_choice(control), None);
});
