//! Ambient occlusion: how much of the light from everywhere reaches each
//! point through the classified volume around it.
//!
//! **What is computed.** The ambient term of the paper's Phong model
//! stands for light scattered in from every direction. Ambient occlusion
//! scales it by how much of that light reaches the point through the
//! classified volume around it (Zhukov et al. 1998's obscurance; for
//! volumes, Hernell et al. 2010's local ambient occlusion): a weighted
//! mean of the transmittance along a fixed set of short rays,
//!
//! ```text
//! A(v) = Σ_d w_d·T_d / Σ_d w_d,   T_d = ∏ (1 − α_d(v + m·d)),  m = 1 … n_d
//! ```
//!
//! over the 26 directions `d` from a voxel to its neighbours (in index
//! space: `d ∈ {−1, 0, 1}³ \ 0`), each ray `n_d` steps of `d` long, the
//! whole number of steps nearest the radius `R` (in voxels of the smallest
//! spacing, as the step is; at least one step). `α_d` is the voxels'
//! classified opacity corrected for one step of `d` (`|d·spacing|` world
//! units, [`correct_opacity`]), interpolated trilinearly, as the shadow
//! rays' is ([`super`]). A point does not occlude itself (`m` starts at 1),
//! and samples outside the grid are empty: the volume's faces let the
//! light in.
//!
//! **The hemisphere a surface faces.** A surface is lit by the sky on its
//! open side, not by the material behind it: the weights are the cosines
//! `w_d = max(0, d̂·N̂)` of the rays with the way out of the material, `N =
//! −∇α` (world; the central differences of the voxels' opacities, one-sided
//! at the grid's faces), as for a Lambertian surface under a uniform sky.
//! So a flat open surface gets `A = 1`, a crease or a hollow less. Where
//! the opacity does not change (`∇α = 0`: inside a uniform medium, in
//! empty space) every ray weighs alike, `w_d = 1`.
//!
//! `A` is found at the voxels and interpolated trilinearly to the samples
//! between them, as their gradients are: post-classified samples read it
//! so. The directions are the lattice's, not spread evenly over the
//! sphere: from a voxel their samples are voxels, so the fast path's
//! `AmbientVolume` gets each
//! voxel's `A` as the reference marches it (to rounding), with no
//! interpolation error.
//!
//! **How it shades.** `A` scales the ambient term:
//! `C = C_s·m·(A·k_a + T·(k_d·(N·L) + k_s·(N·H)^n))`
//! ([`crate::kernels::phong::Phong::shade_reached`]), and where the frame
//! is unlit, the material colour itself (the emission is ambient light:
//! Hernell's unshaded local ambient occlusion). It does not depend on the
//! view or the light, so the fast path computes it once per transfer
//! function and radius.

use crate::kernels::trilinear;
use crate::transfer::classifier::correct_opacity;
use glam::DVec3;

/// The radius `--ambient-occlusion` takes without one, in voxels.
pub const DEFAULT_RADIUS: f64 = 8.0;

/// The radii allowed, in voxels: at least a voxel, and short enough that
/// the fast path's slices in reach stay few (`2·R + 1` of them).
pub const RADII: std::ops::RangeInclusive<f64> = 1.0..=32.0;

/// One ray of the fixed set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction {
    /// One step, in index space: a neighbour's offset.
    pub step: [isize; 3],
    /// Its samples, `n_d`.
    pub steps: usize,
    /// One step's length in voxels of the smallest spacing: the opacity
    /// correction's step.
    pub length: f32,
    /// The unit vector along the ray in world space, for its weight.
    pub world: DVec3,
}

/// The fixed set of rays of ambient occlusion of a radius, in a grid of
/// a spacing.
#[derive(Debug, Clone, PartialEq)]
pub struct AmbientRays {
    directions: Vec<Direction>,
    spacing: DVec3,
}

impl AmbientRays {
    /// The 26 rays of `radius` voxels (of the smallest spacing) in a grid
    /// of `spacing`.
    pub fn new(radius: f64, spacing: DVec3) -> Self {
        let voxel = spacing.min_element();
        let mut directions = Vec::with_capacity(26);
        for z in -1..=1isize {
            for y in -1..=1isize {
                for x in -1..=1isize {
                    if (x, y, z) == (0, 0, 0) {
                        continue;
                    }
                    let world = DVec3::new(x as f64, y as f64, z as f64) * spacing;
                    let length = world.length() / voxel;
                    directions.push(Direction {
                        step: [x, y, z],
                        steps: ((radius / length).round() as usize).max(1),
                        length: length as f32,
                        world: world.normalize(),
                    });
                }
            }
        }
        AmbientRays {
            directions,
            spacing,
        }
    }

    /// The rays, 26.
    pub fn directions(&self) -> &[Direction] {
        &self.directions
    }

    /// The distinct step lengths of the rays, in order of first use.
    pub fn lengths(&self) -> Vec<f32> {
        let mut lengths: Vec<f32> = Vec::new();
        for d in &self.directions {
            if !lengths.contains(&d.length) {
                lengths.push(d.length);
            }
        }
        lengths
    }

    /// How far the rays reach along each axis, in voxels.
    pub fn reach(&self) -> [usize; 3] {
        std::array::from_fn(|a| {
            (self.directions.iter())
                .map(|d| d.steps * d.step[a].unsigned_abs())
                .max()
                .unwrap_or(0)
        })
    }

    /// The grid's spacing the rays were made for.
    pub fn spacing(&self) -> DVec3 {
        self.spacing
    }

    /// The weight of each ray at a voxel whose way out of the material is
    /// `outward` (world, any length; zero: none): the cosines of the rays
    /// with it, not below 0, or all 1 where it is zero.
    pub fn weights(&self, outward: DVec3) -> impl Iterator<Item = f64> + '_ {
        let n = outward.normalize_or_zero();
        self.directions.iter().map(move |d| match n == DVec3::ZERO {
            true => 1.0,
            false => d.world.dot(n).max(0.0),
        })
    }

    /// `A` at voxel `v` of a grid of `dims` voxels, of the opacity
    /// `alpha(q, length)` at index-space points `q` corrected for a step of
    /// `length` voxels, and the weights of [`Self::weights`] for the way
    /// out of the material `outward`: the weighted mean over the rays of
    /// the product of `1 − α` along each (samples outside the grid are
    /// empty).
    pub fn occlusion(
        &self,
        v: [usize; 3],
        dims: [usize; 3],
        outward: DVec3,
        alpha: impl Fn([f64; 3], f32) -> f64,
    ) -> f64 {
        let from = DVec3::from_array(v.map(|c| c as f64));
        let last = DVec3::from_array(dims.map(|n| (n - 1) as f64));
        let (mut sum, mut weights) = (0.0, 0.0);
        for (d, w) in self.directions.iter().zip(self.weights(outward)) {
            if w == 0.0 {
                continue;
            }
            let step = DVec3::from_array(d.step.map(|s| s as f64));
            let mut t = 1.0;
            for m in 1..=d.steps {
                let q = from + step * m as f64;
                if q.cmplt(DVec3::ZERO).any() || q.cmpgt(last).any() {
                    break;
                }
                t *= 1.0 - alpha(q.to_array(), d.length);
                if t == 0.0 {
                    break;
                }
            }
            sum += w * t;
            weights += w;
        }
        sum / weights
    }
}

/// The way out of the material at voxel `(i, j, k)` of a grid of `dims`
/// voxels `spacing` apart whose opacities are `alpha(i, j, k)`: `−∇α`
/// (world), by central differences, one-sided at the grid's faces.
#[inline]
pub fn outward(
    [i, j, k]: [usize; 3],
    dims: [usize; 3],
    spacing: [f32; 3],
    alpha: impl Fn(usize, usize, usize) -> f32,
) -> [f32; 3] {
    let v = [i, j, k];
    std::array::from_fn(|a| {
        let (lo, hi) = (v[a].saturating_sub(1), (v[a] + 1).min(dims[a] - 1));
        if lo == hi {
            return 0.0;
        }
        let at = |c: usize| {
            let mut q = v;
            q[a] = c;
            alpha(q[0], q[1], q[2])
        };
        (at(lo) - at(hi)) / ((hi - lo) as f32 * spacing[a])
    })
}

/// The opacity of `unit` (the opacity of one voxel's length) at
/// index-space point `q`, corrected for a step of `length` voxels at each
/// voxel and interpolated trilinearly: the reference's tap.
pub fn reference_tap(unit: &[f32], dims: [usize; 3], q: [f64; 3], length: f32) -> f64 {
    trilinear::reference(q, dims, 0.0, |i| correct_opacity(unit[i], length) as f64)
}

/// The reference path's ambient occlusion of every voxel of a grid of
/// `dims` voxels whose unit opacities are `unit` (x fastest): each voxel's
/// rays marched ([`AmbientRays::occlusion`]). A voxel whose every
/// neighbour is transparent gets 1 without a march, as in
/// [`super::reference_light`].
pub fn reference_occlusion(unit: &[f32], dims: [usize; 3], rays: &AmbientRays) -> Vec<f32> {
    let [nx, ny, _] = dims;
    let spacing32 = rays.spacing.as_vec3().to_array();
    let tap = |q: [f64; 3], length: f32| reference_tap(unit, dims, q, length);
    super::march_every_voxel(unit, dims, |from| {
        let v = from.to_array().map(|c| c as usize);
        let n = outward(v, dims, spacing32, |i, j, k| unit[i + nx * (j + ny * k)]);
        let n = glam::Vec3::from(n).as_dvec3();
        rays.occlusion(v, dims, n, tap)
    })
}
