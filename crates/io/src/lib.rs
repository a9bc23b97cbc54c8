//! volray's file formats: getting volumes in and images out.
//!
//! The data path of the renderer is
//!
//! ```text
//! file (raw, .npy) --read_volume--> Volume --volray-core renders--> Image --write_png--> PNG
//! ```
//!
//! This crate owns both ends: [`read_volume`] turns a file into a
//! [`Volume`] (x fastest, `index = x + nx·(y + ny·z)`),
//! choosing the reader from the file name, and [`write_png`] turns an
//! [`Image`](volray_core::Image) into an RGB PNG. Every file is written
//! through [`write_atomically`], so a failed write never leaves a
//! half-written file. Errors are [`IoError`]s: one-line messages that name
//! the file, split by [`IoError::is_io_failure`] into operating-system
//! failures and bad input.
//!
//! Readers:
//! - raw: headerless samples whose layout the caller gives in
//!   [`RawOptions`] (dims, [`DType`], [`Endian`], spacing); see [`read_raw`].
//! - NumPy `.npy`: 3-D arrays indexed `a[x, y, z]`; see [`read_npy`] and
//!   [`write_npy`].
//!
//! # Example
//!
//! ```
//! use volray_io::{DType, Endian, RawOptions, read_volume};
//! use volray_core::glam::DVec3;
//!
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("ramp.raw");
//! // A 2×2×2 volume of big-endian u16 samples 0, 10, ..., 70, x fastest.
//! let bytes: Vec<u8> = (0..8u16).flat_map(|v| (10 * v).to_be_bytes()).collect();
//! std::fs::write(&path, bytes)?;
//!
//! let opts = RawOptions {
//!     dims: [2, 2, 2],
//!     dtype: DType::U16,
//!     endian: Endian::Big,
//!     spacing: DVec3::new(1.0, 1.0, 2.5),
//! };
//! let volume = read_volume(&path, Some(&opts))?;
//! assert_eq!(volume.dims(), [2, 2, 2]);
//! assert_eq!(volume.get(1, 0, 1), 50.0); // index 1 + 2·(0 + 2·1) = 5
//! assert_eq!(volume.spacing().z, 2.5);
//!
//! // Without a layout, a file that is not .npy is refused.
//! let err = read_volume(&path, None).unwrap_err();
//! assert!(!err.is_io_failure());
//! assert!(err.to_string().contains("--dims"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod atomic;
mod dtype;
mod error;
mod input;
mod npy;
mod png;
mod raw;

use std::path::Path;

use volray_core::Volume;

pub use self::png::{BitDepth, quantize_8, quantize_16, write_png};
pub use atomic::write_atomically;
pub use dtype::{DType, Endian, ParseNameError, bytes_to_f32, extend_f32};
pub use error::IoError;
pub use npy::{read_npy, write_npy};
pub use raw::{RawOptions, read_raw};

/// The volume formats [`read_volume`] can tell from a file name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VolumeFormat {
    /// NumPy `.npy`.
    Npy,
}

impl VolumeFormat {
    /// The format a file name's extension (case-insensitive) announces, if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "npy" => Some(VolumeFormat::Npy),
            _ => None,
        }
    }

    /// The usual extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            VolumeFormat::Npy => "npy",
        }
    }
}

/// Reads the volume at `path`.
///
/// A file whose extension names a known format ([`VolumeFormat`]) is read
/// by that format's reader, and `raw` must then be `None`: such files
/// carry their own layout. Any other file is read as raw data laid out as
/// `raw` says; without `raw` it is refused as an unknown format.
pub fn read_volume(path: &Path, raw: Option<&RawOptions>) -> Result<Volume, IoError> {
    match (VolumeFormat::from_path(path), raw) {
        (Some(format), Some(_)) => Err(IoError::RawOptionsNotApplicable {
            path: path.to_path_buf(),
            format: format.extension(),
        }),
        (Some(VolumeFormat::Npy), None) => read_npy(path),
        (None, Some(opts)) => read_raw(path, opts),
        (None, None) => Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatch_by_extension() {
        let dir = tempfile::tempdir().unwrap();
        let v = Volume::new([2, 2, 3], (0..12).map(|i| i as f32).collect()).unwrap();
        let upper = dir.path().join("V.NPY");
        write_npy(&upper, &v).unwrap();
        assert_eq!(read_volume(&upper, None).unwrap(), v);

        let opts = RawOptions::new([2, 2, 3], DType::F32);
        let err = read_volume(&upper, Some(&opts)).unwrap_err();
        assert!(!err.is_io_failure());
        assert!(
            err.to_string()
                .ends_with("raw options do not apply to .npy files"),
            "{err}"
        );

        // A .npy file under another name is raw data to read_volume.
        let raw = dir.path().join("v.bin");
        std::fs::copy(&upper, &raw).unwrap();
        let err = read_volume(&raw, None).unwrap_err();
        assert!(matches!(err, IoError::UnknownFormat { .. }), "{err}");
        assert!(err.to_string().starts_with(&raw.display().to_string()));
        let err = read_volume(&raw, Some(&opts)).unwrap_err();
        assert!(matches!(err, IoError::RawSizeMismatch { .. }), "{err}");

        // Missing .npy file: an I/O failure.
        let err = read_volume(&dir.path().join("gone.npy"), None).unwrap_err();
        assert!(err.is_io_failure());
    }

    #[test]
    fn format_detection() {
        assert_eq!(
            VolumeFormat::from_path(Path::new("a/b.Npy")),
            Some(VolumeFormat::Npy)
        );
        assert_eq!(VolumeFormat::from_path(Path::new("a/npy")), None);
        assert_eq!(VolumeFormat::from_path(Path::new("b.npy.raw")), None);
    }
}
