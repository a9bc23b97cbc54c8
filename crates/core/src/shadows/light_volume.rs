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
//! **Cost.** One opacity per voxel (the classifier, with the gradient
//! only where it needs one), then per voxel `K` samples of two bilinear
//! interpolations each and one of the light: `O(n³)`, rows of each slice
//! in parallel, deterministic at any thread count. `T` is kept as a `u16`
//! per voxel ([`BYTES_PER_VOXEL`]), in slice order; the last slices'
//! opacities and light are kept in `f32` while they are read, so that
//! rounding does not accumulate.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Bytes per voxel of a [`LightVolume`].
pub const BYTES_PER_VOXEL: usize = size_of::<u16>();

/// A row's span of no voxels.
const NONE: (usize, usize) = (usize::MAX, 0);

/// `T` is stored in units of `1/UNIT`.
const UNIT: f32 = u16::MAX as f32;

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
    /// grid of `dims` voxels `spacing` apart whose voxel `(i, j, k)` has
    /// step-corrected opacity `alpha(i, j, k)`, corrected for a step of
    /// `step_world` world units.
    pub fn sweep(
        dims: [usize; 3],
        spacing: DVec3,
        to_light: DVec3,
        step_world: f64,
        alpha: impl Fn(usize, usize, usize) -> f32 + Sync,
    ) -> Self {
        let towards = to_light.normalize() / spacing;
        let a = towards.abs().max_position();
        // The other two axes, in order: `b` runs fastest in a slice.
        let (b, c) = match a {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        // One slice towards the light, in index space (`d[a] = ±1`), and
        // the shadow ray's samples per slice.
        let length = 1.0 / towards[a].abs();
        let d = towards * length;
        let per_slice = length / step_world;
        let (nb, nc) = (dims[b], dims[c]);
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
        let voxel = |s: usize, ib: usize, ic: usize| {
            let mut v = [0; 3];
            (v[a], v[b], v[c]) = (s, ib, ic);
            v
        };
        // Slices a segment reaches back: at least `REACH`, and far enough
        // for its last sample to lie beyond the slice behind (where the
        // light is known) whatever the step.
        let reach_most = REACH.max((1.0 / per_slice).ceil() as usize + 1);
        // Rays that leave the grid within this many slices are marched to
        // its face (at least the segment's reach: the slices a segment
        // reads exist).
        let exit_slices = EXIT.max(reach_most);
        let ring_size = exit_slices + 2;
        // The last `ring_size` slices' opacities and light, by slice
        // number modulo `ring_size`.
        let ring = |_| vec![0.0f32; plane];
        let mut alphas: Vec<Vec<f32>> = (0..ring_size).map(ring).collect();
        let mut lights: Vec<Vec<f32>> = (0..ring_size).map(ring).collect();
        // Per slice of the ring and row, the voxels of the row that are
        // not transparent, `lo..=hi` (`lo > hi`: none): most voxels' rays
        // cross nothing near them, and skip their samples.
        let mut spans: Vec<Vec<(usize, usize)>> = (0..ring_size).map(|_| vec![NONE; nc]).collect();
        // How far across the slices a ray's samples reach, within the
        // ring: rows `ic + c_reach.0 ..= ic + c_reach.1` and columns
        // likewise (one more for the interpolation's far corner).
        let reach_across = |d: f64| {
            let far = ring_size as f64 * d;
            (
                far.min(0.0).floor() as isize - 1,
                far.max(0.0).ceil() as isize + 1,
            )
        };
        let (b_reach, c_reach) = (reach_across(d[b]), reach_across(d[c]));
        let mut light = vec![0u16; plane * dims[a]];
        let across = [d[b], d[c]];
        let segment = Segment::new(reach_most, per_slice, across, false);
        let to_exit = Segment::new(exit_slices + 1, per_slice, across, true);
        // Slices from voxel `i` of `n` to where its ray leaves the grid
        // across one axis, at `d` voxels a slice.
        let exit = |i: usize, n: usize, d: f64| {
            if d > 0.0 {
                (n - 1 - i) as f64 / d
            } else if d < 0.0 {
                i as f64 / -d
            } else {
                f64::INFINITY
            }
        };
        for (n, &s) in slices.iter().enumerate() {
            let here = n % ring_size;
            // The slice's opacities first: the samples between it and the
            // slices behind read them.
            (alphas[here]
                .par_chunks_mut(nb)
                .zip(spans[here].par_iter_mut())
                .enumerate())
            .for_each(|(ic, (row, span))| {
                *span = NONE;
                for (ib, alpha_v) in row.iter_mut().enumerate() {
                    let v = voxel(s, ib, ic);
                    *alpha_v = alpha(v[0], v[1], v[2]);
                    if *alpha_v > 0.0 {
                        *span = (span.0.min(ib), ib);
                    }
                }
            });
            // Slice `k` back from this one, in the rings: past the first
            // slice, outside the grid.
            let back = |k: usize| (k <= n).then(|| (n - k) % ring_size);
            let slice_alpha = |k: usize| back(k).map(|k| alphas[k].as_slice());
            let mut t_here = std::mem::take(&mut lights[here]);
            let slice_light = |k: usize| back(k).map(|k| lights[k].as_slice());
            (light[s * plane..(s + 1) * plane].par_chunks_mut(nb))
                .zip(t_here.par_chunks_mut(nb))
                .enumerate()
                .for_each(|(ic, (out, t_row))| {
                    let exit_c = exit(ic, nc, d[c]).min(n as f64);
                    // The columns of the rows and slices this row's rays
                    // sample that are not transparent.
                    let rows = (ic as isize + c_reach.0).max(0) as usize
                        ..=(ic as isize + c_reach.1).clamp(0, nc as isize - 1) as usize;
                    let opaque = (0..ring_size.min(n + 1))
                        .flat_map(|k| rows.clone().map(move |r| (k, r)))
                        .map(|(k, r)| spans[(n - k) % ring_size][r])
                        .fold(NONE, |(lo, hi), (a, b)| (lo.min(a), hi.max(b)));
                    for (ib, (o, t_out)) in out.iter_mut().zip(t_row.iter_mut()).enumerate() {
                        let clear = opaque.0 > opaque.1
                            || ib as isize + b_reach.1 < opaque.0 as isize
                            || ib as isize + b_reach.0 > opaque.1 as isize;
                        // A ray that leaves the grid within `EXIT` slices
                        // is marched to there, as the reference does.
                        let exit_f = exit(ib, nb, d[b]).min(exit_c);
                        let (segment, exit) = if exit_f < exit_slices as f64 {
                            (&to_exit, Some((exit_f, Tap::at(exit_f, across))))
                        } else {
                            (&segment, None)
                        };
                        let t = match (clear, exit) {
                            (true, Some(_)) => 1.0,
                            // Nothing absorbs along the segment: the light
                            // `reach` slices back, one interpolation.
                            (true, None) => (segment.far)
                                .bilinear(ib, ic, nb, nc, slice_light(reach_most).unwrap_or(&[]))
                                .unwrap_or(1.0),
                            (false, _) => {
                                segment.light([ib, ic], [nb, nc], &slice_alpha, &slice_light, exit)
                            }
                        };
                        *t_out = t;
                        // `+ 0.5` and truncation: rounding, without a call to `roundf`.
                        *o = (t.clamp(0.0, 1.0) * UNIT + 0.5) as u16;
                    }
                });
            lights[here] = t_here;
        }
        LightVolume {
            dims,
            strides,
            light,
        }
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

/// Slices a voxel's shadow ray is marched through before it takes the
/// light found there: interpolating that light blurs it (by a variance of
/// `w(1 − w)` voxels² per interpolation, `w` the crossing's fraction of a
/// voxel), so each voxel marches `REACH` slices and the blur is that of
/// one interpolation every `REACH` slices.
const REACH: usize = 4;

/// A voxel whose shadow ray leaves the grid within this many slices is
/// marched to the grid's face, sample by sample as the reference: near a
/// face the light changes abruptly from voxel to voxel (the march counts
/// whole samples before the face) and interpolating it there was off by
/// 0.03 on blobs that touch the faces.
const EXIT: usize = 8;

/// A voxel's shadow ray up to `reach` slices long, as the march takes
/// it: the samples one step apart from the voxel, their opacity
/// interpolated trilinearly between the slices they fall between; then,
/// from the last of them, the light there, interpolated trilinearly
/// between the slices' (the light a march from there would find, its
/// samples a step apart from there: in phase with the voxel's own).
#[derive(Debug, Clone)]
struct Segment {
    /// The samples: each stands for `weight` of the march's; the last is
    /// where the light is taken, unless the ray leaves the grid before it.
    taps: Vec<Tap>,
    weight: f32,
    /// Samples per slice.
    per_slice: f64,
    /// Where the segment's ray crosses the slice `reach` back.
    far: Tap,
}

/// A point on every voxel's shadow ray of a slice, at the same offset from
/// each: `slices + w` slices back (`w` in [0, 1)), and across the slice
/// `b + wb` and `c + wc` voxels from the voxel.
#[derive(Debug, Clone, Copy)]
struct Tap {
    slices: usize,
    w: f32,
    b: isize,
    wb: f32,
    c: isize,
    wc: f32,
}

/// The most samples a segment takes. A segment is longer than this many
/// steps only on a grid whose spacings differ many times over with a
/// small step (5 mm slices of 0.5 mm pixels at step 0.1 take 100 a
/// slice): there the samples spread evenly, each standing for several.
const MAX_SAMPLES: usize = 64;

impl Tap {
    /// The point `f` slices back along `d` (across the slice: `[d_b, d_c]`
    /// per slice).
    fn at(f: f64, d: [f64; 2]) -> Self {
        let split = |x: f64| {
            let floor = x.floor();
            (floor as isize, (x - floor) as f32)
        };
        let (slices, w) = split(f);
        let (b, wb) = split(f * d[0]);
        let (c, wc) = split(f * d[1]);
        Tap {
            slices: slices as usize,
            w,
            b,
            wb,
            c,
            wc,
        }
    }

    /// The corners around the point from voxel `i` on an axis of `n`
    /// voxels (`offset`, `w`): `None` outside it.
    #[inline(always)]
    fn corners(i: usize, offset: isize, w: f32, n: usize) -> Option<(usize, usize, f32)> {
        let lo = i as isize + offset;
        let hi = lo + isize::from(w > 0.0);
        (lo >= 0 && (hi as usize) < n).then_some((lo as usize, hi as usize, w))
    }

    /// The bilinear interpolation of `plane` (rows `nb` long, `nc` of
    /// them) at the point from voxel (`ib`, `ic`); `None` outside it.
    #[inline(always)]
    fn bilinear(&self, ib: usize, ic: usize, nb: usize, nc: usize, plane: &[f32]) -> Option<f32> {
        let (b0, b1, wb) = Self::corners(ib, self.b, self.wb, nb)?;
        let (c0, c1, wc) = Self::corners(ic, self.c, self.wc, nc)?;
        let row = |c: usize| plane[c * nb + b0] * (1.0 - wb) + plane[c * nb + b1] * wb;
        Some(row(c0) * (1.0 - wc) + row(c1) * wc)
    }
}

impl Segment {
    /// Up to `reach` slices of `per_slice` samples each, the slices'
    /// offsets across `d` per slice; `to_exit`: every sample (the ray
    /// leaves the grid before the last), else at most [`MAX_SAMPLES`].
    fn new(reach: usize, per_slice: f64, d: [f64; 2], to_exit: bool) -> Self {
        let samples = (reach as f64 * per_slice + 1e-9).floor() as usize;
        let count = if to_exit {
            samples
        } else {
            samples.min(MAX_SAMPLES)
        };
        let spread = samples as f64 / count.max(1) as f64;
        Segment {
            taps: (1..=count)
                .map(|m| Tap::at(m as f64 * spread / per_slice, d))
                .collect(),
            weight: spread as f32,
            per_slice,
            far: Tap::at(reach as f64, d),
        }
    }

    /// The light reaching voxel (`ib`, `ic`) of a slice (of `nb` by `nc`
    /// voxels), from the opacities `slice_alpha(k)` and the light
    /// `slice_light(k)` of the slices `k` back; `exit`: where its ray
    /// leaves the grid, in slices, and the point there on the face, when
    /// it does within the segment (marched to the face, no light read).
    #[inline]
    fn light<'s>(
        &self,
        [ib, ic]: [usize; 2],
        [nb, nc]: [usize; 2],
        slice_alpha: &impl Fn(usize) -> Option<&'s [f32]>,
        slice_light: &impl Fn(usize) -> Option<&'s [f32]>,
        exit: Option<(f64, Tap)>,
    ) -> f32 {
        // The trilinear interpolation at `tap` of the slices `plane(k)`.
        let at = |tap: &Tap, plane: &dyn Fn(usize) -> Option<&'s [f32]>| {
            let near = tap.bilinear(ib, ic, nb, nc, plane(tap.slices)?)?;
            Some(if tap.w > 0.0 {
                let far = tap.bilinear(ib, ic, nb, nc, plane(tap.slices + 1)?)?;
                near * (1.0 - tap.w) + far * tap.w
            } else {
                near
            })
        };
        let mut keep = 1.0f32;
        if let Some((exit_f, face)) = exit {
            // The samples before the face, then the fraction of a step
            // left to it, on it (as the reference's march).
            let whole = (exit_f * self.per_slice + 1e-9).floor();
            for tap in self.taps.iter().take(whole as usize) {
                keep *= 1.0 - at(tap, slice_alpha).unwrap_or(0.0);
            }
            let rest = (exit_f * self.per_slice - whole).max(0.0) as f32;
            if rest > 0.0 {
                let alpha = at(&face, slice_alpha).unwrap_or(0.0);
                keep *= (1.0 - alpha).max(0.0).powf(rest);
            }
            return keep;
        }
        let Some(last) = self.taps.last() else {
            return 1.0;
        };
        for tap in &self.taps {
            keep *= 1.0 - at(tap, slice_alpha).unwrap_or(0.0);
        }
        if self.weight != 1.0 {
            keep = keep.max(0.0).powf(self.weight);
        }
        keep * at(last, slice_light).unwrap_or(1.0)
    }
}
