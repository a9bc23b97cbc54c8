//! Fuzzes the NetCDF-3 reader (CDF-1, CDF-2, CDF-5 with the CF
//! conventions; a MINC1 layout is handed to the MINC reader).
//! The first byte chooses `--frame` (bits 0-2) and `--array` (bits 4-6:
//! none, or a variable the seeds hold or not).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

const ARRAYS: [Option<&str>; 8] = [
    None,
    Some("rho"),
    Some("temp"),
    Some("v"),
    Some("time"),
    Some("x"),
    Some("image"),
    Some("missing"),
];

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("netcdf", &[]));
    let (control, file) = split_control(data);
    harness.read(
        "input.nc",
        file,
        VolumeFormat::Netcdf,
        frame_choice(control),
        ARRAYS[usize::from((control >> 4) & 7)],
    );
});
