//! Where voxels come from, box by box: the one interface a renderer of
//! pieces takes its data through, whatever holds the data.
//!
//! A [`VolumeSource`] knows its grid (dimensions, spacing, origin) and
//! sample type without reading anything, and gives any box of voxels as a
//! [`Volume`] when asked. Behind it:
//!
//! - a [`Volume`] in memory (this file): a box is a copy of its rows;
//! - a file mapped from disk, in its own axis order (volray-io's
//!   `Reorientation`): a box is copied out of the mapping and reordered;
//! - a chunked store (Zarr, OME-Zarr levels in volray-io): a box is
//!   decoded from the chunks it touches, and nothing else is read.
//!
//! The renderers of pieces take either: a rank of an MPI render reads its
//! own box, and an out-of-core render (volray-distributed's `streamed`)
//! reads the pieces one after another, so that a volume of any size
//! renders in the memory one piece takes.
//!
//! ```
//! use volray_core::glam::DVec3;
//! use volray_core::{Volume, VolumeSource};
//!
//! let volume = Volume::from_fn([8, 8, 8], DVec3::ONE, DVec3::ZERO, |p| p.x as f32).unwrap();
//! let source: &dyn VolumeSource = &volume;
//! let piece = source.read_box([2, 0, 0], [6, 8, 8]).unwrap();
//! assert_eq!(piece.dims(), [4, 8, 8]);
//! assert_eq!(piece.get(0, 0, 0), 2.0);
//! assert_eq!(piece.origin(), DVec3::new(2.0, 0.0, 0.0));
//! ```
//!
//! A box that cannot be read is a [`SourceError`]: its one-line message,
//! and what kind of failure it was ([`SourceErrorKind`]), so that a front
//! end reading piece by piece tells bad data (a corrupt or lying chunk:
//! the command line's exit 1) from the system failing to read (exit 2),
//! as it does for a file read whole.

use super::{SampleType, Volume};
use crate::sampling::grid::GridFrame;
use thiserror::Error;

/// What kind of failure a [`SourceError`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceErrorKind {
    /// The data is corrupt, malformed or inconsistent (a garbled or cut
    /// chunk, a header that lies): bad input.
    BadData,
    /// The operating system failed to read it (a chunk that cannot be
    /// opened or read): an I/O failure.
    Io,
    /// The box would take more memory than the source may use: a limit,
    /// the caller's to raise or to read smaller boxes under.
    OverMemory,
    /// The box asked for is not a box of the grid ([`check_box`]): the
    /// caller's mistake.
    OutsideGrid,
    /// The source was stopped before the read (a stop flag set).
    Stopped,
}

/// Why a box could not be read: a one-line message naming the data and
/// the problem, and its [`SourceErrorKind`].
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{message}")]
pub struct SourceError {
    pub kind: SourceErrorKind,
    pub message: String,
}

impl SourceError {
    /// An error of `kind` saying `message` (one line).
    pub fn new(kind: SourceErrorKind, message: impl Into<String>) -> Self {
        SourceError {
            kind,
            message: message.into(),
        }
    }

    /// [`SourceErrorKind::BadData`].
    pub fn bad_data(message: impl Into<String>) -> Self {
        Self::new(SourceErrorKind::BadData, message)
    }

    /// [`SourceErrorKind::Io`].
    pub fn io(message: impl Into<String>) -> Self {
        Self::new(SourceErrorKind::Io, message)
    }

    /// True when the operating system failed to read (exit code 2 on the
    /// command line); false when the data, the limits or the request were
    /// at fault (exit code 1).
    pub fn is_io_failure(&self) -> bool {
        self.kind == SourceErrorKind::Io
    }

    /// The same error, its message prefixed with `prefix` and `: `.
    pub fn prefixed(self, prefix: impl std::fmt::Display) -> Self {
        SourceError {
            kind: self.kind,
            message: format!("{prefix}: {}", self.message),
        }
    }
}

/// A source of boxes of one volume's voxels (see the module documentation).
pub trait VolumeSource: Send + Sync {
    /// The whole volume's grid.
    fn grid(&self) -> GridFrame;

    /// The type its samples are kept in once read.
    fn sample_type(&self) -> SampleType;

    /// Whether its values are labels (a segmentation).
    fn is_labels(&self) -> bool {
        false
    }

    /// The voxels `lo..hi` (half-open, at least 2 a side) of the whole grid
    /// as a volume placed where they are in the whole (its origin the
    /// world position of `lo`), or a one-line error naming the data and
    /// the problem, and whether it was unreadable, corrupt, or more than
    /// the memory allowed ([`SourceError`]).
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError>;

    /// Bytes one voxel takes once read.
    fn voxel_bytes(&self) -> usize {
        self.sample_type().bytes()
    }
}

/// Checks that `lo..hi` is a box of at least 2 voxels a side inside `dims`.
/// ([`SourceErrorKind::OutsideGrid`] if not).
pub fn check_box(dims: [usize; 3], lo: [usize; 3], hi: [usize; 3]) -> Result<(), SourceError> {
    if (0..3).all(|a| lo[a] + 2 <= hi[a] && hi[a] <= dims[a]) {
        Ok(())
    } else {
        Err(SourceError::new(
            SourceErrorKind::OutsideGrid,
            format!(
                "box {lo:?}..{hi:?} is not a box of at least 2 voxels a side inside the {}x{}x{} grid",
                dims[0], dims[1], dims[2]
            ),
        ))
    }
}

/// A volume in memory is a source of its boxes.
impl VolumeSource for Volume {
    fn grid(&self) -> GridFrame {
        GridFrame {
            dims: self.dims(),
            origin: self.origin(),
            spacing: self.spacing(),
        }
    }

    fn sample_type(&self) -> SampleType {
        Volume::sample_type(self)
    }

    fn is_labels(&self) -> bool {
        Volume::is_labels(self)
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        check_box(self.dims(), lo, hi)?;
        Ok(self.sub_box(lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn a_volume_gives_its_boxes_and_refuses_boxes_outside_it() {
        let v = Volume::from_fn([5, 4, 3], DVec3::splat(0.5), DVec3::ONE, |p| {
            (p.x + 10.0 * p.y + 100.0 * p.z) as f32
        })
        .unwrap()
        .as_labels();
        let b = VolumeSource::read_box(&v, [1, 1, 1], [4, 3, 3]).unwrap();
        assert_eq!(b.dims(), [3, 2, 2]);
        assert_eq!(b.get(0, 0, 0), v.get(1, 1, 1));
        assert_eq!(b.get(2, 1, 1), v.get(3, 2, 2));
        assert_eq!(b.origin(), v.world_position(1, 1, 1));
        assert!(b.is_labels() && VolumeSource::is_labels(&v));
        let err = VolumeSource::read_box(&v, [0, 0, 0], [6, 4, 3]).unwrap_err();
        assert!(err.message.contains("inside the 5x4x3 grid"), "{err}");
        assert_eq!(err.kind, SourceErrorKind::OutsideGrid);
        assert!(!err.is_io_failure());
        assert!(VolumeSource::read_box(&v, [0, 0, 2], [5, 4, 3]).is_err());
    }

    #[test]
    fn only_a_failure_to_read_is_an_io_failure_and_a_prefix_keeps_the_kind() {
        let io = SourceError::io("c/0/0/0: cannot open: Is a directory").prefixed("scan.zarr");
        assert!(io.is_io_failure());
        assert_eq!(
            io.to_string(),
            "scan.zarr: c/0/0/0: cannot open: Is a directory"
        );
        for kind in [
            SourceErrorKind::BadData,
            SourceErrorKind::OverMemory,
            SourceErrorKind::OutsideGrid,
            SourceErrorKind::Stopped,
        ] {
            let e = SourceError::new(kind, "x").prefixed("f");
            assert_eq!((e.kind, e.is_io_failure()), (kind, false));
        }
    }
}
