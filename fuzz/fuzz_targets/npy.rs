//! Fuzzes the reader of NumPy `.npy`.
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::Harness;
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("npy", &[]));
    harness.read("input.npy", data, VolumeFormat::Npy, None, None);
});
