//! Fuzzes the HDF5 reader (pure Rust, hdf5-pure; hdf5-reader for the
//! chunk indexes hdf5-pure cannot read: the seed `latest.h5` holds
//! `/u8`, `/u32`, `/gzip_u16` and `/series` under a version 2 B-tree, a
//! fixed array with layout message 5 and an extensible array).
//! The first byte chooses `--frame` (bits 0-2), a lazy read of a box of
//! half the dataset (bit 3: the chunk index, the chunks a box touches,
//! contiguous rows; `open_lazy`) rather than the whole, and the dataset
//! (bits 4-7, one of the names the seed files hold, or none that exists).
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, frame_choice, read_lazy_half, read_path, split_control};
use volray_io::{ReadOptions, VolumeFormat};

static HARNESS: OnceLock<Harness> = OnceLock::new();

const DATASETS: [&str; 16] = [
    "/fields/density",
    "/u8",
    "/i16_be",
    "/u32",
    "/i64",
    "/f64",
    "/gzip_u16",
    "/series",
    "/bad_spacing",
    "/text",
    "/fields/labels",
    "/meta/plane",
    "/fields",
    "/",
    "/missing",
    "/fields/density/x",
];

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("hdf5", &[]));
    let (control, file) = split_control(data);
    let path = harness.put("input.h5", file);
    let dataset = DATASETS[usize::from(control >> 4)];
    let target = path.with_file_name(format!("input.h5:{dataset}"));
    if control & 8 != 0 {
        let opts = ReadOptions {
            format: Some(VolumeFormat::Hdf5),
            frame: frame_choice(control),
            max_memory: 64 << 20,
            ..ReadOptions::default()
        };
        read_lazy_half(&target, &opts);
    } else {
        read_path(&target, VolumeFormat::Hdf5, frame_choice(control), None);
    }
});
