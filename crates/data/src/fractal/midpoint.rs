//! 3-D midpoint displacement, in place on the final `f32` grid, in
//! parallel and independent of the thread count.
//!
//! The grid has `n = 2^k + 1` points per side. Level 0 sets the 8 corners
//! to `σ·N(0, 1)`. Level `l = 1..=k` halves the spacing from `s = 2h` to
//! `h = (n − 1)/2^l`: every point with at least one coordinate an odd
//! multiple of `h` is new, and is the mean of the corners of the cell, face
//! or edge it is the centre of (8 for three odd coordinates, 4 for two, 2
//! for one), plus `Δ·N(0, 1)` with the sub-pass's `Δ` from
//! [`super::scaling`]. With random additions the new points get the plain
//! mean and then every point of the level's grid gets `Δ_add·N(0, 1)`.
//!
//! This stencil is trilinear refinement: without displacements it
//! reproduces the trilinear interpolant of the corners exactly, and every
//! parent of a point lies at the same distance. The 3-D analogue of Saupe's
//! diamond-square stencil (face centres also averaging the two cube centres
//! beside them, edge midpoints the four face centres around them) measured
//! Hurst exponents further below `4 − D` (`docs/fractal.md`).
//!
//! New points read only old points (those on the spacing-`s` grid), never
//! each other, so a level's order of work cannot change its values. Each
//! level runs in two phases over z-planes:
//! - planes with `z` a multiple of `s`: their new points (x- and y-edge
//!   midpoints, xy-face centres) read old points of the same plane;
//! - planes with `z` an odd multiple of `h`: their new points (z-edge
//!   midpoints, xz- and yz-face centres, cube centres) read the old points
//!   of the planes `z ± h`, which the first phase left unchanged.
//!
//! Rayon hands out whole planes, each written by one task, and the random
//! number of a point comes from its identity ([`super::noise`]), so 1, 2 or
//! 64 threads give the same bytes. Means are summed in `f64` (exact for up
//! to 8 `f32` values of moderate spread) and rounded to `f32` once.

use rayon::prelude::*;

use super::noise::{Stream, StreamKey, level_index};
use super::scaling::{LevelScales, level_scales};

/// What the refinement needs besides the grid.
#[derive(Debug, Clone, Copy)]
pub(super) struct Refinement {
    /// Standard deviation of the corners.
    pub sigma: f64,
    /// Hurst exponent `H = 4 − D`.
    pub hurst: f64,
    /// Seed of every random number.
    pub seed: u64,
    /// Voss's successive random additions instead of displacing new points.
    pub random_additions: bool,
}

/// Fills `data` (`n³` values, x fastest, `n = 2^k + 1`, all zero) with the
/// fractal field.
pub(super) fn fill(data: &mut [f32], n: usize, r: &Refinement) {
    debug_assert!(n >= 3 && (n - 1).is_power_of_two() && data.len() == n * n * n);
    let last = n - 1;
    let corners = StreamKey::new(r.seed, 0, Stream::Displacement);
    for z in [0, last] {
        for y in [0, last] {
            for x in [0, last] {
                let z0 = corners.normal(level_index(0, last, x, y, z));
                data[x + n * (y + n * z)] = (r.sigma * z0) as f32;
            }
        }
    }
    let levels = last.trailing_zeros();
    for level in 1..=levels {
        refine(data, n, level, r);
    }
}

/// One level: interpolation (with displacements unless random additions),
/// then the additions if asked for.
fn refine(data: &mut [f32], n: usize, level: u32, r: &Refinement) {
    let h = (n - 1) >> level;
    let s = 2 * h;
    let scales = level_scales(r.sigma, r.hurst, level);
    let pass = Pass {
        n,
        level,
        h,
        key: StreamKey::new(r.seed, level, Stream::Displacement),
        scales: if r.random_additions {
            LevelScales {
                cube_centre: 0.0,
                face_centre: 0.0,
                edge_midpoint: 0.0,
                addition: scales.addition,
            }
        } else {
            scales
        },
    };

    // Phase 1: planes z ≡ 0 (mod s), each reading only itself.
    data.par_chunks_mut(n * n)
        .enumerate()
        .filter(|(z, _)| z.is_multiple_of(s))
        .for_each(|(z, plane)| pass.old_plane(plane, z));

    // Phase 2: planes z ≡ h (mod s), reading the old points of z ± h:
    // old plane m is z = m·s, so new plane z = (2m + 1)·h lies between old
    // planes m and m + 1.
    let mut old: Vec<&[f32]> = Vec::with_capacity(n / s + 1);
    let mut new: Vec<(usize, &mut [f32])> = Vec::with_capacity(n / s);
    for (z, plane) in data.chunks_mut(n * n).enumerate() {
        if z.is_multiple_of(s) {
            old.push(plane);
        } else if z.is_multiple_of(h) {
            new.push((z, plane));
        }
    }
    let old = &old;
    new.into_par_iter().for_each(|(z, plane)| {
        let m = z / s;
        pass.new_plane(plane, z, old[m], old[m + 1]);
    });

    if r.random_additions {
        let key = StreamKey::new(r.seed, level, Stream::Addition);
        let delta = scales.addition;
        data.par_chunks_mut(n * n)
            .enumerate()
            .filter(|(z, _)| z.is_multiple_of(h))
            .for_each(|(z, plane)| {
                for y in (0..n).step_by(h) {
                    for x in (0..n).step_by(h) {
                        let i = x + n * y;
                        let add = delta * key.normal(level_index(level, h, x, y, z));
                        plane[i] = (f64::from(plane[i]) + add) as f32;
                    }
                }
            });
    }
}

/// One level's geometry, random stream and displacement sizes.
struct Pass {
    n: usize,
    level: u32,
    h: usize,
    key: StreamKey,
    scales: LevelScales,
}

impl Pass {
    /// `mean + Δ·N(0, 1)` for the new point `(x, y, z)`, rounded to `f32`.
    fn displaced(&self, mean: f64, delta: f64, x: usize, y: usize, z: usize) -> f32 {
        if delta == 0.0 {
            return mean as f32;
        }
        let index = level_index(self.level, self.h, x, y, z);
        (mean + delta * self.key.normal(index)) as f32
    }

    /// New points of a plane whose `z` is on the old grid: x-edge midpoints
    /// in old rows, y-edge midpoints and xy-face centres in new rows.
    fn old_plane(&self, p: &mut [f32], z: usize) {
        let (n, h, s) = (self.n, self.h, 2 * self.h);
        let at = |p: &[f32], x: usize, y: usize| f64::from(p[x + n * y]);
        for y in (0..n).step_by(h) {
            if y.is_multiple_of(s) {
                for x in (h..n).step_by(s) {
                    let mean = 0.5 * (at(p, x - h, y) + at(p, x + h, y));
                    p[x + n * y] = self.displaced(mean, self.scales.edge_midpoint, x, y, z);
                }
            } else {
                // Columns alternate old (even i), new (odd i).
                for (i, x) in (0..n).step_by(h).enumerate() {
                    let v = if i & 1 == 0 {
                        let mean = 0.5 * (at(p, x, y - h) + at(p, x, y + h));
                        self.displaced(mean, self.scales.edge_midpoint, x, y, z)
                    } else {
                        let mean = 0.25
                            * ((at(p, x - h, y - h) + at(p, x + h, y - h))
                                + (at(p, x - h, y + h) + at(p, x + h, y + h)));
                        self.displaced(mean, self.scales.face_centre, x, y, z)
                    };
                    p[x + n * y] = v;
                }
            }
        }
    }

    /// Every point of a plane whose `z` is an odd multiple of `h` is new:
    /// z-edge midpoints, xz- and yz-face centres, cube centres, from the
    /// old points of the planes below and above.
    fn new_plane(&self, p: &mut [f32], z: usize, below: &[f32], above: &[f32]) {
        let (n, h, s) = (self.n, self.h, 2 * self.h);
        // Sum of an old point's values below and above.
        let pair = |x: usize, y: usize| f64::from(below[x + n * y]) + f64::from(above[x + n * y]);
        for y in (0..n).step_by(h) {
            let old_row = y.is_multiple_of(s);
            for (i, x) in (0..n).step_by(h).enumerate() {
                let old_column = i & 1 == 0;
                p[x + n * y] = match (old_column, old_row) {
                    (true, true) => {
                        let mean = 0.5 * pair(x, y);
                        self.displaced(mean, self.scales.edge_midpoint, x, y, z)
                    }
                    (false, true) => {
                        let mean = 0.25 * (pair(x - h, y) + pair(x + h, y));
                        self.displaced(mean, self.scales.face_centre, x, y, z)
                    }
                    (true, false) => {
                        let mean = 0.25 * (pair(x, y - h) + pair(x, y + h));
                        self.displaced(mean, self.scales.face_centre, x, y, z)
                    }
                    (false, false) => {
                        let mean = 0.125
                            * ((pair(x - h, y - h) + pair(x + h, y - h))
                                + (pair(x - h, y + h) + pair(x + h, y + h)));
                        self.displaced(mean, self.scales.cube_centre, x, y, z)
                    }
                };
            }
        }
    }
}
