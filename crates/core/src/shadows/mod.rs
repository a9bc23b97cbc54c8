//! Shadows: how much of the light reaches each point through the
//! classified volume in front of it.
//!
//! **What is computed.** The light is at infinity, in the direction `L`
//! (unit, world). The light reaching point `p` is the transmittance of the
//! classified volume along the ray from `p` towards the light, sampled as
//! the frame's view rays are, `s` world units apart (the step, or one
//! voxel where the step is shorter: [`shadow_step`]):
//!
//! ```text
//! T(p) = ∏ (1 − α_s(p + m·s·L)),  m = 1, 2, …  while p + m·s·L is in the volume
//! ```
//!
//! and the part of a step left from the last sample to the volume's
//! boundary counts as that fraction of a sample taken on the boundary,
//! `(1 − α_s)^fraction`, so that `T` does not jump from voxel to voxel
//! where material touches the face the light comes through.
//!
//! `α_s` is the voxels' classified opacity
//! ([`crate::transfer::classifier::Classifier::opacity_at`]) corrected for
//! a step of `s`, interpolated trilinearly: at the view rays' step, the
//! opacity they composite under pre-classification. A point does not shadow itself (`m` starts at 1),
//! outside the volume is empty, and the non-finite voxels rendered as empty
//! space are empty here too. Cropping and clip planes choose what the view
//! rays sample, not what is there: the material they cut away still casts
//! its shadow, as a lamp's light is blocked by what the camera does not
//! show.
//!
//! **How it shades.** `T` scales the diffuse and specular terms of the
//! paper's Phong model; the ambient term stands for light scattered in
//! from everywhere and is not shadowed:
//! `C = C_s·m·(k_a + T·(k_d·(N·L) + k_s·(N·H)^n))`
//! ([`crate::kernels::phong::Phong::shade_reached`]). Pre-classified
//! frames shade each voxel with its `T`; post-classified ones each sample
//! with the `T` at its position.
//!
//! **Two ways to get `T`.** The reference path marches every shadow ray as
//! written above ([`ShadowRay::transmittance`]) from every voxel that any
//! sample can see, in `f64`: exact, and `O(n⁴)`. The fast path keeps
//! every voxel's opacity per transfer function ([`opacities`]) and sweeps
//! a light volume through them across the grid once per light direction
//! ([`light_volume`]): each voxel's `T` from the slices before it on the
//! way to the light, its ray sampled where the march samples it for four
//! slices, `O(n³)`, and kept while neither changes (a light fixed in the
//! world, `--light`, is swept once for a whole orbit).
//!
//! **Ambient occlusion**, the other depth cue, is here too: the ambient
//! light reaching each point along short rays around it ([`ambient`]; the
//! fast path's [`ambient_volume`]).

pub mod ambient;
pub mod ambient_volume;
pub mod light_volume;
pub mod opacities;

/// The step of the shadow rays, in voxels, for view rays `step` voxels
/// apart: the same, but never less than a voxel. The light changes
/// little over a voxel, the opacities are corrected for the step, and
/// a shorter step would only multiply the fast path's samples (at step
/// 0.5 the sweep of a 257³ cloud took twice as long).
pub fn shadow_step(step: f64) -> f64 {
    step.max(1.0)
}

use crate::kernels::trilinear;
use glam::DVec3;
use rayon::prelude::*;

/// A shadow ray's sampling: where its samples fall in index space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowRay {
    /// From one sample to the next, in index space: `s·L / spacing`.
    step: DVec3,
    /// The volume's last voxel, `n − 1` per axis.
    last: DVec3,
}

impl ShadowRay {
    /// Rays towards `to_light` (world, any length) in a grid of `dims`
    /// voxels `spacing` apart, sampled `step_world` world units apart.
    pub fn new(to_light: DVec3, dims: [usize; 3], spacing: DVec3, step_world: f64) -> Self {
        ShadowRay {
            step: to_light.normalize() * step_world / spacing,
            last: DVec3::from_array(dims.map(|n| (n - 1) as f64)),
        }
    }

    /// `T(p)` from index-space point `from`, of the step-corrected opacity
    /// `alpha(p)` at index-space points: the product of `1 − α` over the
    /// samples between `from` and the volume's boundary, and for the part
    /// of a step left from the last of them to the boundary, that fraction
    /// of a sample at the boundary (so that `T` does not jump where the
    /// boundary crosses a sample).
    pub fn transmittance(&self, from: DVec3, alpha: impl Fn([f64; 3]) -> f64) -> f64 {
        // Steps from `from` to the boundary.
        let exit = (0..3)
            .map(|a| match self.step[a] {
                s if s > 0.0 => (self.last[a] - from[a]) / s,
                s if s < 0.0 => -from[a] / s,
                _ => f64::INFINITY,
            })
            .fold(f64::INFINITY, f64::min)
            .max(0.0);
        // A sample on the boundary lands a rounding error out as often as in.
        let whole = (exit + 1e-9).floor();
        let at = |m: f64| {
            (from + self.step * m)
                .clamp(DVec3::ZERO, self.last)
                .to_array()
        };
        let mut t = 1.0;
        for m in 1..=whole as usize {
            t *= 1.0 - alpha(at(m as f64));
            if t == 0.0 {
                return 0.0;
            }
        }
        let rest = (exit - whole).max(0.0);
        if rest > 0.0 {
            t *= (1.0 - alpha(at(exit))).max(0.0).powf(rest);
        }
        t
    }
}

/// The reference path's light reaching every voxel of a grid of `dims`
/// voxels whose step-corrected opacities are `alpha` (x fastest): each
/// voxel's shadow ray marched ([`ShadowRay::transmittance`]) through their
/// trilinear interpolation.
pub fn reference_light(alpha: &[f32], dims: [usize; 3], ray: &ShadowRay) -> Vec<f32> {
    let sample = |p: [f64; 3]| trilinear::reference(p, dims, 0.0, |v| alpha[v] as f64);
    march_every_voxel(alpha, dims, |from| ray.transmittance(from, sample))
}

/// `march(voxel)` for every voxel of a grid of `dims` voxels of opacities
/// `alpha` (x fastest), in parallel. A voxel whose every neighbour (the 26
/// around it and itself) is transparent gets 1 without a march: every cell
/// it is a corner of is transparent, so no composited sample sees its
/// colour.
fn march_every_voxel(
    alpha: &[f32],
    dims: [usize; 3],
    march: impl Fn(DVec3) -> f64 + Sync,
) -> Vec<f32> {
    let [nx, ny, nz] = dims;
    let slice = nx * ny;
    let opaque_near = |i: usize, j: usize, k: usize| {
        let around = |c: usize, n: usize| c.saturating_sub(1)..=(c + 1).min(n - 1);
        around(k, nz).any(|z| {
            around(j, ny).any(|y| around(i, nx).any(|x| alpha[x + nx * (y + ny * z)] > 0.0))
        })
    };
    let mut out = vec![1.0f32; alpha.len()];
    out.par_chunks_mut(slice).enumerate().for_each(|(k, out)| {
        for (n, t) in out.iter_mut().enumerate() {
            let (i, j) = (n % nx, n / nx);
            if opaque_near(i, j, k) {
                *t = march(DVec3::new(i as f64, j as f64, k as f64)) as f32;
            }
        }
    });
    out
}

/// The value at index-space point `p` (in `[0, n − 1]³`, clamped) of a
/// grid of `dims` voxels read by `at`, interpolated trilinearly: the fast
/// paths' light and ambient volumes, sampled where post-classified samples
/// fall.
#[inline]
pub(crate) fn sample_voxels(
    dims: [usize; 3],
    p: glam::Vec3,
    at: impl Fn([usize; 3]) -> f32,
) -> f32 {
    let last = dims.map(|n| n - 1);
    let c = std::array::from_fn::<_, 3, _>(|a| (p[a].max(0.0) as usize).min(last[a]));
    let f: [f32; 3] = std::array::from_fn(|a| (p[a] - c[a] as f32).clamp(0.0, 1.0));
    let next = |a: usize| (c[a] + 1).min(last[a]);
    let mut sum = 0.0;
    for (dz, wz) in [(c[2], 1.0 - f[2]), (next(2), f[2])] {
        for (dy, wy) in [(c[1], 1.0 - f[1]), (next(1), f[1])] {
            for (dx, wx) in [(c[0], 1.0 - f[0]), (next(0), f[0])] {
                sum += wx * wy * wz * at([dx, dy, dz]);
            }
        }
    }
    sum
}

#[cfg(test)]
mod tests;
