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
//! opacity and bounds Levoy's iso-surfaces (see `transfer::classifier`).

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
    /// The values are labels: differences of the smoothed indicator.
    labels: bool,
}

impl<'a, T: Sample> Differences<'a, T> {
    /// The differences of `volume`, whose samples are `data`.
    pub fn new(data: &'a [T], volume: &Volume) -> Self {
        debug_assert_eq!(data.len(), volume.len());
        Differences {
            data,
            dims: volume.dims(),
            spacing: volume.spacing(),
            labels: volume.is_labels(),
        }
    }

    /// The world-space gradient at voxel (`i`, `j`, `k`): of the values,
    /// or of a label volume's smoothed indicator ([`Self::label_at`]).
    #[inline]
    pub fn at(&self, i: usize, j: usize, k: usize) -> [f32; 3] {
        if self.labels {
            return self.label_at(i, j, k);
        }
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

impl<T: Sample> Differences<'_, T> {
    /// The world-space gradient at voxel (`i`, `j`, `k`) of the indicator
    /// of its own label `L` (1 where the value is `L`, 0 elsewhere),
    /// smoothed across each axis by the Sobel weights (¼, ½, ¼) in the two
    /// other axes: the difference along x is
    /// `Σ w(b)·w(c)·(χ[i+1, j+b, k+c] − χ[i−1, j+b, k+c])`, over the step
    /// between the two planes, with neighbours clamped to the grid as in
    /// [`Self::at`]. A label's boundary is a staircase of voxels; its raw
    /// central differences point along the axes, these follow the surface
    /// (within a few degrees on a voxelised sphere, see the tests). The
    /// gradient points into the label, as a density's points into the
    /// dense side; its magnitude is at most `1/spacing` per axis.
    #[inline]
    pub fn label_at(&self, i: usize, j: usize, k: usize) -> [f32; 3] {
        const W: [f32; 3] = [0.25, 0.5, 0.25];
        let [nx, ny, nz] = self.dims;
        let label = self.data[i + nx * (j + ny * k)].to_f32();
        let is = |i: usize, j: usize, k: usize| {
            f32::from(u8::from(self.data[i + nx * (j + ny * k)].to_f32() == label))
        };
        let near = |c: usize, d: usize, n: usize| (c + d).saturating_sub(1).min(n - 1);
        let axis = |c: usize, n: usize| {
            let lo = c.saturating_sub(1);
            let hi = (c + 1).min(n - 1);
            (lo, hi, (hi - lo) as f32)
        };
        let (i0, i1, si) = axis(i, nx);
        let (j0, j1, sj) = axis(j, ny);
        let (k0, k1, sk) = axis(k, nz);
        let mut g = [0.0f32; 3];
        for (a, wa) in W.iter().enumerate() {
            for (b, wb) in W.iter().enumerate() {
                let w = wa * wb;
                let (ja, ka) = (near(j, a, ny), near(k, b, nz));
                g[0] += w * (is(i1, ja, ka) - is(i0, ja, ka));
                let (ia, kb) = (near(i, a, nx), near(k, b, nz));
                g[1] += w * (is(ia, j1, kb) - is(ia, j0, kb));
                let (ib, jb) = (near(i, a, nx), near(j, b, ny));
                g[2] += w * (is(ib, jb, k1) - is(ib, jb, k0));
            }
        }
        let spacing = self.spacing;
        [
            g[0] * (1.0 / spacing.x) as f32 / si.max(1.0),
            g[1] * (1.0 / spacing.y) as f32 / sj.max(1.0),
            g[2] * (1.0 / spacing.z) as f32 / sk.max(1.0),
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

    /// The angle in degrees between `g` and `want`.
    fn angle(g: [f32; 3], want: DVec3) -> f64 {
        let g = DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64);
        g.angle_between(want).to_degrees()
    }

    #[test]
    fn a_labelled_balls_normals_follow_its_surface_not_its_staircase() {
        // A ball of label 1 (radius 9.3) in label 0: at the ball's boundary
        // voxels the gradient should point at the centre.
        let c = DVec3::splat(12.0);
        let ball = |p: DVec3| if (p - c).length() <= 9.3 { 1.0 } else { 0.0 };
        let raw = Volume::from_fn([25; 3], DVec3::ONE, DVec3::ZERO, ball).unwrap();
        let labels = raw.clone().as_labels();
        let (mut worst, mut sum_label, mut sum_raw, mut n) = (0.0f64, 0.0, 0.0, 0);
        for k in 1..24 {
            for j in 1..24 {
                for i in 1..24 {
                    let p = DVec3::new(i as f64, j as f64, k as f64);
                    let inside = ball(p) == 1.0;
                    let boundary = [(1, 0, 0), (0, 1, 0), (0, 0, 1)].iter().any(|&(a, b, d)| {
                        ball(p + DVec3::new(a as f64, b as f64, d as f64)) == 0.0
                            || ball(p - DVec3::new(a as f64, b as f64, d as f64)) == 0.0
                    });
                    if !(inside && boundary) {
                        continue;
                    }
                    let towards_centre = c - p;
                    let a = angle(gradient_at(&labels, i, j, k), towards_centre);
                    worst = worst.max(a);
                    sum_label += a;
                    sum_raw += angle(gradient_at(&raw, i, j, k), towards_centre);
                    n += 1;
                }
            }
        }
        let (mean_label, mean_raw) = (sum_label / n as f64, sum_raw / n as f64);
        println!("{n} voxels: smoothed {mean_label:.1}° (worst {worst:.1}°), raw {mean_raw:.1}°");
        assert!(n > 500);
        assert!(mean_label < 8.0 && worst < 25.0, "{mean_label} {worst}");
        assert!(mean_label < 0.7 * mean_raw, "{mean_label} vs {mean_raw}");
    }

    #[test]
    fn between_two_labels_each_side_points_into_its_own() {
        // Label 1 for x < 4, label 5 from x = 4: the values' gradient points
        // at the larger label on both sides; a label's into itself.
        let f = |p: DVec3| if p.x < 4.0 { 1.0 } else { 5.0 };
        let raw = Volume::from_fn([8, 5, 5], DVec3::ONE, DVec3::ZERO, f).unwrap();
        let labels = raw.clone().as_labels();
        assert!(gradient_at(&raw, 3, 2, 2)[0] > 0.0);
        assert!(gradient_at(&raw, 4, 2, 2)[0] > 0.0);
        let one = gradient_at(&labels, 3, 2, 2);
        let five = gradient_at(&labels, 4, 2, 2);
        // The indicator steps by 1 over 2 voxels: ±½, exactly along x.
        assert_eq!(one, [-0.5, 0.0, 0.0]);
        assert_eq!(five, [0.5, 0.0, 0.0]);
        // Away from the boundary: no gradient.
        assert_eq!(gradient_at(&labels, 1, 2, 2), [0.0; 3]);
    }
}
