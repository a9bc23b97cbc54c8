//! The harness shared by volray's fuzz targets (one target per reader,
//! in `fuzz_targets/`).
//!
//! volray's readers take a path, not bytes, so each target writes its
//! input to a file in a scratch directory of its own (under `/dev/shm`,
//! one per process, reused for every input) and reads it back through
//! [`volray_io::read`] with the format forced, exactly as
//! `volray render FILE --format F` would. A read that succeeds is then
//! touched (`Volume::value_range` and friends) so
//! that nothing is left undone lazily.
//!
//! What a target checks is the project's rule for bad input: no panic, no
//! abort, no hang, no allocation beyond libFuzzer's `-malloc_limit_mb`,
//! and an error that is one line naming the file. Any `Err` is fine.
//!
//! Companion files (the data of a detached `.nhdr`/`.mhd` header, the
//! `.img` of a NIfTI `.hdr`) are written into the scratch directory once,
//! under the names the seed headers use, so detached headers are fuzzed
//! too.

use std::fs;
use std::path::{Path, PathBuf};

use volray_io::{IoError, ReadOptions, VolumeFormat};

/// How every scratch directory's name starts.
const SCRATCH_PREFIX: &str = "/volray-fuzz-";

/// One reader under fuzzing: where its inputs go and which companions
/// lie beside them.
pub struct Harness {
    dir: PathBuf,
}

impl Harness {
    /// A scratch directory for `target` in this process, holding the
    /// `companions` (file name, bytes).
    pub fn new(target: &str, companions: &[(&str, &[u8])]) -> Harness {
        let base = if Path::new("/dev/shm").is_dir() {
            PathBuf::from("/dev/shm")
        } else {
            std::env::temp_dir()
        };
        let dir = base.join(format!(
            "{}{target}-{}",
            &SCRATCH_PREFIX[1..],
            std::process::id()
        ));
        fs::create_dir_all(&dir).expect("cannot create the fuzz scratch directory");
        for (name, bytes) in companions {
            fs::write(dir.join(name), bytes).expect("cannot write a companion file");
        }
        Harness { dir }
    }

    /// The scratch directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes `data` to `file_name` in the scratch directory and returns
    /// its path.
    pub fn put(&self, file_name: &str, data: &[u8]) -> PathBuf {
        let path = self.dir.join(file_name);
        if let Some(parent) = path.parent() {
            fs::create_dir_all(parent).expect("cannot create the fuzz input's directory");
        }
        fs::write(&path, data).expect("cannot write the fuzz input");
        path
    }

    /// Writes `data` to `file_name` and reads it as `format` with `frame`
    /// and `array`: see [`read_path`].
    pub fn read(
        &self,
        file_name: &str,
        data: &[u8],
        format: VolumeFormat,
        frame: Option<usize>,
        array: Option<&str>,
    ) {
        let path = self.put(file_name, data);
        read_path(&path, format, frame, array);
    }
}

/// Reads `path` as `format` and checks the outcome: a volume is touched
/// all over, an error must be one line naming a file in the scratch
/// directory (the input or a companion it names).
pub fn read_path(path: &Path, format: VolumeFormat, frame: Option<usize>, array: Option<&str>) {
    let opts = ReadOptions {
        format: Some(format),
        frame,
        array: array.map(str::to_string),
        ..ReadOptions::default()
    };
    read_with(path, &opts);
}

/// As [`read_path`], with the options given whole (the raw target sets
/// the layout).
pub fn read_with(path: &Path, opts: &ReadOptions) {
    match volray_io::read(path, opts) {
        Ok(loaded) => {
            let v = &loaded.volume;
            std::hint::black_box((
                v.value_range(),
                v.count_non_finite(),
                v.dims(),
                v.extent(),
                v.bounds(),
                v.centre(),
            ));
            std::hint::black_box(format!("{:?}", loaded.info));
        }
        Err(err) => check_error(&err),
    }
}

/// Opens `path` lazily, as a source of boxes (a chunked store: Zarr, HDF5),
/// and reads the box of the first half of each axis (at least 2 voxels),
/// so that the readers of part of a chunk or shard are fuzzed too; a
/// refusal (of the store, or of the box) must be one line naming the file.
pub fn read_lazy_half(path: &Path, opts: &ReadOptions) {
    match volray_io::open_lazy(path, opts) {
        Ok(Some(lazy)) => {
            let dims = lazy.source.grid().dims;
            // Boxes are at least 2 voxels a side.
            let hi = dims.map(|d| d.div_ceil(2).max(2).min(d));
            match lazy.source.read_box([0; 3], hi) {
                Ok(v) => {
                    std::hint::black_box((v.value_range(), v.count_non_finite()));
                }
                Err(e) => {
                    let message = e.to_string();
                    assert!(
                        !message.contains('\n') && message.contains(SCRATCH_PREFIX),
                        "a box's error is not one line naming the file: {message:?}"
                    );
                }
            }
        }
        Ok(None) => {}
        Err(err) => check_error(&err),
    }
}

/// The project's rule for errors: one line, naming the file. The file
/// named may be a companion in the same directory (a detached header's
/// data file) or the input under another spelling (`file.h5:/dataset`),
/// so the check is for the scratch directory; an operating-system
/// failure names the file it failed on, wherever a header pointed it
/// (an absolute `data file:` path).
fn check_error(err: &IoError) {
    let message = err.to_string();
    assert!(
        !message.contains('\n'),
        "error message spans several lines: {message:?}"
    );
    if matches!(
        err,
        IoError::Os { .. } | IoError::NotAFile { .. } | IoError::Truncated { .. }
    ) {
        return;
    }
    assert!(
        message.contains(SCRATCH_PREFIX),
        "error message does not name the file: {message:?}"
    );
}

/// Splits the options byte off the front of an input: targets whose
/// reader takes `--frame` or `--array` prefix their inputs with one byte
/// choosing them (seeds start with 0, the defaults).
pub fn split_control(data: &[u8]) -> (u8, &[u8]) {
    match data.split_first() {
        Some((&c, rest)) => (c, rest),
        None => (0, data),
    }
}

/// The `--frame` a control byte chooses (its low 3 bits): none, 0 to 4,
/// or an index far past any file's frames (`2^40`, `usize::MAX`) so that
/// frame arithmetic is checked for overflow.
pub fn frame_choice(control: u8) -> Option<usize> {
    match control & 7 {
        0 => None,
        n @ 1..=5 => Some(usize::from(n) - 1),
        6 => Some(1 << 40),
        _ => Some(usize::MAX),
    }
}

/// The `--array` a control byte chooses (bits 4 to 7): none, or one of the
/// array names the VTK seeds hold, with and without the `point:`/`cell:`
/// prefixes, or names they do not hold.
pub fn array_choice(control: u8) -> Option<&'static str> {
    const NAMES: [&str; 15] = [
        "ramp",
        "cells",
        "point:ramp",
        "cell:cells",
        "point:cells",
        "cell:ramp",
        "velocity",
        "pair a",
        "other",
        "u8",
        "f64",
        "ImageFile",
        "v",
        "missing",
        "point:",
    ];
    match control >> 4 {
        0 => None,
        n => Some(NAMES[usize::from(n) - 1]),
    }
}
