//! Non-finite voxel values (NaN, ±∞): refused, or rendered as empty space.
//!
//! The rules are documented on [`NonFinite`], what a caller chooses.

use crate::bricks::{BRICK, BrickGrid};
use crate::kernels::trilinear::weights;
use crate::volume::Volume;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// What the renderer does with a volume holding NaN or infinite values.
///
/// Real files hold them: masked regions written as NaN, divisions by zero,
/// overflowed densities. By default the renderer refuses such a volume
/// ([`NonFinite::Refuse`], naming the count). With
/// [`NonFinite::Transparent`] a non-finite voxel contributes no opacity,
/// exactly as follows.
///
/// - **The value window** (`fmin`, `fmax`) is that of the finite values
///   ([`Volume::value_range`]), as are the range and histogram a front end reports.
/// - **Cleaned copy.** The renderer works on a copy of the volume whose
///   non-finite voxels hold the *fill* value, the smallest finite value
///   `fmin` (0 if there is none), and keeps a bitmask of them
///   ([`NonFiniteMask`]). Every path reads the copy, so no NaN can reach
///   an interpolation, a gradient or a bound; the mask decides what counts.
/// - **Gradients** are the ordinary central differences
///   ([`crate::kernels::gradient`]) of the cleaned copy: a masked voxel reads as the
///   bottom of the value range. This was chosen over one-sided differences
///   at masked neighbours (as at the grid's faces) because "empty space" is
///   what a masked voxel stands for: an object bordering a masked region
///   then has a surface there, whose normal points into the empty space
///   and is lit like any boundary between data and air, the usual meaning of
///   the lowest value (air in CT, vacuum in densities). One-sided differences
///   would instead see only the object's inside, leaving the edge of a flat
///   region with no normal (ambient light only). It also keeps one gradient
///   code for every path, so the reference and the fast paths agree by
///   construction. The largest gradient magnitude (for gradient opacity
///   and iso-surfaces) is that of these gradients.
/// - **Pre-classification** (the paper's, reference and bricked fast
///   path): a masked voxel's opacity is 0. Its colour is what the cleaned
///   copy gives it (the fill value's material, lit by its gradient); as
///   colours and opacities are interpolated separately (the paper's
///   method), that colour tints the samples in the cells next to it, as any
///   transparent voxel's does, and the opacity fades to 0 across those
///   cells.
/// - **Post-classification, the projections (maximum, minimum, average)
///   and post-classified iso-surfaces**: a sample is *skipped* (no opacity;
///   not counted by the maximum, minimum or mean) exactly when a masked
///   voxel has a non-zero trilinear weight in it, that is, when
///   interpolating the original data there would not give a finite number.
///   A sample on a grid plane takes no weight from the voxels off it, so a
///   sample on a finite voxel next to a masked one counts. A ray with no
///   counted sample shows the background.
///
/// The skip test is made on the reference's `f64` sample position
/// ([`PixelSamples::position`](crate::sampling::PixelSamples::position)) on every path, so the fast
/// paths, which interpolate in `f32`, skip the very samples the reference
/// skips (an `f32` position a rounding error across a grid plane could
/// otherwise decide the other way). The fast paths test only in bricks
/// near a masked voxel ([`NonFiniteMask::near`]); a volume without
/// non-finite values has no mask and pays nothing. Empty-space skipping
/// stays conservative: a brick's value range now includes the fill value,
/// the bottom of the finite range, which can only widen it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NonFinite {
    /// Refuse the volume, naming the count.
    #[default]
    Refuse,
    /// Render non-finite voxels as empty space (see the module's notes).
    Transparent,
}

/// Bytes a volume of `dims` voxels with non-finite values needs beside
/// itself to render them as empty space: the cleaned copy (`f32`), the mask
/// (a bit a voxel) and its per-brick flags (see [`NonFiniteMask`]).
pub(crate) fn bytes(dims: [usize; 3]) -> u128 {
    let voxels: u128 = dims.iter().map(|&n| n as u128).product();
    let bricks = BrickGrid::new(dims.map(|n| n.max(2))).len() as u128;
    voxels * size_of::<f32>() as u128
        + voxels.div_ceil(64) * size_of::<u64>() as u128
        + bricks * size_of::<bool>() as u128
}

/// The non-finite voxels of a volume, and which bricks lie near them.
#[derive(Debug, Clone, PartialEq)]
pub struct NonFiniteMask {
    dims: [usize; 3],
    /// Bit `i` set where voxel `i` (x fastest) is not finite.
    bits: Vec<u64>,
    count: usize,
    fill: f32,
    grid: BrickGrid,
    /// Per brick ([`BrickGrid::index`]): whether a masked voxel lies in its
    /// box widened by one voxel on every side.
    near: Vec<bool>,
}

impl NonFiniteMask {
    /// The mask of `volume`'s non-finite voxels and the cleaned copy, each
    /// of them replaced by the fill value (the smallest finite value, or 0
    /// if there is none); `None` if every value is finite.
    pub fn clean(volume: &Volume) -> Option<(NonFiniteMask, Volume)> {
        let count = volume.count_non_finite();
        if count == 0 {
            return None;
        }
        let fill = volume.value_range().map_or(0.0, |(lo, _)| lo);
        // Only `f32` samples can be non-finite (the count is 0 otherwise).
        let data = volume.values();
        let bits: Vec<u64> = data
            .par_chunks(64)
            .map(|chunk| {
                (chunk.iter().enumerate())
                    .filter(|(_, v)| !v.is_finite())
                    .fold(0u64, |word, (i, _)| word | 1 << i)
            })
            .collect();
        let cleaned: Vec<f32> = (data.par_iter())
            .map(|&v| if v.is_finite() { v } else { fill })
            .collect();
        let dims = volume.dims();
        let cleaned = Volume::new(dims, cleaned)
            .and_then(|v| v.with_spacing(volume.spacing()))
            .and_then(|v| v.with_origin(volume.origin()))
            .expect("the same grid as a valid volume");
        let grid = BrickGrid::new(dims);
        let mut mask = NonFiniteMask {
            dims,
            bits,
            count,
            fill,
            grid,
            near: Vec::new(),
        };
        mask.near = (0..grid.len())
            .into_par_iter()
            .map(|i| mask.any_in_widened_box(grid.coords(i)))
            .collect();
        Some((mask, cleaned))
    }

    /// Number of non-finite voxels.
    pub fn count(&self) -> usize {
        self.count
    }

    /// The value the cleaned copy holds at the masked voxels.
    pub fn fill(&self) -> f32 {
        self.fill
    }

    /// Whether voxel `index` (x fastest) is masked.
    #[inline]
    pub fn contains(&self, index: usize) -> bool {
        self.bits[index / 64] >> (index % 64) & 1 != 0
    }

    /// Whether a masked voxel lies within one voxel of brick `b`'s box:
    /// only samples in such bricks can be skipped (a sample's cell, even a
    /// rounding error outside the brick, has its corners there).
    #[inline]
    pub fn near(&self, b: [usize; 3]) -> bool {
        self.near[self.grid.index(b)]
    }

    /// [`Self::near`] for the brick of the cell holding the index-space
    /// point `p` (in `[0, n − 1]³`).
    #[inline]
    pub fn near_point(&self, p: Vec3) -> bool {
        let b = std::array::from_fn(|a| (p[a] as usize).min(self.dims[a] - 2) / BRICK);
        self.near(b)
    }

    /// Whether the sample at index-space point `p` (the reference's `f64`
    /// position) is skipped: a masked voxel has a non-zero trilinear
    /// weight in it.
    #[inline]
    pub fn skips(&self, p: DVec3) -> bool {
        weights(p.to_array(), self.dims)
            .iter()
            .any(|&(index, w)| w != 0.0 && self.contains(index))
    }

    /// Whether a masked voxel lies in brick `b`'s voxel box widened by one
    /// voxel on every side (clipped to the grid).
    fn any_in_widened_box(&self, b: [usize; 3]) -> bool {
        let (lo, hi) = self.grid.bounds(b);
        let lo = lo.map(|c| c.saturating_sub(1));
        let hi: [usize; 3] = std::array::from_fn(|a| (hi[a] + 1).min(self.dims[a] - 1));
        let [nx, ny, _] = self.dims;
        (lo[2]..=hi[2]).any(|z| {
            (lo[1]..=hi[1]).any(|y| {
                let row = nx * (y + ny * z);
                (lo[0]..=hi[0]).any(|x| self.contains(row + x))
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn volume(dims: [usize; 3], non_finite: &[(usize, f32)]) -> Volume {
        let n = dims.iter().product();
        let mut data: Vec<f32> = (0..n).map(|i| 2.0 + (i % 7) as f32).collect();
        for &(i, v) in non_finite {
            data[i] = v;
        }
        Volume::new(dims, data).unwrap()
    }

    #[test]
    fn a_finite_volume_has_no_mask() {
        assert!(NonFiniteMask::clean(&volume([3, 4, 5], &[])).is_none());
    }

    #[test]
    fn cleaning_fills_the_masked_voxels_with_the_smallest_finite_value() {
        let v = volume(
            [20, 9, 4],
            &[(5, f32::NAN), (64, f32::INFINITY), (700, f32::NEG_INFINITY)],
        )
        .with_spacing(DVec3::new(1.0, 0.5, 2.0))
        .unwrap()
        .with_origin(DVec3::new(-3.0, 1.0, 0.25))
        .unwrap();
        let (mask, clean) = NonFiniteMask::clean(&v).unwrap();
        assert_eq!(mask.count(), 3);
        assert_eq!(mask.fill(), 2.0);
        assert_eq!(clean.bounds(), v.bounds());
        assert_eq!(clean.value_range(), v.value_range());
        for i in 0..v.len() {
            let masked = [5, 64, 700].contains(&i);
            assert_eq!(mask.contains(i), masked, "{i}");
            let want = if masked { 2.0 } else { v.values()[i] };
            assert_eq!(clean.values()[i], want, "{i}");
        }
        // All non-finite: the fill is 0.
        let all = Volume::new([2, 2, 2], vec![f32::NAN; 8]).unwrap();
        let (mask, clean) = NonFiniteMask::clean(&all).unwrap();
        assert_eq!((mask.count(), mask.fill()), (8, 0.0));
        assert_eq!(*clean.values(), [0.0; 8]);
    }

    #[test]
    fn a_sample_is_skipped_exactly_where_a_masked_voxel_weighs_in_it() {
        // Voxel (2, 1, 1) masked in a 5×3×3 grid.
        let dims = [5, 3, 3];
        let v = volume(dims, &[(2 + 5 * (1 + 3), f32::NAN)]);
        let (mask, _) = NonFiniteMask::clean(&v).unwrap();
        let skips = |x: f64, y: f64, z: f64| mask.skips(DVec3::new(x, y, z));
        // Anywhere strictly inside the eight cells around it.
        assert!(skips(2.0, 1.0, 1.0));
        assert!(skips(1.01, 0.5, 1.7) && skips(2.99, 1.99, 0.01));
        // On a neighbouring grid plane the masked voxel has no weight.
        assert!(!skips(1.0, 1.0, 1.0) && !skips(3.0, 0.5, 1.5));
        assert!(!skips(2.0, 0.0, 1.0) && !skips(2.5, 1.5, 2.0));
        // Cells without it.
        assert!(!skips(0.5, 0.5, 0.5) && !skips(3.5, 1.5, 1.5));
        // The grid's far faces belong to the cell below, as in trilinear.
        let far = volume(dims, &[(4 + 5 * (2 + 3 * 2), f32::INFINITY)]);
        let (mask, _) = NonFiniteMask::clean(&far).unwrap();
        assert!(mask.skips(DVec3::new(4.0, 2.0, 2.0)));
        assert!(mask.skips(DVec3::new(3.5, 1.5, 1.5)));
        assert!(!mask.skips(DVec3::new(3.5, 2.0, 1.0)));
        assert!(mask.skips(DVec3::new(4.0, 2.0, 1.5)));
        assert!(!mask.skips(DVec3::new(4.0, 2.0, 1.0)));
    }

    #[test]
    fn bricks_near_a_masked_voxel_are_flagged_one_voxel_beyond_their_box() {
        // 26 voxels along x: bricks cover x in [0, 8], [8, 16], [16, 24],
        // [24, 25]. A masked voxel at x = 17 is in brick 2's box, and one
        // voxel from brick 1's (widened to 17) but not brick 3's (23).
        let dims = [26, 3, 3];
        let at = |x: usize| x + 26 * (1 + 3);
        let flags = |x: usize| {
            let (mask, _) = NonFiniteMask::clean(&volume(dims, &[(at(x), f32::NAN)])).unwrap();
            (0..4).map(|b| mask.near([b, 0, 0])).collect::<Vec<_>>()
        };
        assert_eq!(flags(17), [false, true, true, false]);
        assert_eq!(flags(16), [false, true, true, false]);
        assert_eq!(flags(23), [false, false, true, true]);
        assert_eq!(flags(0), [true, false, false, false]);
        assert_eq!(flags(25), [false, false, true, true]);
        let (mask, _) = NonFiniteMask::clean(&volume(dims, &[(at(17), f32::NAN)])).unwrap();
        assert!(mask.near_point(Vec3::new(17.5, 1.0, 1.0)));
        assert!(mask.near_point(Vec3::new(9.0, 0.0, 2.0)));
        assert!(!mask.near_point(Vec3::new(7.9, 1.0, 1.0)));
        assert!(!mask.near_point(Vec3::new(25.0, 1.0, 1.0)));
    }
}
