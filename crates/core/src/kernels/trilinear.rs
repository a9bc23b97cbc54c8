//! Trilinear resampling: the value at an index-space point from the eight
//! voxels of the cell around it (the paper's resampling along each ray).
//!
//! Two forms: [`sample_reference`] (and [`scalar_reference`],
//! [`vector_reference`] for post-classification's scalars and gradients),
//! the textbook weighted sum `Σ w_ijk·v_ijk` with
//! `w = (1−fx or fx)(1−fy or fy)(1−fz or fz)` in `f64`, and [`sample`], the
//! same interpolation as seven `f32` lerps on RGBA vectors for the fast
//! path ([`sample_scalar`] for scalars). Both are exact on trilinear functions
//! `a + bx + cy + dz + exy + fyz + gxz + hxyz` (up to rounding).

use glam::{DVec3, DVec4, Vec3, Vec4};

/// The cell holding index-space point `p` and `p`'s offsets in it.
///
/// `p` must lie in `[0, n−1]³`; the last plane of voxels belongs to the
/// cell below it (offset 1), so every point has a whole cell.
#[inline]
fn locate(p: [f64; 3], dims: [usize; 3]) -> ([usize; 3], [f64; 3]) {
    let mut cell = [0usize; 3];
    let mut frac = [0.0f64; 3];
    for a in 0..3 {
        let c = (p[a].floor().max(0.0) as usize).min(dims[a] - 2);
        cell[a] = c;
        frac[a] = p[a] - c as f64;
    }
    (cell, frac)
}

/// The eight voxels of the cell around index-space point `p` (indices
/// into an x-fastest array) with their trilinear weights
/// `(1−fx or fx)(1−fy or fy)(1−fz or fz)`, which sum to 1.
#[inline]
pub fn corners(p: [f64; 3], dims: [usize; 3]) -> [(usize, f64); 8] {
    let ([i, j, k], [fx, fy, fz]) = locate(p, dims);
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

/// Reference trilinear interpolation of the per-voxel RGBA values in
/// `voxels` at index-space point `p` (`f64` arithmetic).
pub fn sample_reference(voxels: &[Vec4], dims: [usize; 3], p: [f64; 3]) -> DVec4 {
    let mut sum = DVec4::ZERO;
    for (index, w) in corners(p, dims) {
        sum += w * voxels[index].as_dvec4();
    }
    sum
}

/// Reference trilinear interpolation of the scalars `values` (a volume's
/// data) at index-space point `p`.
pub fn scalar_reference(values: &[f32], dims: [usize; 3], p: [f64; 3]) -> f64 {
    corners(p, dims)
        .iter()
        .map(|&(index, w)| w * values[index] as f64)
        .sum()
}

/// Reference trilinear interpolation of per-voxel vectors (gradients) at
/// index-space point `p`.
pub fn vector_reference(vectors: &[[f32; 3]], dims: [usize; 3], p: [f64; 3]) -> DVec3 {
    corners(p, dims)
        .iter()
        .map(|&(index, w)| w * Vec3::from(vectors[index]).as_dvec3())
        .sum()
}

/// Fast trilinear interpolation (`f32`, seven vector lerps) at index-space
/// point `p`, which must lie in `[0, n−1]³`.
#[inline]
pub fn sample(voxels: &[Vec4], dims: [usize; 3], p: Vec3) -> Vec4 {
    let [nx, ny, nz] = dims;
    let i = (p.x as usize).min(nx - 2);
    let j = (p.y as usize).min(ny - 2);
    let k = (p.z as usize).min(nz - 2);
    let (fx, fy, fz) = (p.x - i as f32, p.y - j as f32, p.z - k as f32);
    let (sy, sz) = (nx, nx * ny);
    let base = i + nx * j + sz * k;
    let c00 = voxels[base].lerp(voxels[base + 1], fx);
    let c10 = voxels[base + sy].lerp(voxels[base + sy + 1], fx);
    let c01 = voxels[base + sz].lerp(voxels[base + sz + 1], fx);
    let c11 = voxels[base + sy + sz].lerp(voxels[base + sy + sz + 1], fx);
    c00.lerp(c10, fy).lerp(c01.lerp(c11, fy), fz)
}

/// Fast trilinear interpolation of the scalars `values` (`f32`, seven
/// lerps) at index-space point `p`, which must lie in `[0, n−1]³`.
#[inline]
pub fn sample_scalar(values: &[f32], dims: [usize; 3], p: Vec3) -> f32 {
    let [nx, ny, nz] = dims;
    let i = (p.x as usize).min(nx - 2);
    let j = (p.y as usize).min(ny - 2);
    let k = (p.z as usize).min(nz - 2);
    let (fx, fy, fz) = (p.x - i as f32, p.y - j as f32, p.z - k as f32);
    let (sy, sz) = (nx, nx * ny);
    let base = i + nx * j + sz * k;
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let c00 = lerp(values[base], values[base + 1], fx);
    let c10 = lerp(values[base + sy], values[base + sy + 1], fx);
    let c01 = lerp(values[base + sz], values[base + sz + 1], fx);
    let c11 = lerp(values[base + sy + sz], values[base + sy + sz + 1], fx);
    lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trilinear function with all eight terms, different per channel.
    fn trilinear_fn(x: f64, y: f64, z: f64) -> [f64; 4] {
        let f = |c: f64| {
            0.3 + c * 0.01 * x - 0.02 * y + 0.015 * z + 0.004 * x * y - 0.003 * y * z
                + 0.002 * x * z * c
                - 0.0007 * x * y * z
        };
        [f(1.0), f(2.0), f(-1.0), f(0.5)]
    }

    fn grid(dims: [usize; 3]) -> Vec<Vec4> {
        let mut v = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let c = trilinear_fn(i as f64, j as f64, k as f64);
                    v.push(Vec4::new(
                        c[0] as f32,
                        c[1] as f32,
                        c[2] as f32,
                        c[3] as f32,
                    ));
                }
            }
        }
        v
    }

    #[test]
    fn exact_on_trilinear_functions() {
        let dims = [7, 5, 6];
        let voxels = grid(dims);
        // The red channel as scalars, red-green-blue as vectors.
        let scalars: Vec<f32> = voxels.iter().map(|v| v.x).collect();
        let vectors: Vec<[f32; 3]> = voxels.iter().map(|v| v.truncate().to_array()).collect();
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
            let r = sample_reference(&voxels, dims, p);
            let f = sample(
                &voxels,
                dims,
                Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32),
            );
            for c in 0..4 {
                assert!(
                    (r[c] - want[c]).abs() < 1e-6,
                    "reference at {p:?}: {} vs {}",
                    r[c],
                    want[c]
                );
                assert!(
                    (f[c] as f64 - want[c]).abs() < 1e-5,
                    "fast at {p:?}: {} vs {}",
                    f[c],
                    want[c]
                );
            }
            assert!((scalar_reference(&scalars, dims, p) - want[0]).abs() < 1e-6);
            let fast = sample_scalar(
                &scalars,
                dims,
                Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32),
            );
            assert!((fast as f64 - want[0]).abs() < 1e-5);
            let v = vector_reference(&vectors, dims, p);
            assert!(
                (v - DVec3::new(want[0], want[1], want[2]))
                    .abs()
                    .max_element()
                    < 1e-6
            );
        }
    }

    #[test]
    fn reproduces_voxels_at_grid_points() {
        let dims = [3, 3, 3];
        let voxels = grid(dims);
        let v = sample(&voxels, dims, Vec3::new(2.0, 1.0, 2.0));
        assert_eq!(v, voxels[2 + 3 * (1 + 3 * 2)]);
        let r = sample_reference(&voxels, dims, [2.0, 1.0, 2.0]);
        assert_eq!(r.as_vec4(), voxels[2 + 3 * (1 + 3 * 2)]);
    }
}
