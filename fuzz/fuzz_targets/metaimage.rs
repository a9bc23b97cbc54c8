//! Fuzzes the reader of MetaImage, attached (`.mha`) and detached (`.mhd`, with the fixtures' data files beside it).
//! The first byte chooses `--frame` (bits 0-2) and `.mhd` (bit 3).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| {
        Harness::new(
            "metaimage",
            &[
                (
                    "be_i16.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/be_i16.raw"),
                ),
                (
                    "headersize.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/headersize.raw"),
                ),
                (
                    "list_0.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/list_0.raw"),
                ),
                (
                    "list_1.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/list_1.raw"),
                ),
                (
                    "list_2.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/list_2.raw"),
                ),
                (
                    "list_3.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/list_3.raw"),
                ),
                (
                    "list_4.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/list_4.raw"),
                ),
                (
                    "slice001.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/slice001.raw"),
                ),
                (
                    "slice002.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/slice002.raw"),
                ),
                (
                    "slice003.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/slice003.raw"),
                ),
                (
                    "slice004.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/slice004.raw"),
                ),
                (
                    "slice005.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/slice005.raw"),
                ),
                (
                    "tail.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/tail.raw"),
                ),
                (
                    "u16_zlib.zraw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/u16_zlib.zraw"),
                ),
                (
                    "u8.raw",
                    include_bytes!("../../crates/io/tests/fixtures/metaimage/u8.raw"),
                ),
            ],
        )
    });
    let (control, file) = split_control(data);
    let name = if control & 8 != 0 {
        "input.mhd"
    } else {
        "input.mha"
    };
    harness.read(
        name,
        file,
        VolumeFormat::MetaImage,
        frame_choice(control),
        None,
    );
});
