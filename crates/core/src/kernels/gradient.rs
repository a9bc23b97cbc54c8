//! Intensity gradients by central differences (the paper's δf, errata 1).
//!
//! `δf(g_ijk) = [½(f[i+1,j,k] − f[i−1,j,k]) / dx, ½(f[i,j+1,k] − f[i,j−1,k]) / dy,
//! ½(f[i,j,k+1] − f[i,j,k−1]) / dz]`, in world units, so anisotropic voxels
//! get the physical gradient. At the grid's faces the difference is
//! one-sided: `(f[1] − f[0]) / dx` and `(f[n−1] − f[n−2]) / dx`. All three
//! forms are exact for a linear function.
//!
//! Gradients depend on the data alone, not on the view: they are computed
//! once per volume and kept across frames (as VTK caches its normals).
//! Their largest magnitude, [`max_magnitude`], scales gradient-magnitude
//! opacity and bounds Levoy's iso-surfaces (see [`crate::transfer::classifier`]).

use crate::volume::{Sample, Volume};
use glam::DVec3;
use rayon::prelude::*;

/// Bytes per voxel of [`gradients`].
pub const BYTES_PER_VOXEL: usize = size_of::<[f32; 3]>();

/// World-space gradient of `volume` at every voxel, x fastest.
pub fn gradients(volume: &Volume) -> Vec<[f32; 3]> {
    let [nx, ny, _] = volume.dims();
    let mut out = vec![[0.0f32; 3]; volume.len()];
    crate::with_samples!(volume.samples(), |data| {
        let d = Differences::new(data, volume);
        out.par_chunks_mut(nx * ny)
            .enumerate()
            .for_each(|(k, slice)| {
                for j in 0..ny {
                    for i in 0..nx {
                        slice[i + nx * j] = d.at(i, j, k);
                    }
                }
            });
    });
    out
}

/// World-space gradient of `volume` at voxel (`i`, `j`, `k`): central
/// differences inside, one-sided ones on the faces. (Loops over many
/// voxels take a [`Differences`] of the samples' own type.)
#[inline]
pub fn gradient_at(volume: &Volume, i: usize, j: usize, k: usize) -> [f32; 3] {
    crate::with_samples!(volume.samples(), |data| Differences::new(data, volume)
        .at(i, j, k))
}

/// A volume's samples of type `T` with what central differences need.
#[derive(Debug, Clone, Copy)]
pub struct Differences<'a, T> {
    data: &'a [T],
    dims: [usize; 3],
    spacing: DVec3,
}

impl<'a, T: Sample> Differences<'a, T> {
    /// The differences of `volume`, whose samples are `data`.
    pub fn new(data: &'a [T], volume: &Volume) -> Self {
        debug_assert_eq!(data.len(), volume.len());
        Differences {
            data,
            dims: volume.dims(),
            spacing: volume.spacing(),
        }
    }

    /// The world-space gradient at voxel (`i`, `j`, `k`).
    #[inline]
    pub fn at(&self, i: usize, j: usize, k: usize) -> [f32; 3] {
        let [nx, ny, nz] = self.dims;
        let spacing = self.spacing;
        let at = |i: usize, j: usize, k: usize| self.data[i + nx * (j + ny * k)].to_f32();
        // One axis: the neighbours below and above, clamped to the grid, and
        // how many voxel steps they span (2, or 1 at a face).
        let axis = |c: usize, n: usize| {
            let lo = c.saturating_sub(1);
            let hi = (c + 1).min(n - 1);
            (lo, hi, hi - lo)
        };
        let d = |lo: f32, hi: f32, span: usize, spacing: f64| {
            (hi - lo) * (1.0 / spacing) as f32 / span as f32
        };
        let (i0, i1, si) = axis(i, nx);
        let (j0, j1, sj) = axis(j, ny);
        let (k0, k1, sk) = axis(k, nz);
        [
            d(at(i0, j, k), at(i1, j, k), si, spacing.x),
            d(at(i, j0, k), at(i, j1, k), sj, spacing.y),
            d(at(i, j, k0), at(i, j, k1), sk, spacing.z),
        ]
    }
}

/// `|g|`, in `f32` as every path computes it: the classifier's opacity
/// and [`max_magnitude`] must agree on it to the last bit, so that the
/// maximum bounds every voxel's magnitude exactly.
#[inline]
pub fn magnitude(g: [f32; 3]) -> f32 {
    (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
}

/// The largest [`magnitude`] of [`gradient_at`] over every voxel of
/// `volume` (0 for a constant volume), without storing the gradients.
pub fn max_magnitude(volume: &Volume) -> f32 {
    let [nx, ny, nz] = volume.dims();
    crate::with_samples!(volume.samples(), |data| {
        let d = Differences::new(data, volume);
        (0..nz)
            .into_par_iter()
            .map(|k| {
                let mut max = 0.0f32;
                for j in 0..ny {
                    for i in 0..nx {
                        max = max.max(magnitude(d.at(i, j, k)));
                    }
                }
                max
            })
            .reduce(|| 0.0, f32::max)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn central_differences_are_exact_on_a_linear_ramp() {
        // f = 3x − 2y + 0.5z + 7 in world coordinates, anisotropic voxels.
        let spacing = DVec3::new(0.5, 2.0, 1.25);
        let v = Volume::from_fn([5, 4, 6], spacing, DVec3::new(1.0, -3.0, 2.0), |p| {
            (3.0 * p.x - 2.0 * p.y + 0.5 * p.z + 7.0) as f32
        })
        .unwrap();
        for g in gradients(&v) {
            assert!((g[0] - 3.0).abs() < 1e-4, "{g:?}");
            assert!((g[1] + 2.0).abs() < 1e-4, "{g:?}");
            assert!((g[2] - 0.5).abs() < 1e-4, "{g:?}");
        }
    }

    #[test]
    fn interior_uses_central_and_faces_one_sided_differences() {
        // f = x² along x: central difference at i is ((i+1)² − (i−1)²)/2 = 2i,
        // one-sided at the faces: 1 at i = 0 and (n−1)² − (n−2)² at i = n−1.
        let n = 5;
        let v =
            Volume::from_fn([n, 2, 2], DVec3::ONE, DVec3::ZERO, |p| (p.x * p.x) as f32).unwrap();
        let g = gradients(&v);
        let gx: Vec<f32> = (0..n).map(|i| g[v.index(i, 1, 1)][0]).collect();
        assert_eq!(gx, vec![1.0, 2.0, 4.0, 6.0, 7.0]);
        assert!(g.iter().all(|g| g[1] == 0.0 && g[2] == 0.0));
    }

    #[test]
    fn the_largest_magnitude_is_the_steepest_voxels() {
        // f = x² + 2y on a grid with x spacing 0.5: the gradient is (2x, 2)
        // inside; the face x = 2 (i = 4) has the one-sided difference
        // (4 − 2.25)/0.5 = 3.5, the largest, so the maximum is √(3.5² + 2²).
        let v = Volume::from_fn([5, 3, 2], DVec3::new(0.5, 1.0, 1.0), DVec3::ZERO, |p| {
            (p.x * p.x + 2.0 * p.y) as f32
        })
        .unwrap();
        let want = (3.5f32 * 3.5 + 4.0).sqrt();
        assert!(
            (max_magnitude(&v) - want).abs() < 1e-6,
            "{}",
            max_magnitude(&v)
        );
        let all = gradients(&v).into_iter().map(magnitude).fold(0.0, f32::max);
        assert_eq!(max_magnitude(&v), all);
        let flat = Volume::new([2, 2, 2], vec![4.0; 8]).unwrap();
        assert_eq!(max_magnitude(&flat), 0.0);
    }
}
