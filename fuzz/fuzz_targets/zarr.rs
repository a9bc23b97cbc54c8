//! Fuzzes the Zarr reader (through `zarrs`, with volray's checks): one
//! array of a metadata file and one chunk (or shard) file. The first byte
//! chooses Zarr v2 (bit 0: `.zarray` and chunk `0.0.0`; else `zarr.json`
//! and `c/0/0/0`), no chunk file at all (bit 1: the fill value), and a
//! lazy read of a box of half the array (bit 2: partial chunk and shard
//! reads) rather than the whole; the next two give the metadata's length
//! (little-endian, cut to what follows), the metadata follows, and the
//! rest is the chunk. The store is made afresh for each input, and read
//! with a memory limit of 64 MiB. Seeds: `fuzz/seeds/zarr/`
//! (`make_zarr_seeds.py`, stores written by zarr-python).
#![no_main]

use std::fs;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use volray_fuzz::{Harness, read_lazy_half, read_with, split_control};
use volray_io::{ReadOptions, VolumeFormat};

static HARNESS: OnceLock<Harness> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let harness = HARNESS.get_or_init(|| Harness::new("zarr", &[]));
    let (control, rest) = split_control(data);
    let (len, rest) = match rest {
        [lo, hi, rest @ ..] => (usize::from(u16::from_le_bytes([*lo, *hi])), rest),
        _ => (0, rest),
    };
    let (meta, chunk) = rest.split_at(len.min(rest.len()));
    let root = harness.dir().join("input.zarr");
    let _ = fs::remove_dir_all(&root);
    let (meta_name, chunk_name) = if control & 1 != 0 {
        ("input.zarr/.zarray", "input.zarr/0.0.0")
    } else {
        ("input.zarr/zarr.json", "input.zarr/c/0/0/0")
    };
    harness.put(meta_name, meta);
    if control & 2 == 0 {
        harness.put(chunk_name, chunk);
    }
    let opts = ReadOptions {
        format: Some(VolumeFormat::Zarr),
        max_memory: 64 << 20,
        ..ReadOptions::default()
    };
    if control & 4 != 0 {
        read_lazy_half(&root, &opts);
    } else {
        read_with(&root, &opts);
    }
});
