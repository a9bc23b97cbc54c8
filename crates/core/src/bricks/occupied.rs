//! The fast path's view-independent stage 1: the occupied bricks of a
//! volume under one transfer function, and every voxel's normal and
//! opacity, kept compact and kept across frames, under a memory budget.
//!
//! A brick (see [`crate::bricks`]) is *occupied* when any of its voxels has
//! a non-zero opacity; the others hold no sample that could add to a ray
//! (trilinear interpolation of eight zero opacities is exactly zero), so
//! they are neither stored nor visited. The min/max macro-cell grid rules
//! out most of them at once (see [`crate::bricks::macrocells`]); the rest are
//! classified voxel by voxel, with the voxel's gradient where the opacity
//! depends on it (an iso-surface, gradient-magnitude opacity). Inside an
//! occupied brick a mask marks the occupied *cells* (any of the eight
//! corners with non-zero opacity), so that the ray caster skips empty cells
//! with one bit test, and the box of the occupied cells bounds each ray's
//! samples in it. These are kept for every occupied brick (about 100 bytes
//! a brick).
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
//! **Budget.** The slots of the occupied bricks are kept in a
//! [`BrickCache`] of at most the budget's bytes (5.8 KiB a brick). When
//! they all fit they are all classified at once and kept, as if there were
//! no budget. When they do not (a dense 1024³ CT has two million occupied
//! bricks, 11 GiB of slots), a brick is classified when a frame first
//! needs it, and kept while the budget has room or while recent frames use
//! it; the others are classified again when needed (see the cache's
//! policy). Classifying a brick gives the same slots whenever it is done,
//! so the images do not depend on the budget.
//!
//! All of this depends on the volume and the classifier only: the light,
//! which follows the camera, is applied per frame by `cpu::lit_bricks`.

use crate::bricks::cache::{BrickCache, Budget, CacheRef};
use crate::bricks::macrocells::Macrocells;
use crate::bricks::{BRICK, BrickGrid, CELLS, SIDE, SLOTS, cell, slot, slot_coords};
use crate::kernels::gradient::Differences;
use crate::transfer::classifier::Classifier;
use crate::volume::{Sample, Volume};
use rayon::prelude::*;
use std::sync::Arc;

/// Bytes one occupied brick takes beside its slots, for the memory bound
/// ([`crate::memory`]): its entries in every per-brick list of
/// [`ClassifiedBricks`] and in the cache of its slots.
pub(crate) const BYTES_PER_OCCUPIED_BRICK: usize = size_of::<u32>()
    + size_of::<[u64; CELLS / 64]>()
    + size_of::<([u8; 3], [u8; 3])>()
    + BrickCache::<Classified>::BYTES_PER_ENTRY;
/// Bytes of one occupied brick's classified slots, in the cache.
pub(crate) const SLOT_BYTES_PER_OCCUPIED_BRICK: usize = size_of::<Classified>();
/// Bytes every brick, occupied or not, takes while the occupied ones are
/// found (a flag).
pub(crate) const BYTES_PER_BRICK: usize = size_of::<bool>();

/// Units of a `u16` colour or opacity: 65535 is 1.
pub const UNIT: f32 = 65535.0;
/// Units of an `i16` normal component: 32767 is 1.
pub const NORMAL_UNIT: f32 = 32767.0;

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

/// What classifying a brick reads: the volume, the classifier, and which
/// voxels are masked (non-finite in the original, for a cleaned volume;
/// see [`NonFinite`](crate::NonFinite)), which get zero opacity.
#[derive(Clone, Copy)]
pub struct Source<'a> {
    pub volume: &'a Volume,
    pub classifier: &'a Classifier,
    pub masked: &'a (dyn Fn(usize) -> bool + Sync),
}

/// The occupied bricks of a volume under one classifier, and the cache of
/// their classified slots.
pub struct ClassifiedBricks {
    pub grid: BrickGrid,
    /// Per occupied brick: its index in the grid ([`BrickGrid::index`]).
    occupied: Vec<u32>,
    /// Per occupied brick: bit [`cell`] set where the cell has a corner of
    /// non-zero opacity.
    pub cells: Vec<[u64; CELLS / 64]>,
    /// Per occupied brick: the first and the last occupied cell along x, y
    /// and z. Samples outside this box are in empty cells.
    pub occupied_cells: Vec<([u8; 3], [u8; 3])>,
    /// Per occupied brick, its classified slots, while the budget holds
    /// them.
    voxels: BrickCache<Classified>,
}

/// An occupied brick's classified slots: its [`SLOTS`] voxels in slot
/// order, and which of them are the corners of occupied cells (the others
/// are never sampled).
#[derive(Debug, Clone, PartialEq)]
pub struct Classified {
    pub voxels: [Voxel; SLOTS],
    pub needed: [u64; SLOTS.div_ceil(64)],
}

impl Classified {
    /// All zero, to be filled.
    fn blank() -> Box<Self> {
        Box::new(Classified {
            voxels: [Voxel::default(); SLOTS],
            needed: [0; SLOTS.div_ceil(64)],
        })
    }
}

impl ClassifiedBricks {
    /// Finds the occupied bricks of `source`'s volume (`macrocells` are its
    /// value ranges) and classifies them, keeping at most `budget` bytes of
    /// classified slots (see the module docs).
    #[cfg(test)]
    pub fn new(source: &Source, macrocells: &Macrocells, budget: usize) -> Self {
        Self::sharing(source, macrocells, Budget::new(budget), &|| false).expect("never stopped")
    }

    /// [`Self::new`], the classified slots drawing on `budget`, which
    /// other caches may share (the lit bricks, which take precedence:
    /// see [`Self::shed`]). `None` once `stopped` says so: each brick
    /// asks it before its work (a frame's classification, a pass over
    /// every voxel, took 0.44 s for `fractal:257` at step 0.01, and a
    /// newer frame waited for it), and nothing half made is kept.
    pub(crate) fn sharing(
        source: &Source,
        macrocells: &Macrocells,
        budget: Arc<Budget>,
        stopped: &(dyn Fn() -> bool + Sync),
    ) -> Option<Self> {
        crate::with_samples!(source.volume.samples(), |data| Self::classify(
            source, data, macrocells, budget, stopped
        ))
    }

    /// [`Self::new`] on samples `data` of type `T`.
    fn classify<T: Sample>(
        source: &Source,
        data: &[T],
        macrocells: &Macrocells,
        budget: Arc<Budget>,
        stopped: &(dyn Fn() -> bool + Sync),
    ) -> Option<Self> {
        let Source {
            volume,
            classifier,
            masked,
        } = *source;
        let grid = macrocells.grid;
        let differences = Differences::new(data, volume);
        // The opacity of voxel `v` (at `(x, y, z)`) in the stored units;
        // the gradient is computed only where the opacity needs it.
        let opacity = |v: usize, [x, y, z]: [usize; 3]| {
            if masked(v) {
                return 0;
            }
            let gradient = if classifier.uses_gradient() {
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
                !stopped()
                    && !classifier.is_transparent_between(lo, hi)
                    && slot_coords().any(|s| {
                        let v = grid.voxel_of_slot(b, s);
                        opacity(v, grid.voxel_coords(v)) > 0
                    })
            })
            .collect();
        if stopped() {
            return None;
        }

        let occupied: Vec<u32> = (is_occupied.iter().enumerate())
            .filter(|(_, o)| **o)
            .map(|(i, _)| i as u32)
            .collect();
        drop(is_occupied);

        // Every occupied brick's cells, from its slots' opacities; and, if
        // a third of the budget holds them all, its slots, classified now
        // and kept. A third, not all of it (the share the classified
        // bricks had before the caches shared one budget): classifying
        // every brick up front costs the first frame the bricks no ray
        // reaches, and a still is one frame. The dense 512³ CT under the
        // ramp at 1024² (87 499 bricks, 0.5 GB of slots; 12 064 lit a
        // frame): classified in 1.91 s with them all up front, 0.96 s with
        // the third; later frames 0.170–0.178 s against 0.164–0.168 s
        // (`volray bench --peers`, alternated, 2026-11-25).
        let eager = occupied.len().saturating_mul(size_of::<Classified>()) <= budget.limit() / 3;
        let voxels = BrickCache::new(occupied.len(), budget, |_, _| true, |f, now| f + 1 < now);
        let (cells, occupied_cells): (Vec<_>, Vec<_>) = (0..occupied.len())
            .into_par_iter()
            .map(|n| {
                let b = grid.coords(occupied[n] as usize);
                let cells = if stopped() {
                    [0; CELLS / 64]
                } else if eager {
                    let mut slots = Classified::blank();
                    classify_brick(source, &differences, data, grid, b, &mut slots.voxels);
                    let cells = cell_mask(|s| slots.voxels[s].alpha);
                    slots.needed = needed_slots(&cells);
                    assert!(voxels.put(n, slots), "the budget holds every brick");
                    cells
                } else {
                    let mut alpha = [0u16; SLOTS];
                    for (s, local) in slot_coords().enumerate() {
                        let v = grid.voxel_of_slot(b, local);
                        alpha[s] = opacity(v, grid.voxel_coords(v));
                    }
                    cell_mask(|s| alpha[s])
                };
                (cells, cell_bounds(&cells))
            })
            .unzip();
        if stopped() {
            return None;
        }

        Some(ClassifiedBricks {
            grid,
            occupied,
            cells,
            occupied_cells,
            voxels,
        })
    }

    /// Occupied brick `n`'s classified slots in frame `frame`: from the
    /// cache, or classified now from `source` (the one the bricks were made
    /// from) into the cache or, when it has no room, into `scratch` (see
    /// [`BrickCache::get`]).
    pub fn classified<'a>(
        &'a self,
        n: usize,
        frame: u64,
        source: &Source,
        scratch: &'a mut Option<Box<Classified>>,
    ) -> CacheRef<'a, Classified> {
        self.voxels.get(
            n,
            frame,
            Classified::blank,
            |slots| {
                crate::with_samples!(source.volume.samples(), |data| classify_brick(
                    source,
                    &Differences::new(data, source.volume),
                    data,
                    self.grid,
                    self.brick(n),
                    &mut slots.voxels
                ));
                slots.needed = needed_slots(&self.cells[n]);
            },
            scratch,
            || false,
        )
    }

    /// Drops one brick's classified slots, if one is cached and no one is
    /// reading it, giving its bytes back to the budget (for the lit bricks,
    /// which need them more: a brick is classified again from the volume
    /// when needed); says whether it did.
    pub fn shed(&self) -> bool {
        self.voxels.shed()
    }

    /// How many times a brick was classified on demand since the bricks
    /// were made (into the cache or, where it had no room, a scratch
    /// buffer); bricks classified when they were made do not count.
    pub fn classified_count(&self) -> usize {
        self.voxels.fills()
    }

    /// Bytes of classified slots held now.
    pub fn slot_bytes(&self) -> usize {
        self.voxels.bytes()
    }

    /// The index-space box of occupied brick `n`'s occupied cells, clipped
    /// to the volume.
    pub fn occupied_box(&self, n: usize) -> ([usize; 3], [usize; 3]) {
        let origin = self.grid.origin(self.brick(n));
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

    /// The coordinates of occupied brick `n`.
    #[inline]
    pub fn brick(&self, n: usize) -> [usize; 3] {
        self.grid.coords(self.occupied[n] as usize)
    }

    /// The coordinates of every occupied brick, in order.
    pub fn bricks(&self) -> impl ExactSizeIterator<Item = [usize; 3]> + '_ {
        (0..self.len()).map(|n| self.brick(n))
    }
}

/// Classifies the slots of brick `b` (samples `data`, their `differences`)
/// into `slots`: each voxel's normal and opacity.
fn classify_brick<T: Sample>(
    source: &Source,
    differences: &Differences<T>,
    data: &[T],
    grid: BrickGrid,
    b: [usize; 3],
    slots: &mut [Voxel; SLOTS],
) {
    for (s, local) in slot_coords().enumerate() {
        let v = grid.voxel_of_slot(b, local);
        let [x, y, z] = grid.voxel_coords(v);
        let gradient = differences.at(x, y, z);
        let alpha = if (source.masked)(v) {
            0.0
        } else {
            source.classifier.opacity_at(data[v].to_f32(), gradient)
        };
        slots[s] = Voxel {
            normal: quantise_normal(gradient),
            alpha: quantise(alpha),
        };
    }
}

/// The occupied cells of one brick from its slots' opacities (`alpha` of
/// slot `s`, in the stored units).
fn cell_mask(alpha: impl Fn(usize) -> u16) -> [u64; CELLS / 64] {
    let mut mask = [0u64; CELLS / 64];
    let side = SIDE - 1;
    for k in 0..side {
        for j in 0..side {
            for i in 0..side {
                let any = (0..8).any(|c| {
                    let s = slot(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                    alpha(s) > 0
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

/// The slots at the corners of a brick's occupied cells: a slot is needed
/// where any of the (up to) eight cells around it is occupied. Row by row:
/// the cells along x of row `(j, k)` are one byte of the mask, and a row of
/// slots `(j, k)` takes the cells of rows `j − 1..=j` and `k − 1..=k`,
/// widened by one along x.
pub fn needed_slots(cells: &[u64; CELLS / 64]) -> [u64; SLOTS.div_ceil(64)] {
    // Cell (i, j, k) is bit i + 8j of word k (`cell`).
    const _: () = assert!(BRICK == 8 && CELLS / 64 == BRICK);
    let row = |j: usize, k: usize| (cells[k] >> (8 * j)) as u16 & 0xFF;
    let mut needed = [0u64; SLOTS.div_ceil(64)];
    for k in 0..SIDE {
        for j in 0..SIDE {
            let mut m = 0u16;
            for dk in k.saturating_sub(1)..=k.min(BRICK - 1) {
                for dj in j.saturating_sub(1)..=j.min(BRICK - 1) {
                    m |= row(dj, dk);
                }
            }
            // Slots i and i + 1 are the corners of cell i; the row's nine
            // bits may straddle two words.
            let first = slot(0, j, k);
            let bits = u128::from(m | (m << 1)) << (first % 64);
            needed[first / 64] |= bits as u64;
            if let Some(next) = needed.get_mut(first / 64 + 1) {
                *next |= (bits >> 64) as u64;
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

    /// The bricks of `v` under `c`, keeping `budget` bytes of slots.
    fn classify(v: &Volume, c: &Classifier, budget: usize) -> ClassifiedBricks {
        let source = Source {
            volume: v,
            classifier: c,
            masked: &|_| false,
        };
        ClassifiedBricks::new(&source, &Macrocells::new(v), budget)
    }

    /// Occupied brick `n`'s slots.
    fn slots(b: &ClassifiedBricks, n: usize, v: &Volume, c: &Classifier) -> Vec<Voxel> {
        let source = Source {
            volume: v,
            classifier: c,
            masked: &|_| false,
        };
        b.classified(n, 1, &source, &mut None).voxels.to_vec()
    }

    /// Opacity zero below t = 0.5, a ramp above it.
    fn threshold() -> Classifier {
        let table = PiecewiseLinear::new("opacity", vec![(0.5, [0.0]), (1.0, [0.8])]).unwrap();
        Classifier::new((0.0, 1.0), OpacityMap::Table(table), None, 0.5)
    }

    #[test]
    fn a_classification_stopped_part_way_keeps_nothing() {
        // Every brick of a bright volume is occupied: 4³ bricks.
        let v = Volume::new([33; 3], vec![1.0f32; 33 * 33 * 33]).unwrap();
        let c = threshold();
        let source = Source {
            volume: &v,
            classifier: &c,
            masked: &|_| false,
        };
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        // Stopped after the first `k` bricks asked (and, at the end, never).
        for (k, kept) in [(0, false), (10, false), (63, false), (usize::MAX, true)] {
            let asked = std::sync::atomic::AtomicUsize::new(0);
            let stopped = || asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= k;
            let bricks = one.install(|| {
                ClassifiedBricks::sharing(
                    &source,
                    &Macrocells::new(&v),
                    Budget::new(usize::MAX),
                    &stopped,
                )
            });
            assert_eq!(bricks.is_some(), kept, "stopped after {k}");
            if let Some(b) = bricks {
                assert_eq!(b.len(), 64);
            }
        }
    }

    #[test]
    fn only_bricks_with_visible_voxels_are_kept() {
        // One bright voxel at (12, 3, 20) in a 30 × 10 × 25 grid: it lies in
        // brick (1, 0, 2) only (x 8..16, y 0..8, z 16..24).
        let mut data = vec![0.0f32; 30 * 10 * 25];
        data[12 + 30 * (3 + 10 * 20)] = 1.0;
        let v = Volume::new([30, 10, 25], data).unwrap();
        let c = threshold();
        let b = classify(&v, &c, usize::MAX);
        assert_eq!(b.bricks().collect::<Vec<_>>(), vec![[1, 0, 2]]);
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
        let needed_bits = needed_slots(&b.cells[0]);
        let needed: Vec<usize> = (0..SLOTS)
            .filter(|s| needed_bits[s / 64] >> (s % 64) & 1 == 1)
            .collect();
        let mut want: Vec<usize> = (0..27)
            .map(|c| slot(3 + c % 3, 2 + (c / 3) % 3, 3 + c / 9))
            .collect();
        want.sort();
        assert_eq!(needed, want);
        let voxels = slots(&b, 0, &v, &c);
        assert_eq!(voxels[slot(4, 3, 4)].alpha, quantise(c.sample_opacity(1.0)));
        assert_eq!(voxels[slot(5, 3, 4)].alpha, 0);
    }

    #[test]
    fn the_needed_slots_are_the_corners_of_the_occupied_cells() {
        // Cell masks of every density, from a hash: the row-wise dilation
        // against the definition, cell by cell, corner by corner.
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        for density in [1u64, 5, 20, 64] {
            let cells: [u64; CELLS / 64] = std::array::from_fn(|_| {
                (0..64).fold(0, |word, bit| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    word | (u64::from(seed % 64 < density) << bit)
                })
            });
            let mut want = [0u64; SLOTS.div_ceil(64)];
            for k in 0..BRICK {
                for j in 0..BRICK {
                    for i in 0..BRICK {
                        let n = cell(i, j, k);
                        if cells[n / 64] >> (n % 64) & 1 == 1 {
                            for c in 0..8 {
                                let s = slot(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                                want[s / 64] |= 1 << (s % 64);
                            }
                        }
                    }
                }
            }
            assert_eq!(needed_slots(&cells), want, "density {density}");
        }
    }

    #[test]
    fn a_voxel_on_a_brick_face_occupies_both_bricks() {
        let mut data = vec![0.0f32; 20 * 5 * 5];
        data[8 + 20 * (2 + 5 * 2)] = 1.0;
        let v = Volume::new([20, 5, 5], data).unwrap();
        let b = classify(&v, &threshold(), usize::MAX);
        assert_eq!(b.bricks().collect::<Vec<_>>(), vec![[0, 0, 0], [1, 0, 0]]);
    }

    #[test]
    fn normals_are_unit_gradients() {
        // f = 0.6 + 0.03 (3x + 4y) on a stretched grid: the world gradient
        // is along (3/2, 4, 0) after the x spacing of 2.
        let v = Volume::from_fn([12, 12, 12], DVec3::new(2.0, 1.0, 1.0), DVec3::ZERO, |p| {
            (0.6 + 0.03 * (1.5 * p.x + 4.0 * p.y)) as f32
        })
        .unwrap();
        let c = threshold();
        let b = classify(&v, &c, usize::MAX);
        assert!(b.len() > 0);
        let want = DVec3::new(1.5, 4.0, 0.0).normalize() * NORMAL_UNIT as f64;
        let all: Vec<Voxel> = (0..b.len()).flat_map(|n| slots(&b, n, &v, &c)).collect();
        for v in &all {
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
        // Every brick's slots kept, and none kept: the same bricks, cells
        // and slots.
        let b = classify(&v, &c, usize::MAX);
        let lazy = classify(&v, &c, 0);
        assert_eq!(
            (&b.occupied, &b.cells, &b.occupied_cells),
            (&lazy.occupied, &lazy.cells, &lazy.occupied_cells)
        );
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
            let number = b.bricks().position(|o| o == brick);
            assert_eq!(number.is_some(), visible, "brick {brick:?}");
            let (lo, hi) = m.ranges[i];
            if c.is_transparent_between(lo, hi) {
                assert!(!visible, "brick {brick:?} called transparent");
                skipped_by_range += 1;
            }
            if let Some(n) = number {
                let stored: Vec<u16> = slots(&b, n, &v, &c).iter().map(|v| v.alpha).collect();
                assert_eq!(stored, alphas);
                assert_eq!(slots(&lazy, n, &v, &c), slots(&b, n, &v, &c));
            }
        }
        // 5³ bricks; the 98 that touch the grid's faces hold no value
        // nearer the centre than 11.5, beyond 9 + 2·max|∇f| ≈ 11; the 27
        // inner ones all hold values within reach of 9.
        assert_eq!(skipped_by_range, 98);
        assert!(b.len() > 0);
    }
}
