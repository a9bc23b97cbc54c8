//! [`IoError`]: everything that can go wrong reading a volume or writing an image.
//!
//! Every message is one line that starts with the file it is about
//! (`Path::display`) followed by the problem, e.g.
//! `data.raw: file is 1000 bytes but raw layout 10x10x10 f32 needs 4000 bytes`.
//!
//! Messages speak of the reader's own options ([`ReadOptions`]), never of
//! a command line's flags. An error a reader option caused has a variant
//! of its own carrying the option's value ([`IoError::RawSizeMismatch`],
//! [`IoError::FrameOutOfRange`], [`IoError::OverMemoryLimit`], ...), so
//! that a command-line tool can say which of its flags set it by matching
//! on the variant.
//!
//! An underlying `std::io::Error` is part of the message, not a
//! [`source`](std::error::Error::source), so printing an error chain never
//! repeats it.

use std::io;
use std::path::{Path, PathBuf};

use thiserror::Error;
use volray_core::{SourceError, SourceErrorKind, VolumeError};

#[cfg(doc)]
use crate::ReadOptions;
use crate::dtype::DType;

/// Why a volume could not be read or an image could not be written.
#[derive(Debug, Error)]
pub enum IoError {
    /// The operating system refused an operation (open, read, write, sync, rename).
    #[error("{}: cannot {action}: {error}", path.display())]
    Os {
        path: PathBuf,
        /// What was being done, as a verb phrase: "open", "read", "write", ...
        action: &'static str,
        error: io::Error,
    },

    /// The path exists but is a directory or some other non-regular file.
    #[error("{}: not a regular file", path.display())]
    NotAFile { path: PathBuf },

    /// A file got shorter between checking its size and reading it.
    #[error("{}: file ended after {read} of {expected} expected bytes (was it changed while being read?)", path.display())]
    Truncated {
        path: PathBuf,
        read: u64,
        expected: u64,
    },

    /// The directory a file should be written into does not exist.
    #[error("{}: cannot write: directory {} does not exist", path.display(), dir.display())]
    NoSuchDirectory { path: PathBuf, dir: PathBuf },

    /// A destination that is (or whose parent is) not what a file can be written to.
    #[error("{}: cannot write: {reason}", path.display())]
    BadDestination { path: PathBuf, reason: String },

    /// Raw data whose length does not match the raw layout's dimensions
    /// and sample type ([`ReadOptions::raw`]).
    #[error(
        "{}: file is {actual} bytes but raw layout {}x{}x{} {dtype} needs {expected} bytes",
        path.display(), dims[0], dims[1], dims[2]
    )]
    RawSizeMismatch {
        path: PathBuf,
        dims: [usize; 3],
        dtype: DType,
        actual: u64,
        expected: u64,
    },

    /// Raw layout dimensions so large that the byte count overflows.
    #[error(
        "{}: raw layout {}x{}x{} {dtype} describes more bytes than this machine can address",
        path.display(), dims[0], dims[1], dims[2]
    )]
    DimsOverflow {
        path: PathBuf,
        dims: [usize; 3],
        dtype: DType,
    },

    /// The data does not make a valid [`Volume`](volray_core::Volume).
    #[error("{}: {error}", path.display())]
    Volume { path: PathBuf, error: VolumeError },

    /// A malformed or unsupported NumPy `.npy` file.
    #[error("{}: {reason}", path.display())]
    Npy { path: PathBuf, reason: String },

    /// A malformed, inconsistent or unsupported file of a known format.
    /// `reason` names the field and the value, e.g.
    /// `NRRD field "sizes": 3 values for dimension 4`.
    #[error("{}: {reason}", path.display())]
    Invalid { path: PathBuf, reason: String },

    /// No reader is known for the file and no raw layout was given
    /// ([`ReadOptions::raw`], [`ReadOptions::format`]).
    #[error(
        "{}: unknown volume format (known by extension or content: {}); raw data needs a raw layout (dimensions, and sample type, byte order, spacing as needed), or name the format",
        path.display(), crate::VolumeFormat::KNOWN
    )]
    UnknownFormat { path: PathBuf },

    /// A format volray recognises (by content) but does not read, e.g.
    /// `scan.PAR: Philips PAR/REC is not read by volray; convert it to ...`:
    /// `hint` names a tool that converts it to a format volray reads.
    #[error("{}: {format} is not read by volray; {hint}", path.display())]
    NotRead {
        path: PathBuf,
        format: &'static str,
        hint: &'static str,
    },

    /// A raw layout ([`ReadOptions::raw`]) given for a file whose format
    /// carries its own layout.
    #[error("{}: raw layout options do not apply to {format} files", path.display())]
    RawOptionsNotApplicable { path: PathBuf, format: &'static str },

    /// A frame ([`ReadOptions::frame`]) chosen in a file whose format holds
    /// one volume.
    #[error("{}: frame selection does not apply to {format} files: they hold one volume", path.display())]
    FrameNotApplicable { path: PathBuf, format: &'static str },

    /// A resolution level ([`ReadOptions::level`]) chosen in a file whose
    /// format has one.
    #[error("{}: level selection applies to Zarr/OME-Zarr images only, not to {format} files", path.display())]
    LevelNotApplicable { path: PathBuf, format: &'static str },

    /// A channel ([`ReadOptions::channel`]) the file does not hold. `held`
    /// says what it holds, e.g. `the file holds 3 channels (dim[5]),
    /// numbered from 0` (see [`Volumes`](crate::Volumes)).
    #[error("{}: channel {channel} is out of range: {held}", path.display())]
    ChannelOutOfRange {
        path: PathBuf,
        channel: usize,
        held: String,
    },

    /// A frame ([`ReadOptions::frame`]) the file does not hold. `held` says
    /// what it holds, e.g. `the file holds 2 volumes (dim[4]), numbered from 0`.
    #[error("{}: frame {frame} is out of range: {held}", path.display())]
    FrameOutOfRange {
        path: PathBuf,
        frame: usize,
        held: String,
    },

    /// A file holding several volumes none of which is read without a
    /// frame ([`ReadOptions::frame`]): `held` says what it holds (`directory
    /// holds 2 DICOM series`), `choices` lists them by frame number.
    #[error("{}: {held}; choose one by its frame number: {choices}", path.display())]
    FrameNeeded {
        path: PathBuf,
        held: String,
        choices: String,
    },

    /// A named array ([`ReadOptions::array`]) chosen in a file whose format
    /// has none.
    #[error("{}: array selection applies to VTK files and OME-Zarr plates and collections only, not to {format} files", path.display())]
    ArrayNotApplicable { path: PathBuf, format: &'static str },

    /// A named array ([`ReadOptions::array`]) the file does not hold; `held`
    /// lists what it holds.
    #[error("{}: no array named \"{name}\": {held}", path.display())]
    NoSuchArray {
        path: PathBuf,
        name: String,
        held: String,
    },

    /// A named array ([`ReadOptions::array`]) that is not a scalar, in a
    /// file that holds one-component arrays: `array` says which and how
    /// many components it has (`point array "v" has 3 components`),
    /// `scalars` names the one-component arrays.
    #[error(
        "{}: {array}: volray renders scalar arrays; pick a one-component array ({scalars})",
        path.display()
    )]
    ArrayNotScalar {
        path: PathBuf,
        array: String,
        scalars: String,
    },

    /// Data that would take more memory than [`ReadOptions::max_memory`]
    /// (or the limit a caller gave). `need` says what needs it, up to the
    /// limit: `sizes 4000 4000 4000 (6.4e10 values, 238 GiB as f32) exceed`.
    #[error("{}: {need} the memory limit of {}", path.display(), crate::format_bytes(u128::from(*limit)))]
    OverMemoryLimit {
        path: PathBuf,
        need: String,
        limit: u64,
    },

    /// A file that holds one image, not a volume (a single slice, a 2-D
    /// image): what was read, for a caller that describes files rather
    /// than rendering them; `reason` says why a volume needs more.
    #[error("{}: {}", path.display(), image.reason)]
    FlatImage {
        path: PathBuf,
        image: Box<crate::FlatImage>,
    },

    /// An image that PNG cannot hold (a side of 0 or more than 2^31 − 1 pixels).
    #[error(
        "{}: cannot write a {width}x{height} image as PNG: each side must be 1 to 2147483647 pixels",
        path.display()
    )]
    ImageSize {
        path: PathBuf,
        width: usize,
        height: usize,
    },
}

impl IoError {
    /// True for genuine operating-system I/O failures (a file or directory
    /// that cannot be opened, read, written or renamed: exit code 2 in the
    /// CLI); false for bad input, i.e. a malformed or inconsistent file or
    /// options (exit code 1).
    ///
    /// A missing input file, a missing output directory and a destination
    /// that is a directory count as I/O failures: the operating system
    /// cannot perform the operation asked of it.
    pub fn is_io_failure(&self) -> bool {
        match self {
            IoError::Os { .. }
            | IoError::NotAFile { .. }
            | IoError::Truncated { .. }
            | IoError::NoSuchDirectory { .. }
            | IoError::BadDestination { .. } => true,
            IoError::RawSizeMismatch { .. }
            | IoError::DimsOverflow { .. }
            | IoError::Volume { .. }
            | IoError::Npy { .. }
            | IoError::Invalid { .. }
            | IoError::UnknownFormat { .. }
            | IoError::NotRead { .. }
            | IoError::RawOptionsNotApplicable { .. }
            | IoError::FrameNotApplicable { .. }
            | IoError::LevelNotApplicable { .. }
            | IoError::FrameOutOfRange { .. }
            | IoError::ChannelOutOfRange { .. }
            | IoError::FrameNeeded { .. }
            | IoError::ArrayNotApplicable { .. }
            | IoError::NoSuchArray { .. }
            | IoError::ArrayNotScalar { .. }
            | IoError::OverMemoryLimit { .. }
            | IoError::FlatImage { .. }
            | IoError::ImageSize { .. } => false,
        }
    }

    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            IoError::Os { path, .. }
            | IoError::NotAFile { path }
            | IoError::Truncated { path, .. }
            | IoError::NoSuchDirectory { path, .. }
            | IoError::BadDestination { path, .. }
            | IoError::RawSizeMismatch { path, .. }
            | IoError::DimsOverflow { path, .. }
            | IoError::Volume { path, .. }
            | IoError::Npy { path, .. }
            | IoError::Invalid { path, .. }
            | IoError::UnknownFormat { path }
            | IoError::NotRead { path, .. }
            | IoError::RawOptionsNotApplicable { path, .. }
            | IoError::FrameNotApplicable { path, .. }
            | IoError::LevelNotApplicable { path, .. }
            | IoError::FrameOutOfRange { path, .. }
            | IoError::ChannelOutOfRange { path, .. }
            | IoError::FrameNeeded { path, .. }
            | IoError::ArrayNotApplicable { path, .. }
            | IoError::NoSuchArray { path, .. }
            | IoError::ArrayNotScalar { path, .. }
            | IoError::OverMemoryLimit { path, .. }
            | IoError::FlatImage { path, .. }
            | IoError::ImageSize { path, .. } => path,
        }
    }

    pub(crate) fn os(path: &Path, action: &'static str, error: io::Error) -> Self {
        // A compressed file's decoder found its stream corrupt: bad input
        // (shared/packed.rs), not the system's failure.
        if let Some(corrupt) = (error.get_ref()).and_then(|e| e.downcast_ref::<CorruptStream>()) {
            return IoError::invalid(path, corrupt.to_string());
        }
        IoError::Os {
            path: path.to_path_buf(),
            action,
            error,
        }
    }

    pub(crate) fn npy(path: &Path, reason: impl Into<String>) -> Self {
        IoError::Npy {
            path: path.to_path_buf(),
            reason: reason.into(),
        }
    }

    /// A bad-input error about `path`: `reason` should name the field and
    /// the value that are wrong.
    /// Control characters from the file (a name with a newline in it, a
    /// parser's multi-line message) are escaped, so the message stays one
    /// line.
    pub fn invalid(path: &Path, reason: impl Into<String>) -> Self {
        IoError::Invalid {
            path: path.to_path_buf(),
            reason: one_line(reason),
        }
    }

    // The variants a reader option causes, their text from the file made
    // one line as [`IoError::invalid`] does.

    /// [`IoError::FrameOutOfRange`]: `frame` is not among what the file
    /// holds, which `held` says.
    pub(crate) fn frame_out_of_range(path: &Path, frame: usize, held: impl Into<String>) -> Self {
        IoError::FrameOutOfRange {
            path: path.to_path_buf(),
            frame,
            held: one_line(held),
        }
    }

    /// [`IoError::ChannelOutOfRange`]: `channel` is not among what the
    /// file holds, which `held` says.
    pub(crate) fn channel_out_of_range(
        path: &Path,
        channel: usize,
        held: impl Into<String>,
    ) -> Self {
        IoError::ChannelOutOfRange {
            path: path.to_path_buf(),
            channel,
            held: one_line(held),
        }
    }

    /// [`IoError::NoSuchArray`].
    pub(crate) fn no_such_array(path: &Path, name: &str, held: impl Into<String>) -> Self {
        IoError::NoSuchArray {
            path: path.to_path_buf(),
            name: one_line(name),
            held: one_line(held),
        }
    }

    /// [`IoError::ArrayNotScalar`].
    pub(crate) fn array_not_scalar(
        path: &Path,
        array: impl Into<String>,
        scalars: impl Into<String>,
    ) -> Self {
        IoError::ArrayNotScalar {
            path: path.to_path_buf(),
            array: one_line(array),
            scalars: one_line(scalars),
        }
    }

    /// [`IoError::OverMemoryLimit`]: `need` says what exceeds `limit`.
    pub(crate) fn over_memory_limit(path: &Path, need: impl Into<String>, limit: u64) -> Self {
        IoError::OverMemoryLimit {
            path: path.to_path_buf(),
            need: one_line(need),
            limit,
        }
    }

    pub(crate) fn volume(path: &Path, error: VolumeError) -> Self {
        IoError::Volume {
            path: path.to_path_buf(),
            error,
        }
    }
}

/// A reader's error as a box read's (a lazy reader's
/// [`VolumeSource::read_box`](volray_core::VolumeSource::read_box)): the
/// same line, an I/O failure kept apart from bad data and from the
/// memory limit.
impl From<IoError> for SourceError {
    fn from(e: IoError) -> Self {
        let kind = match &e {
            IoError::OverMemoryLimit { .. } => SourceErrorKind::OverMemory,
            e if e.is_io_failure() => SourceErrorKind::Io,
            _ => SourceErrorKind::BadData,
        };
        SourceError::new(kind, e.to_string())
    }
}

/// `text` with its control characters escaped (`\n`, `\u{1b}`): one line.
fn one_line(text: impl Into<String>) -> String {
    let text: String = text.into();
    if !text.chars().any(char::is_control) {
        return text;
    }
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// A decoder's complaint about its stream: the file is corrupt (bad
/// input), not unreadable. Carried inside an [`io::Error`] of kind
/// `InvalidData`, which [`IoError::os`] turns into an invalid-file error
/// (shared/packed.rs's decoders, an `.npz` member's).
#[derive(Debug)]
pub(crate) struct CorruptStream(pub String);

impl std::fmt::Display for CorruptStream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for CorruptStream {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_one_line_and_start_with_the_file() {
        let errors = [
            IoError::os(
                Path::new("a/b.raw"),
                "open",
                io::Error::new(io::ErrorKind::NotFound, "No such file or directory"),
            ),
            IoError::RawSizeMismatch {
                path: "data.raw".into(),
                dims: [10, 10, 10],
                dtype: DType::F32,
                actual: 1000,
                expected: 4000,
            },
            IoError::npy(Path::new("x.npy"), "bad magic"),
            IoError::volume(Path::new("v.raw"), VolumeError::TooThin(1, 2, 2)),
            IoError::UnknownFormat {
                path: "v.dat".into(),
            },
            IoError::frame_out_of_range(
                Path::new("a.nii"),
                5,
                "the file holds 2 volumes (dim[4]), numbered from 0",
            ),
            IoError::over_memory_limit(
                Path::new("a.nrrd"),
                "sizes 10 10 10 (1000 values, 3.9 KiB as f32) exceed",
                4 << 30,
            ),
        ];
        for e in &errors {
            let msg = e.to_string();
            assert!(!msg.contains('\n'), "{msg}");
            let name = e.path().display().to_string();
            assert!(msg.starts_with(&format!("{name}: ")), "{msg}");
        }
        assert_eq!(
            errors[1].to_string(),
            "data.raw: file is 1000 bytes but raw layout 10x10x10 f32 needs 4000 bytes"
        );

        assert_eq!(
            errors[0].to_string(),
            "a/b.raw: cannot open: No such file or directory"
        );
        assert_eq!(
            errors[5].to_string(),
            "a.nii: frame 5 is out of range: the file holds 2 volumes (dim[4]), numbered from 0"
        );
        assert_eq!(
            errors[6].to_string(),
            "a.nrrd: sizes 10 10 10 (1000 values, 3.9 KiB as f32) exceed the memory limit of 4 GiB"
        );
    }

    #[test]
    fn invalid_escapes_control_characters() {
        // A name with a newline, a parser's multi-line message: still one line.
        let e = IoError::invalid(Path::new("f.vti"), "a\nb\tc\u{1b}");
        assert_eq!(e.to_string(), "f.vti: a\\nb\\tc\\u{1b}");
        let e = IoError::no_such_array(Path::new("f.vtk"), "a\nb", "the file holds \"c\rd\"");
        assert_eq!(
            e.to_string(),
            "f.vtk: no array named \"a\\nb\": the file holds \"c\\rd\""
        );
        let plain = IoError::invalid(Path::new("f"), "x \"y\" é");
        assert_eq!(plain.to_string(), "f: x \"y\" é");
        assert!(!plain.is_io_failure());
    }

    #[test]
    fn a_box_read_keeps_the_line_and_whether_the_system_failed() {
        let cases = [
            (
                IoError::os(Path::new("c/0"), "read", io::Error::other("boom")),
                SourceErrorKind::Io,
            ),
            (
                IoError::invalid(Path::new("s.zarr"), "chunk cut"),
                SourceErrorKind::BadData,
            ),
            (
                IoError::over_memory_limit(Path::new("s.zarr"), "Zarr box", 10),
                SourceErrorKind::OverMemory,
            ),
        ];
        for (e, kind) in cases {
            let line = e.to_string();
            let s = SourceError::from(e);
            assert_eq!((s.kind, s.message), (kind, line));
        }
    }

    #[test]
    fn io_failures_are_told_from_bad_input() {
        let os = IoError::os(Path::new("f"), "read", io::Error::other("boom"));
        assert!(os.is_io_failure());
        assert!(
            IoError::NoSuchDirectory {
                path: "d/f.png".into(),
                dir: "d".into()
            }
            .is_io_failure()
        );
        assert!(!IoError::npy(Path::new("f.npy"), "bad").is_io_failure());
        assert!(!IoError::volume(Path::new("f"), VolumeError::TooThin(1, 1, 1)).is_io_failure());
        assert!(
            !IoError::UnknownFormat {
                path: "f.dat".into()
            }
            .is_io_failure()
        );
        assert!(
            !IoError::ImageSize {
                path: "f.png".into(),
                width: 0,
                height: 3
            }
            .is_io_failure()
        );
    }
}
