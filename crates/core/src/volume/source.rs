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

use super::{SampleType, Volume};
use crate::sampling::grid::GridFrame;

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
    /// the problem (unreadable, corrupt, or more than the memory allowed).
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String>;

    /// Bytes one voxel takes once read.
    fn voxel_bytes(&self) -> usize {
        self.sample_type().bytes()
    }
}

/// Checks that `lo..hi` is a box of at least 2 voxels a side inside `dims`.
pub fn check_box(dims: [usize; 3], lo: [usize; 3], hi: [usize; 3]) -> Result<(), String> {
    if (0..3).all(|a| lo[a] + 2 <= hi[a] && hi[a] <= dims[a]) {
        Ok(())
    } else {
        Err(format!(
            "box {lo:?}..{hi:?} is not a box of at least 2 voxels a side inside the {}x{}x{} grid",
            dims[0], dims[1], dims[2]
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

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
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
        assert!(err.contains("inside the 5x4x3 grid"), "{err}");
        assert!(VolumeSource::read_box(&v, [0, 0, 2], [5, 4, 3]).is_err());
    }
}
