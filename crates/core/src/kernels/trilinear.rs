//! Trilinear resampling: the value at an index-space point from the eight
//! voxels of the cell around it (the paper's resampling along each ray).
//!
//! Two forms, each written once:
//!
//! - **The fast form**, in `f32`: seven lerps `a + (b − a)·t`, first along
//!   x (four), then y (two), then z ([`interpolate`]), on one value or on
//!   four SIMD lanes ([`Lanes`]: RGBA, or a gradient packed with its
//!   value). [`corners`] fetches a cell's eight voxels from any x-fastest
//!   layout (a volume, a brick's slots) by its strides, and [`cell_of`]
//!   finds the cell of a point. Every fast caster calls these, so they
//!   interpolate by the very same operations.
//! - **The reference form**, in `f64`: the textbook weighted sum
//!   `Σ w_ijk·v_ijk` with `w = (1−fx or fx)(1−fy or fy)(1−fz or fz)`
//!   ([`weights`], [`reference()`]), for the oracle.
//!
//! Both are exact on trilinear functions `a + bx + cy + dz + exy + fyz +
//! gxz + hxyz` (up to rounding).

use crate::kernels::lanes::Lanes;
use crate::volume::Sample;
use glam::Vec3;
use std::ops::{Add, Mul};

/// `a + (b − a)·t`.
#[inline(always)]
pub fn lerp<T: Lanes>(a: T, b: T, t: f32) -> T {
    a + (b - a) * T::splat(t)
}

/// The eight voxels of the cell whose first voxel is at `base`, in a
/// layout with x stride 1, y stride `sy` and z stride `sz`, read by `at`:
/// `[v000, v100, v010, v110, v001, v101, v011, v111]` (x fastest).
#[inline(always)]
pub fn corners<T>(at: impl Fn(usize) -> T, base: usize, sy: usize, sz: usize) -> [T; 8] {
    [
        at(base),
        at(base + 1),
        at(base + sy),
        at(base + sy + 1),
        at(base + sz),
        at(base + sz + 1),
        at(base + sy + sz),
        at(base + sy + sz + 1),
    ]
}

/// Trilinear interpolation of a cell's eight voxels `c` (as [`corners`]
/// orders them) at offsets `[fx, fy, fz]` in the cell: four lerps along x,
/// two along y, one along z.
#[inline(always)]
pub fn interpolate<T: Lanes>(c: [T; 8], [fx, fy, fz]: [f32; 3]) -> T {
    let y0 = lerp(lerp(c[0], c[1], fx), lerp(c[2], c[3], fx), fy);
    let y1 = lerp(lerp(c[4], c[5], fx), lerp(c[6], c[7], fx), fy);
    lerp(y0, y1, fz)
}

/// The cell holding index-space point `p` (at least 0 on every axis) and
/// `p`'s offsets in it; `last` is the last cell along each axis (its far
/// face belongs to it, so every point has a whole cell).
#[inline(always)]
pub fn cell_of(p: Vec3, last: [usize; 3]) -> ([usize; 3], [f32; 3]) {
    // `p` ≥ 0, so truncation is the floor.
    let c = [
        (p.x as usize).min(last[0]),
        (p.y as usize).min(last[1]),
        (p.z as usize).min(last[2]),
    ];
    (c, [p.x - c[0] as f32, p.y - c[1] as f32, p.z - c[2] as f32])
}

/// The fast trilinear interpolation of the scalars `values` (x fastest,
/// `dims` voxels, any sample type, read as `f32`) at index-space point `p`, which must lie in `[0, n−1]³`.
#[inline]
pub fn sample_scalar<T: Sample>(values: &[T], dims: [usize; 3], p: Vec3) -> f32 {
    let [nx, ny, nz] = dims;
    let (c, f) = cell_of(p, [nx - 2, ny - 2, nz - 2]);
    let base = c[0] + nx * (c[1] + ny * c[2]);
    interpolate(corners(|i| values[i].to_f32(), base, nx, nx * ny), f)
}

/// The eight voxels of the cell around index-space point `p` (indices
/// into an x-fastest array of `dims` voxels) with their trilinear weights
/// `(1−fx or fx)(1−fy or fy)(1−fz or fz)`, which sum to 1.
///
/// `p` must lie in `[0, n−1]³`; the last plane of voxels belongs to the
/// cell below it (offset 1), so every point has a whole cell.
#[inline]
pub fn weights(p: [f64; 3], dims: [usize; 3]) -> [(usize, f64); 8] {
    let mut cell = [0usize; 3];
    let mut frac = [0.0f64; 3];
    for a in 0..3 {
        let c = (p[a].floor().max(0.0) as usize).min(dims[a] - 2);
        cell[a] = c;
        frac[a] = p[a] - c as f64;
    }
    let ([i, j, k], [fx, fy, fz]) = (cell, frac);
    let mut out = [(0, 0.0); 8];
    let mut n = 0;
    for (dk, wz) in [(0, 1.0 - fz), (1, fz)] {
        for (dj, wy) in [(0, 1.0 - fy), (1, fy)] {
            for (di, wx) in [(0, 1.0 - fx), (1, fx)] {
                out[n] = (
                    (i + di) + dims[0] * ((j + dj) + dims[1] * (k + dk)),
                    wx * wy * wz,
                );
                n += 1;
            }
        }
    }
    out
}

/// The reference trilinear interpolation (`f64`) at index-space point `p`
/// of the per-voxel values `value(index)` (scalars, colours, gradients),
/// summed from `zero`.
#[inline]
pub fn reference<V>(p: [f64; 3], dims: [usize; 3], zero: V, value: impl Fn(usize) -> V) -> V
where
    V: Add<Output = V> + Mul<f64, Output = V>,
{
    weights(p, dims)
        .into_iter()
        .fold(zero, |sum, (index, w)| sum + value(index) * w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec3, DVec4, Vec4};
    use wide::f32x4;

    /// A trilinear function with all eight terms, different per channel.
    fn trilinear_fn(x: f64, y: f64, z: f64) -> [f64; 4] {
        let f = |c: f64| {
            0.3 + c * 0.01 * x - 0.02 * y + 0.015 * z + 0.004 * x * y - 0.003 * y * z
                + 0.002 * x * z * c
                - 0.0007 * x * y * z
        };
        [f(1.0), f(2.0), f(-1.0), f(0.5)]
    }

    fn grid(dims: [usize; 3]) -> Vec<[f32; 4]> {
        let mut v = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    v.push(trilinear_fn(i as f64, j as f64, k as f64).map(|c| c as f32));
                }
            }
        }
        v
    }

    /// The fast form on four lanes at `p`.
    fn fast4(voxels: &[[f32; 4]], dims: [usize; 3], p: Vec3) -> [f32; 4] {
        let [nx, ny, nz] = dims;
        let (c, f) = cell_of(p, [nx - 2, ny - 2, nz - 2]);
        let base = c[0] + nx * (c[1] + ny * c[2]);
        interpolate(corners(|i| f32x4::new(voxels[i]), base, nx, nx * ny), f).to_array()
    }

    #[test]
    fn both_forms_are_exact_on_trilinear_functions() {
        let dims = [7, 5, 6];
        let voxels = grid(dims);
        let scalars: Vec<f32> = voxels.iter().map(|v| v[0]).collect();
        // Deterministic scatter of points, including the faces and corners.
        let mut points = vec![
            [0.0, 0.0, 0.0],
            [6.0, 4.0, 5.0],
            [6.0, 0.0, 2.5],
            [3.0, 4.0, 0.0],
        ];
        let mut s = 0.123456789f64;
        for _ in 0..200 {
            let mut p = [0.0; 3];
            for (a, pa) in p.iter_mut().enumerate() {
                s = (s * 9301.0 + 0.49297).fract();
                *pa = s * (dims[a] - 1) as f64;
            }
            points.push(p);
        }
        for p in points {
            let want = trilinear_fn(p[0], p[1], p[2]);
            let r = reference(p, dims, DVec4::ZERO, |i| Vec4::from(voxels[i]).as_dvec4());
            let pf = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
            let f = fast4(&voxels, dims, pf);
            for c in 0..4 {
                assert!((r[c] - want[c]).abs() < 1e-6, "reference at {p:?}");
                assert!((f[c] as f64 - want[c]).abs() < 1e-5, "fast at {p:?}");
            }
            let scalar = reference(p, dims, 0.0, |i| scalars[i] as f64);
            assert!((scalar - want[0]).abs() < 1e-6);
            // One lane and four lanes interpolate alike, to the bit.
            assert_eq!(sample_scalar(&scalars, dims, pf).to_bits(), f[0].to_bits());
            let v = reference(p, dims, DVec3::ZERO, |i| {
                Vec4::from(voxels[i]).truncate().as_dvec3()
            });
            let want3 = DVec3::new(want[0], want[1], want[2]);
            assert!((v - want3).abs().max_element() < 1e-6);
        }
    }

    #[test]
    fn both_forms_reproduce_voxels_at_grid_points() {
        let dims = [3, 3, 3];
        let voxels = grid(dims);
        let at = 2 + 3 * (1 + 3 * 2);
        assert_eq!(fast4(&voxels, dims, Vec3::new(2.0, 1.0, 2.0)), voxels[at]);
        let r = reference([2.0, 1.0, 2.0], dims, DVec4::ZERO, |i| {
            Vec4::from(voxels[i]).as_dvec4()
        });
        assert_eq!(r.as_vec4().to_array(), voxels[at]);
    }

    #[test]
    fn weights_sum_to_one_and_name_the_cell_corners() {
        let dims = [4, 3, 5];
        let w = weights([1.25, 2.0, 3.5], dims);
        assert!((w.iter().map(|(_, w)| w).sum::<f64>() - 1.0).abs() < 1e-15);
        // y = 2 is the last plane: it belongs to cell 1 at offset 1.
        assert_eq!(w[0].0, 1 + 4 * (1 + 3 * 3));
        assert_eq!(w[7].0, 2 + 4 * (2 + 3 * 4));
    }
}
