//! [`IoError`]: everything that can go wrong reading a volume or writing an image.
//!
//! Every message is one line that starts with the file it is about
//! (`Path::display`) followed by the problem, e.g.
//! `data.raw: file is 1000 bytes but --dims 10,10,10 with --dtype f32 need 4000 bytes`.
//! An underlying `std::io::Error` is part of the message, not a
//! [`source`](std::error::Error::source), so printing an error chain never
//! repeats it.

use std::io;
use std::path::{Path, PathBuf};

use thiserror::Error;
use volray_core::VolumeError;

use crate::shared::dtype::DType;

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

    /// Raw data whose length does not match the dimensions and sample type.
    #[error(
        "{}: file is {actual} bytes but --dims {},{},{} with --dtype {dtype} need {expected} bytes",
        path.display(), dims[0], dims[1], dims[2]
    )]
    RawSizeMismatch {
        path: PathBuf,
        dims: [usize; 3],
        dtype: DType,
        actual: u64,
        expected: u64,
    },

    /// Dimensions so large that the byte count overflows.
    #[error(
        "{}: --dims {},{},{} with --dtype {dtype} describe more bytes than this machine can address",
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

    /// A malformed, inconsistent or unsupported file of a known format, or
    /// a reader option (`--frame`, `--array`) the file cannot satisfy.
    /// `reason` names the field and the value, e.g.
    /// `NRRD field "sizes": 3 values for dimension 4`.
    #[error("{}: {reason}", path.display())]
    Invalid { path: PathBuf, reason: String },

    /// No reader is known for the file and no raw layout was given.
    #[error(
        "{}: unknown volume format (known by extension or content: {}); raw data needs --dims (and --dtype, --endian, --spacing as needed), or name the format with --format",
        path.display(), crate::VolumeFormat::KNOWN
    )]
    UnknownFormat { path: PathBuf },

    /// Raw layout options given for a file whose format carries its own layout.
    #[error("{}: raw options (--dims, --dtype, --endian) do not apply to {format} files", path.display())]
    RawOptionsNotApplicable { path: PathBuf, format: &'static str },

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
            | IoError::RawOptionsNotApplicable { .. }
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
            | IoError::RawOptionsNotApplicable { path, .. }
            | IoError::ImageSize { path, .. } => path,
        }
    }

    pub(crate) fn os(path: &Path, action: &'static str, error: io::Error) -> Self {
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
        let reason: String = reason.into();
        let reason = if reason.chars().any(char::is_control) {
            reason
                .chars()
                .map(|c| {
                    if c.is_control() {
                        c.escape_default().to_string()
                    } else {
                        c.to_string()
                    }
                })
                .collect()
        } else {
            reason
        };
        IoError::Invalid {
            path: path.to_path_buf(),
            reason,
        }
    }

    pub(crate) fn volume(path: &Path, error: VolumeError) -> Self {
        IoError::Volume {
            path: path.to_path_buf(),
            error,
        }
    }
}

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
        ];
        for e in &errors {
            let msg = e.to_string();
            assert!(!msg.contains('\n'), "{msg}");
            let name = e.path().display().to_string();
            assert!(msg.starts_with(&format!("{name}: ")), "{msg}");
        }
        assert_eq!(
            errors[1].to_string(),
            "data.raw: file is 1000 bytes but --dims 10,10,10 with --dtype f32 need 4000 bytes"
        );
        assert_eq!(
            errors[0].to_string(),
            "a/b.raw: cannot open: No such file or directory"
        );
    }

    #[test]
    fn invalid_escapes_control_characters() {
        // A name with a newline, a parser's multi-line message: still one line.
        let e = IoError::invalid(Path::new("f.vti"), "a\nb\tc\u{1b}");
        assert_eq!(e.to_string(), "f.vti: a\\nb\\tc\\u{1b}");
        let plain = IoError::invalid(Path::new("f"), "x \"y\" é");
        assert_eq!(plain.to_string(), "f: x \"y\" é");
        assert!(!plain.is_io_failure());
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
