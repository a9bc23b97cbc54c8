//! Fuzzes the reader of NumPy `.npz` archives (the `zip` crate, then each
//! member through the `.npy` reader).
//! The first byte chooses `--array` (bits 4-5: none, `arr_0`, `density`,
//! `missing`).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("npz", &[]));
    let (control, file) = split_control(data);
    let array =
        [None, Some("arr_0"), Some("density"), Some("missing")][usize::from(control >> 4) & 3];
    harness.read("input.npz", file, VolumeFormat::Npz, None, array);
});
