//! The min/max macro-cell grid: the smallest and largest value among the
//! voxels of every brick (see [`crate::bricks`]).
//!
//! It depends on the data alone, so it is computed once per volume. Tested
//! against a transfer function's zero-opacity ranges
//! ([`crate::transfer::classifier::Classifier::is_transparent_between`]), it rules
//! out most empty bricks without classifying their voxels one by one.

use crate::bricks::{BrickGrid, SIDE, slot_coords};
use crate::volume::{Sample, Volume};
use rayon::prelude::*;

/// Bytes each brick takes in [`Macrocells`].
pub(crate) const BYTES_PER_BRICK: usize = size_of::<(f32, f32)>();

/// `(min, max)` of the values of every brick's voxels, faces included.
#[derive(Debug, Clone, PartialEq)]
pub struct Macrocells {
    pub grid: BrickGrid,
    pub ranges: Vec<(f32, f32)>,
}

impl Macrocells {
    pub fn new(volume: &Volume) -> Self {
        let grid = BrickGrid::new(volume.dims());
        let ranges = crate::with_samples!(volume.samples(), |data| ranges(data, grid));
        Macrocells { grid, ranges }
    }
}

/// Every brick's `(min, max)` over `data`'s values as `f32`.
fn ranges<T: Sample>(data: &[T], grid: BrickGrid) -> Vec<(f32, f32)> {
    (0..grid.len())
        .into_par_iter()
        .map(|i| {
            let b = grid.coords(i);
            let mut range = (f32::INFINITY, f32::NEG_INFINITY);
            // Whole rows of slots at a time: x varies fastest in both.
            for s in slot_coords().step_by(SIDE) {
                let start = grid.voxel_of_slot(b, s);
                let end = grid.voxel_of_slot(b, [SIDE - 1, s[1], s[2]]);
                for v in &data[start..=end] {
                    let v = v.to_f32();
                    range = (range.0.min(v), range.1.max(v));
                }
            }
            range
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn ranges_cover_each_bricks_voxels_and_faces() {
        // f = x + 100 y on 20 × 12 × 3 voxels: bricks [0, 8], [8, 16], [16, 19]
        // along x and [0, 8], [8, 11] along y.
        let v = Volume::from_fn([20, 12, 3], DVec3::ONE, DVec3::ZERO, |p| {
            (p.x + 100.0 * p.y) as f32
        })
        .unwrap();
        let m = Macrocells::new(&v);
        assert_eq!(m.grid.bricks, [3, 2, 1]);
        assert_eq!(m.ranges[m.grid.index([0, 0, 0])], (0.0, 808.0));
        assert_eq!(m.ranges[m.grid.index([1, 0, 0])], (8.0, 816.0));
        assert_eq!(m.ranges[m.grid.index([2, 1, 0])], (816.0, 1119.0));
    }
}
