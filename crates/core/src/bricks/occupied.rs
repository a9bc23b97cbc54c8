//! The fast path's view-independent stage 1: the occupied bricks of a
//! volume under one transfer function, with every voxel's normal, material
//! colour and opacity, kept compact and kept across frames.
//!
//! A brick (see [`crate::bricks`]) is *occupied* when any of its voxels has
//! a non-zero opacity; the others hold no sample that could add to a ray
//! (trilinear interpolation of eight zero opacities is exactly zero), so
//! they are neither stored nor visited. The min/max macro-cell grid rules
//! out most of them at once (see [`crate::bricks::macrocells`]); the rest are
//! classified voxel by voxel, with the voxel's gradient where the opacity
//! depends on it (an iso-surface, gradient-magnitude opacity). Inside an occupied brick a mask marks the
//! occupied *cells* (any of the eight corners with non-zero opacity), so
//! that the ray caster skips empty cells with one bit test.
//!
//! Storage per voxel slot of an occupied brick (8 bytes, [`Voxel`]): the
//! unit normal (gradient direction, errata 1) as three `i16` in units of
//! 1/32767, zero where the gradient is zero (ambient light only), and the
//! per-sample opacity as a `u16` in units of 1/65535. Normal rounding moves
//! `N·L` by at most 3·0.5/32767 ≈ 4.6·10⁻⁵; opacity rounding is at most
//! 7.6·10⁻⁶ (opacity needs the 16 bits: it compounds along a ray, and 8 bits
//! would cost up to 1/510 per sample). The material colour is not stored:
//! each frame recomputes it exactly from the voxel's value.
//!
//! All of this depends on the volume and the classifier only: the light,
//! which follows the camera, is applied per frame by [`crate::cpu::lit_bricks`].

use crate::bricks::macrocells::Macrocells;
use crate::bricks::{BRICK, BrickGrid, CELLS, SIDE, SLOTS, cell, slot, slot_coords};
use crate::kernels::gradient::Differences;
use crate::transfer::classifier::Classifier;
use crate::volume::{Sample, Volume};
use rayon::prelude::*;

/// Bytes one occupied brick takes, for the memory bound
/// ([`crate::memory`]): its [`SLOTS`] voxels and its entries in every
/// per-brick list of [`ClassifiedBricks`] (and the flag each brick gets
/// while they are found).
pub(crate) const BYTES_PER_OCCUPIED_BRICK: usize = SLOTS * size_of::<Voxel>()
    + size_of::<[usize; 3]>()
    + size_of::<[u64; CELLS / 64]>()
    + size_of::<([u8; 3], [u8; 3])>()
    + size_of::<[u64; SLOTS.div_ceil(64)]>();
/// Bytes every brick, occupied or not, takes in [`ClassifiedBricks`]
/// (`slot_of`, and the occupancy flag while classifying).
pub(crate) const BYTES_PER_BRICK: usize = size_of::<u32>() + size_of::<bool>();

/// Units of a `u16` colour or opacity: 65535 is 1.
pub const UNIT: f32 = 65535.0;
/// Units of an `i16` normal component: 32767 is 1.
pub const NORMAL_UNIT: f32 = 32767.0;
/// `slot_of` entry of a brick that is not occupied.
pub const EMPTY: u32 = u32::MAX;

/// `x` in [0, 1] to the nearest `u16` step.
#[inline]
pub fn quantise(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * UNIT + 0.5) as u16
}

/// The unit vector along `gradient` in `i16` steps, or zero where the
/// gradient is zero or not finite (no normal: ambient light only).
#[inline]
pub fn quantise_normal(gradient: [f32; 3]) -> [i16; 3] {
    let [x, y, z] = gradient;
    let len = (x * x + y * y + z * z).sqrt();
    if len > 0.0 && len.is_finite() {
        gradient.map(|g| (g / len * NORMAL_UNIT).round() as i16)
    } else {
        [0; 3]
    }
}

/// What is kept of one voxel slot: eight bytes, the normal first, so that
/// two voxels load as one 16-byte vector of `i16`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(C)]
pub struct Voxel {
    /// The unit normal, quantised; zero where there is none.
    pub normal: [i16; 3],
    /// The per-sample opacity, quantised.
    pub alpha: u16,
}

/// The occupied bricks of a volume under one classifier.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassifiedBricks {
    pub grid: BrickGrid,
    /// Per brick (see [`BrickGrid::index`]): its number among the occupied
    /// bricks, or [`EMPTY`].
    pub slot_of: Vec<u32>,
    /// Per occupied brick: its coordinates.
    pub occupied: Vec<[usize; 3]>,
    /// Per occupied brick: bit [`cell`] set where the cell has a corner of
    /// non-zero opacity.
    pub cells: Vec<[u64; CELLS / 64]>,
    /// Per occupied brick: the first and the last occupied cell along x, y
    /// and z. Samples outside this box are in empty cells.
    pub occupied_cells: Vec<([u8; 3], [u8; 3])>,
    /// Per occupied brick: bit `s` set where slot `s` is a corner of an
    /// occupied cell. The other slots are never sampled.
    pub needed: Vec<[u64; SLOTS.div_ceil(64)]>,
    /// Per occupied brick, [`SLOTS`] each, in slot order.
    pub voxels: Vec<Voxel>,
}

impl ClassifiedBricks {
    /// Classifies `volume` brick by brick; `macrocells` are its value
    /// ranges. For a cleaned volume, the voxels `masked` says (non-finite in the
    /// original, see [`NonFinite`](crate::NonFinite)) get zero opacity.
    pub fn new(
        volume: &Volume,
        macrocells: &Macrocells,
        classifier: &Classifier,
        masked: impl Fn(usize) -> bool + Sync,
    ) -> Self {
        crate::with_samples!(volume.samples(), |data| Self::classify(
            Differences::new(data, volume),
            data,
            macrocells,
            classifier,
            &masked
        ))
    }

    /// [`Self::new`] on samples `data` of type `T`.
    fn classify<T: Sample>(
        differences: Differences<T>,
        data: &[T],
        macrocells: &Macrocells,
        classifier: &Classifier,
        masked: &(impl Fn(usize) -> bool + Sync),
    ) -> Self {
        let grid = macrocells.grid;
        let [nx, ny, _] = grid.dims;
        let coords = |v: usize| (v % nx, (v / nx) % ny, v / (nx * ny));
        // The gradient is computed here only where the opacity needs it;
        // the occupied bricks' voxels below need it for their normals anyway.
        let opacity = |v: usize| {
            if masked(v) {
                return 0;
            }
            let gradient = if classifier.uses_gradient() {
                let (x, y, z) = coords(v);
                differences.at(x, y, z)
            } else {
                [0.0; 3]
            };
            quantise(classifier.opacity_at(data[v].to_f32(), gradient))
        };
        let is_occupied: Vec<bool> = (0..grid.len())
            .into_par_iter()
            .map(|i| {
                let (lo, hi) = macrocells.ranges[i];
                let b = grid.coords(i);
                !classifier.is_transparent_between(lo, hi)
                    && slot_coords().any(|s| opacity(grid.voxel_of_slot(b, s)) > 0)
            })
            .collect();

        let mut slot_of = vec![EMPTY; grid.len()];
        let mut occupied = Vec::new();
        for (i, _) in is_occupied.iter().enumerate().filter(|(_, o)| **o) {
            slot_of[i] = occupied.len() as u32;
            occupied.push(grid.coords(i));
        }

        let mut voxels = vec![Voxel::default(); occupied.len() * SLOTS];
        let mut cells = vec![[0u64; CELLS / 64]; occupied.len()];
        let mut occupied_cells = vec![([0u8; 3], [0u8; 3]); occupied.len()];
        let mut needed = vec![[0u64; SLOTS.div_ceil(64)]; occupied.len()];
        voxels
            .par_chunks_mut(SLOTS)
            .zip(cells.par_iter_mut())
            .zip(occupied_cells.par_iter_mut())
            .zip(needed.par_iter_mut())
            .zip(occupied.par_iter())
            .for_each(|((((voxels, cells), bounds), needed), &b)| {
                for (s, [i, j, k]) in slot_coords().enumerate() {
                    let v = grid.voxel_of_slot(b, [i, j, k]);
                    let (x, y, z) = coords(v);
                    let gradient = differences.at(x, y, z);
                    let alpha = if masked(v) {
                        0.0
                    } else {
                        classifier.opacity_at(data[v].to_f32(), gradient)
                    };
                    voxels[s] = Voxel {
                        normal: quantise_normal(gradient),
                        alpha: quantise(alpha),
                    };
                }
                *cells = cell_mask(voxels);
                *bounds = cell_bounds(cells);
                *needed = needed_slots(cells);
            });

        ClassifiedBricks {
            grid,
            slot_of,
            occupied,
            cells,
            occupied_cells,
            needed,
            voxels,
        }
    }

    /// The index-space box of occupied brick `n`'s occupied cells, clipped
    /// to the volume.
    pub fn occupied_box(&self, n: usize) -> ([usize; 3], [usize; 3]) {
        let origin = self.grid.origin(self.occupied[n]);
        let (first, last) = self.occupied_cells[n];
        let lo = std::array::from_fn(|a| origin[a] + first[a] as usize);
        let hi =
            std::array::from_fn(|a| (origin[a] + last[a] as usize + 1).min(self.grid.dims[a] - 1));
        (lo, hi)
    }

    /// Number of occupied bricks.
    pub fn len(&self) -> usize {
        self.occupied.len()
    }
}

/// The occupied cells of one brick from its slots' opacities.
fn cell_mask(voxels: &[Voxel]) -> [u64; CELLS / 64] {
    let mut mask = [0u64; CELLS / 64];
    let side = SIDE - 1;
    for k in 0..side {
        for j in 0..side {
            for i in 0..side {
                let any = (0..8).any(|c| {
                    let s = slot(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                    voxels[s].alpha > 0
                });
                if any {
                    let n = cell(i, j, k);
                    mask[n / 64] |= 1 << (n % 64);
                }
            }
        }
    }
    mask
}

/// The slots at the corners of a brick's occupied cells.
fn needed_slots(cells: &[u64; CELLS / 64]) -> [u64; SLOTS.div_ceil(64)] {
    let mut needed = [0u64; SLOTS.div_ceil(64)];
    for k in 0..BRICK {
        for j in 0..BRICK {
            for i in 0..BRICK {
                let n = cell(i, j, k);
                if cells[n / 64] >> (n % 64) & 1 == 1 {
                    for c in 0..8 {
                        let s = slot(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                        needed[s / 64] |= 1 << (s % 64);
                    }
                }
            }
        }
    }
    needed
}

/// The first and last occupied cell along each axis of a brick with at
/// least one occupied cell.
fn cell_bounds(cells: &[u64; CELLS / 64]) -> ([u8; 3], [u8; 3]) {
    let (mut lo, mut hi) = ([u8::MAX; 3], [0u8; 3]);
    for k in 0..BRICK {
        for j in 0..BRICK {
            for i in 0..BRICK {
                let n = cell(i, j, k);
                if cells[n / 64] >> (n % 64) & 1 == 1 {
                    for (a, c) in [i, j, k].into_iter().enumerate() {
                        lo[a] = lo[a].min(c as u8);
                        hi[a] = hi[a].max(c as u8);
                    }
                }
            }
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::gradient::{gradient_at, max_magnitude};
    use crate::transfer::classifier::OpacityMap;
    use crate::transfer::function::PiecewiseLinear;
    use crate::transfer::iso::IsoSurface;
    use glam::DVec3;

    /// Opacity zero below t = 0.5, a ramp above it.
    fn threshold() -> Classifier {
        let table = PiecewiseLinear::new("opacity", vec![(0.5, [0.0]), (1.0, [0.8])]).unwrap();
        Classifier::new((0.0, 1.0), OpacityMap::Table(table), None, 0.5)
    }

    #[test]
    fn only_bricks_with_visible_voxels_are_kept() {
        // One bright voxel at (12, 3, 20) in a 30 × 10 × 25 grid: it lies in
        // brick (1, 0, 2) only (x 8..16, y 0..8, z 16..24).
        let mut data = vec![0.0f32; 30 * 10 * 25];
        data[12 + 30 * (3 + 10 * 20)] = 1.0;
        let v = Volume::new([30, 10, 25], data).unwrap();
        let c = threshold();
        let b = ClassifiedBricks::new(&v, &Macrocells::new(&v), &c, |_| false);
        assert_eq!(b.occupied, vec![[1, 0, 2]]);
        assert_eq!(b.slot_of[b.grid.index([1, 0, 2])], 0);
        assert_eq!(b.slot_of.iter().filter(|&&s| s != EMPTY).count(), 1);
        // The voxel is local (4, 3, 4): the eight cells around it are occupied.
        let occupied: Vec<usize> = (0..CELLS)
            .filter(|n| b.cells[0][n / 64] >> (n % 64) & 1 == 1)
            .collect();
        let mut want: Vec<usize> = (0..8)
            .map(|c| cell(3 + (c & 1), 2 + ((c >> 1) & 1), 3 + (c >> 2)))
            .collect();
        want.sort();
        assert_eq!(occupied, want);
        assert_eq!(b.occupied_cells, vec![([3, 2, 3], [4, 3, 4])]);
        // The corners of those cells: the 3 × 3 × 3 slots around the voxel.
        let needed: Vec<usize> = (0..SLOTS)
            .filter(|s| b.needed[0][s / 64] >> (s % 64) & 1 == 1)
            .collect();
        let mut want: Vec<usize> = (0..27)
            .map(|c| slot(3 + c % 3, 2 + (c / 3) % 3, 3 + c / 9))
            .collect();
        want.sort();
        assert_eq!(needed, want);
        assert_eq!(
            b.voxels[slot(4, 3, 4)].alpha,
            quantise(c.sample_opacity(1.0))
        );
        assert_eq!(b.voxels[slot(5, 3, 4)].alpha, 0);
    }

    #[test]
    fn a_voxel_on_a_brick_face_occupies_both_bricks() {
        let mut data = vec![0.0f32; 20 * 5 * 5];
        data[8 + 20 * (2 + 5 * 2)] = 1.0;
        let v = Volume::new([20, 5, 5], data).unwrap();
        let b = ClassifiedBricks::new(&v, &Macrocells::new(&v), &threshold(), |_| false);
        assert_eq!(b.occupied, vec![[0, 0, 0], [1, 0, 0]]);
    }

    #[test]
    fn normals_are_unit_gradients() {
        // f = 0.6 + 0.03 (3x + 4y) on a stretched grid: the world gradient
        // is along (3/2, 4, 0) after the x spacing of 2.
        let v = Volume::from_fn([12, 12, 12], DVec3::new(2.0, 1.0, 1.0), DVec3::ZERO, |p| {
            (0.6 + 0.03 * (1.5 * p.x + 4.0 * p.y)) as f32
        })
        .unwrap();
        let b = ClassifiedBricks::new(&v, &Macrocells::new(&v), &threshold(), |_| false);
        assert!(b.len() > 0);
        let want = DVec3::new(1.5, 4.0, 0.0).normalize() * NORMAL_UNIT as f64;
        for v in &b.voxels {
            for a in 0..3 {
                let n = v.normal;
                assert!((n[a] as f64 - want[a]).abs() <= 1.0, "{n:?} vs {want}");
            }
        }
        assert_eq!(quantise_normal([0.0; 3]), [0; 3]);
        assert_eq!(quantise_normal([0.0, -1e-10, 0.0]), [0, -32767, 0]);
        // As in [`crate::kernels::phong`], a gradient whose square underflows has no normal.
        assert_eq!(quantise_normal([0.0, -1e-30, 0.0]), [0; 3]);
    }

    #[test]
    fn iso_bricks_are_exactly_those_near_the_surface() {
        // The distance from the centre of a 40³ grid, iso-surface at 9
        // voxels, 2 voxels thick: bricks far inside and far outside the
        // shell are skipped by their value range alone, and every brick
        // with a voxel of non-zero contour opacity is kept.
        let v = Volume::from_fn([40, 40, 40], DVec3::ONE, DVec3::ZERO, |p| {
            (p - DVec3::splat(19.5)).length() as f32
        })
        .unwrap();
        let m = Macrocells::new(&v);
        let base = Classifier::new((0.0, 30.0), OpacityMap::Ramp { p: 0.1, q: 0.6 }, None, 0.7);
        let iso = IsoSurface {
            value: 9.0,
            thickness: 2.0,
        };
        let c = base.with_iso(iso, 1.0, max_magnitude(&v));
        let b = ClassifiedBricks::new(&v, &m, &c, |_| false);
        let mut skipped_by_range = 0;
        for i in 0..m.grid.len() {
            let brick = m.grid.coords(i);
            let alphas: Vec<u16> = slot_coords()
                .map(|s| {
                    let n = m.grid.voxel_of_slot(brick, s);
                    let (x, y, z) = (n % 40, (n / 40) % 40, n / 1600);
                    quantise(c.opacity_at(v.samples().get(n), gradient_at(&v, x, y, z)))
                })
                .collect();
            let visible = alphas.iter().any(|a| *a > 0);
            assert_eq!(b.slot_of[i] != EMPTY, visible, "brick {brick:?}");
            let (lo, hi) = m.ranges[i];
            if c.is_transparent_between(lo, hi) {
                assert!(!visible, "brick {brick:?} called transparent");
                skipped_by_range += 1;
            }
            if visible {
                let n = b.slot_of[i] as usize;
                let stored: Vec<u16> = b.voxels[n * SLOTS..][..SLOTS]
                    .iter()
                    .map(|v| v.alpha)
                    .collect();
                assert_eq!(stored, alphas);
            }
        }
        // 5³ bricks; the 98 that touch the grid's faces hold no value
        // nearer the centre than 11.5, beyond 9 + 2·max|∇f| ≈ 11; the 27
        // inner ones all hold values within reach of 9.
        assert_eq!(skipped_by_range, 98);
        assert!(b.len() > 0);
    }
}
