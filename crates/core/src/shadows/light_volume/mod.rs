//! The fast path's light volume: the light reaching every voxel
//! ([`super`]'s `T`), swept across the grid slice by slice from the light.
//!
//! **The sweep.** In index space the light's direction is `L / spacing`;
//! let `a` be the axis along which it is longest, and `d` that direction
//! scaled so that `d_a = ±1`: one slice across `a` towards the light.
//! Slices are taken in order from the light's side, and each voxel `v` of
//! a slice gets its light from the slices already done:
//!
//! ```text
//! T(v) = ∏ (1 − α_s(v + m·s·L)), m = 1 … K,  times  T(v + K·s·L)
//! ```
//!
//! the march's own first `K` samples (`s` the step the opacities are
//! corrected for, `K` the whole samples within `REACH` (4) slices), their
//! opacities interpolated trilinearly between the slices they fall
//! between, then the light the march would find from the `K`-th sample
//! on, interpolated trilinearly between the slices' (its samples are in
//! phase with `v`'s own). A voxel whose ray leaves the grid within
//! `EXIT` (8) slices, through a side or the light's face, is marched to the
//! face, its last fraction of a step included, as the reference marches.
//!
//! Where the light is along an axis of a grid of equal spacings and the
//! step is one voxel, the samples are voxels: the sweep equals the march
//! to rounding. Elsewhere the light read `K` samples on is interpolated
//! between voxels, which blurs it by a fraction of a voxel every `REACH`
//! slices, and where the light jumps from voxel to voxel (a binary
//! volume's surfaces) the interpolation misses the jump: see
//! `docs/options.md`, "Shadows", for what that costs against the march.
//!
//! **Cost.** The opacities are kept per classifier ([`VoxelOpacities`]),
//! so a sweep reads each voxel's with one multiplication; then per voxel
//! `K` samples of two bilinear interpolations each and one of the light:
//! `O(n³)`. Within a row, each sample is one pass along the run of voxels
//! that take it (the same offset from every voxel of the run, so the
//! passes vectorise); the slices keep a border of one voxel of zeros, so
//! that no pass tests its reads. Most of it is skipped (see `Slice` and
//! `Reach`): a sample is taken only over the voxels whose sample meets
//! material, the light at the last only where that light is not 1, and a
//! row asks once whether any of its samples can. Rows are done in
//! parallel, a group of slices at a time (`Sweep::group`). A row is the
//! same products in the same order on any thread: deterministic at any
//! thread count, and the same whether the rows are compiled for AVX2
//! (where the CPU has it: `Isa`) or the baseline. On the peers' 257³
//! cloud under the camera's key light, two threads (medians of 12, the
//! `sweep_bench` example): 225 ms in its first form (each voxel's samples
//! one at a time through checked reads, every voxel classified again),
//! 55 in the form that took every sample over every row, 36 in this one;
//! on their 50³ hydrogen orbital, 1.16 and 0.78 ms.
//! `T` is kept as a `u16` per voxel ([`BYTES_PER_VOXEL`]), in slice order;
//! the last slices' opacities and light are kept in `f32` while they are
//! read ([`LightVolume::ring_bytes`]), so that rounding does not
//! accumulate.

mod rows;

use super::opacities::{self, VoxelOpacities};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
pub(crate) use rows::Isa;
use rows::{Lit, Scratch, Slice, Sweep, UNIT};

/// Bytes per voxel of a [`LightVolume`].
pub const BYTES_PER_VOXEL: usize = size_of::<u16>();

/// The fewest voxels a thread takes of a slice at a time: a 50³ grid's
/// slices in two or three tasks each. 8192 (one task a slice) was a
/// quarter slower on the peers' 50³ grids.
const TASK: usize = 1024;

/// A task of a row of a group of slices: the slices back from its slice,
/// its place (`n`-th slice, row `ic`), its light's rows (`u16` out,
/// `f32` in the ring) and its shade.
type RowTask<'a> = (
    &'a [Option<&'a Slice>],
    usize,
    usize,
    ((&'a mut [u16], &'a mut [f32]), &'a mut (usize, usize)),
);

/// The most bytes of a [`RowTask`], counted by [`LightVolume::ring_bytes`].
const ROW_TASK_BYTES: usize = 80;
const _: () = assert!(size_of::<RowTask>() <= ROW_TASK_BYTES);

/// The light reaching every voxel of a grid, for one light direction and
/// one classification.
#[derive(Debug, Clone, PartialEq)]
pub struct LightVolume {
    dims: [usize; 3],
    /// Where voxel `(i, j, k)` is in `light`: `i·s₀ + j·s₁ + k·s₂` (slice
    /// order: the swept axis slowest).
    strides: [usize; 3],
    light: Vec<u16>,
}

impl LightVolume {
    /// Sweeps the light towards `to_light` (world, any length) through a
    /// grid of voxels `spacing` apart whose opacities are `opacities`,
    /// for shadow rays' samples a step apart (their
    /// [unit](VoxelOpacities::unit_world)), [arranging](VoxelOpacities::arrange)
    /// them in the sweep's order.
    pub fn sweep(spacing: DVec3, to_light: DVec3, opacities: &mut VoxelOpacities) -> Self {
        let mut light = LightVolume {
            dims: [0; 3],
            strides: [0; 3],
            light: Vec::new(),
        };
        light.resweep(spacing, to_light, opacities);
        light
    }

    /// [`Self::sweep`] into this light volume's memory (a new light
    /// volume's pages cost the sweep a tenth of its time on first touch).
    pub fn resweep(&mut self, spacing: DVec3, to_light: DVec3, opacities: &mut VoxelOpacities) {
        self.resweep_for(Isa::best(), spacing, to_light, opacities);
    }

    /// [`Self::resweep`], its rows compiled for `isa`.
    pub(crate) fn resweep_for(
        &mut self,
        isa: Isa,
        spacing: DVec3,
        to_light: DVec3,
        opacities: &mut VoxelOpacities,
    ) {
        let dims = opacities.dims();
        let step_world = opacities.unit_world();
        let towards = to_light.normalize() / spacing;
        let a = towards.abs().max_position();
        // The other two axes, in order: `b` runs fastest in a slice.
        let (b, c) = opacities::across(a);
        // One slice towards the light, in index space (`d[a] = ±1`), and
        // the shadow ray's samples per slice.
        let length = 1.0 / towards[a].abs();
        let d = towards * length;
        let sweep = Sweep::new([dims[b], dims[c]], [d[b], d[c]], length / step_world);
        opacities.arrange(a);
        let opacities = &*opacities;
        // Where the opacities' voxel (`s`, `ib`, `ic`) is: `ib` strides
        // along a row, by one.
        let from = opacities.strides();
        debug_assert_eq!(from[b], 1);
        let [nb, nc] = sweep.n;
        let plane = nb * nc;
        let mut strides = [0; 3];
        strides[b] = 1;
        strides[c] = nb;
        strides[a] = plane;
        // The slices in order from the light's side.
        let slices: Vec<usize> = if d[a] > 0.0 {
            (0..dims[a]).rev().collect()
        } else {
            (0..dims[a]).collect()
        };
        // Rows a task: at least `TASK` voxels.
        let min_rows = (TASK / nb.max(1)).max(1);
        let ring_size = sweep.ring;
        let mut ring: Vec<Slice> = (0..ring_size).map(|_| Slice::new(sweep.n)).collect();
        let mut light = std::mem::take(&mut self.light);
        light.resize(plane * dims[a], 0);
        let mut planes: Vec<Option<&mut [u16]>> = light.chunks_mut(plane).map(Some).collect();
        let pb = nb + 2;
        // The slices a group at a time: a slice reads the light of none of
        // the `group` before it (see `Sweep::group`), so a group's rows
        // are one parallel loop.
        for group in (0..slices.len()).collect::<Vec<_>>().chunks(sweep.group) {
            // The group's opacities first: the samples of its slices and
            // those after read them.
            let mut rows = Vec::with_capacity(group.len() * nc);
            for (slot, slice) in ring.iter_mut().enumerate() {
                let Some(&n) = group.iter().find(|&&n| n % ring_size == slot) else {
                    continue;
                };
                let Slice {
                    alpha, material, ..
                } = slice;
                let slice_rows = alpha[pb..].chunks_mut(pb).zip(material.iter_mut());
                rows.extend((slice_rows.enumerate()).map(|(ic, row)| (slices[n], ic, row)));
            }
            (rows.par_iter_mut().with_min_len(min_rows)).for_each(|(s, ic, (row, span))| {
                // A row of the arranged opacities is contiguous.
                let first = *s * from[a] + *ic * from[c];
                Slice::read_row(&opacities.values()[first..first + nb], row, span);
            });
            drop(rows);
            for &n in group {
                let slice = &mut ring[n % ring_size];
                Slice::count_rows(&slice.material, &mut slice.material_rows);
            }
            // Their light: out of the ring while it is written.
            let mut lit: Vec<Lit> = (group.iter())
                .map(|&n| {
                    let slice = &mut ring[n % ring_size];
                    Lit {
                        n,
                        light: std::mem::take(&mut slice.light),
                        shade: std::mem::take(&mut slice.shade),
                    }
                })
                .collect();
            // The slice `k` back from each: past the first, outside the grid.
            let backs: Vec<Vec<Option<&Slice>>> = (group.iter())
                .map(|&n| {
                    (0..ring_size)
                        .map(|k| (k <= n).then(|| &ring[(n + ring_size - k) % ring_size]))
                        .collect()
                })
                .collect();
            let mut rows: Vec<RowTask> = Vec::with_capacity(group.len() * nc);
            for (back, Lit { n, light, shade }) in backs.iter().zip(&mut lit) {
                let out = planes[slices[*n]].take().expect("each slice once");
                let slice_rows = (out.chunks_mut(nb))
                    .zip(light[pb..].chunks_mut(pb))
                    .zip(shade.iter_mut());
                rows.extend((slice_rows.enumerate()).map(|(ic, row)| (&back[..], *n, ic, row)));
            }
            (rows.par_iter_mut().with_min_len(min_rows)).for_each_init(
                Scratch::default,
                |scratch, (back, n, ic, ((out, t_row), shade))| {
                    let t = &mut t_row[1..=nb];
                    sweep.row(isa, [*ic, *n], back, (t, shade), out, scratch);
                },
            );
            drop(rows);
            drop(backs);
            for Lit { n, light, shade } in lit {
                let slice = &mut ring[n % ring_size];
                Slice::count_rows(&shade, &mut slice.shade_rows);
                slice.light = light;
                slice.shade = shade;
            }
        }
        drop(planes);
        *self = LightVolume {
            dims,
            strides,
            light,
        };
    }

    /// The most bytes a sweep of a grid of `dims` voxels holds besides
    /// the light volume, for shadow rays `step` voxels apart (voxels of
    /// the shortest spacing): its ring of slices.
    pub fn ring_bytes(dims: [usize; 3], step: f64) -> usize {
        let [x, y, z] = dims;
        let plane = ((x + 2) * (y + 2))
            .max((y + 2) * (z + 2))
            .max((x + 2) * (z + 2));
        let rows = x.max(y).max(z);
        // A slice is at least a voxel of the shortest spacing long.
        let ring = Sweep::ring_size(1.0 / step);
        // Per row of a slice: its two spans and two counts, and while a
        // group is done (no more slices than the ring) a task of a few
        // references.
        let row = 2 * size_of::<(usize, usize)>() + 2 * size_of::<u32>() + ROW_TASK_BYTES;
        // And a reference to each slice of the light volume.
        ring * (plane * 2 * size_of::<f32>() + rows * row) + rows * size_of::<&mut [u16]>()
    }

    /// The grid's size, in voxels.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.light.len() * BYTES_PER_VOXEL
    }

    /// The light reaching voxel `(i, j, k)`, in [0, 1].
    #[inline]
    pub fn at(&self, [i, j, k]: [usize; 3]) -> f32 {
        let [si, sj, sk] = self.strides;
        f32::from(self.light[i * si + j * sj + k * sk]) * (1.0 / UNIT)
    }

    /// The light reaching index-space point `p` (in `[0, n − 1]³`),
    /// interpolated trilinearly between the voxels'.
    #[inline]
    pub fn sample(&self, p: Vec3) -> f32 {
        super::sample_voxels(self.dims, p, |v| self.at(v))
    }
}
