//! Fuzzes the MINC reader: MINC2 (HDF5 in libminc's layout, through
//! hdf5-pure) and, for inputs starting with `CDF`, MINC1 (NetCDF-3).
//! The first byte chooses `--frame` (bits 0-2).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, read_path, split_control};
use volray_io::VolumeFormat;

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("minc", &[]));
    let (control, file) = split_control(data);
    let path = harness.put("input.mnc", file);
    read_path(&path, VolumeFormat::Minc, frame_choice(control), None);
});
