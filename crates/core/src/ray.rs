//! Stage 2 sampling positions: where each ray meets the volume and where
//! along it the samples lie.
//!
//! Positions are computed in *index space* (voxel (i, j, k) at (i, j, k)),
//! where the volume is the box `[0, n−1]³` and trilinear interpolation is
//! simplest. The ray `p(t) = pixel centre + t·d` is sampled at `t = k·Δ` for
//! every integer `k` whose sample lies inside the box (Δ is the step in
//! world units). Because `t = 0` on the image plane, the samples of all
//! rays lie on common planes parallel to the image: neighbouring rays sample
//! the same depths, which avoids the wood-grain pattern that per-ray start
//! offsets cause. Sample 0 is the nearest to the eye (errata 4). The fast and
//! the reference path take their positions from here, so they sample the
//! very same points.

use crate::camera::OrthographicView;
use glam::DVec3;

/// The samples of one ray, in index space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RaySamples {
    /// Index-space point where `t = 0` (the pixel centre).
    pub origin: DVec3,
    /// Index-space displacement per world unit of `t`.
    pub direction: DVec3,
    /// World distance between samples.
    pub step: f64,
    /// First and last sample number `k` (inclusive), `first ≤ last`.
    pub first: i64,
    pub last: i64,
}

impl RaySamples {
    /// Number of samples.
    pub fn count(&self) -> usize {
        (self.last - self.first + 1) as usize
    }

    /// Index-space position of sample `k`, clamped into the box.
    #[inline]
    pub fn position(&self, k: i64, dims: [usize; 3]) -> DVec3 {
        let p = self.origin + (k as f64 * self.step) * self.direction;
        clamp_to_grid(p, dims)
    }
}

/// Clamps an index-space point into `[0, n−1]³`: samples found inside the
/// box by a tolerant test may sit a rounding error outside it.
#[inline]
pub fn clamp_to_grid(p: DVec3, dims: [usize; 3]) -> DVec3 {
    p.clamp(
        DVec3::ZERO,
        DVec3::new(
            (dims[0] - 1) as f64,
            (dims[1] - 1) as f64,
            (dims[2] - 1) as f64,
        ),
    )
}

/// Maps world positions to index space for a grid of `origin` and `spacing`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridFrame {
    pub dims: [usize; 3],
    pub origin: DVec3,
    pub spacing: DVec3,
}

impl GridFrame {
    /// The samples of the ray through pixel (`col`, `row`) of `view`, `step`
    /// world units apart, or `None` if the ray misses the volume.
    pub fn ray(
        &self,
        view: &OrthographicView,
        col: usize,
        row: usize,
        step: f64,
    ) -> Option<RaySamples> {
        let origin = (view.pixel_centre(col, row) - self.origin) / self.spacing;
        let direction = view.direction / self.spacing;
        let (mut t_enter, mut t_exit) = (f64::NEG_INFINITY, f64::INFINITY);
        for axis in 0..3 {
            let (o, d) = (origin[axis], direction[axis]);
            let n = (self.dims[axis] - 1) as f64;
            if d == 0.0 {
                if !(0.0..=n).contains(&o) {
                    return None;
                }
            } else {
                let (a, b) = ((0.0 - o) / d, (n - o) / d);
                t_enter = t_enter.max(a.min(b));
                t_exit = t_exit.min(a.max(b));
            }
        }
        // Samples within a millionth of a step of a face count as inside.
        let tolerance = 1e-6 * step;
        let first = ((t_enter - tolerance) / step).ceil();
        let last = ((t_exit + tolerance) / step).floor();
        (first <= last).then_some(RaySamples {
            origin,
            direction,
            step,
            first: first as i64,
            last: last as i64,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;

    fn frame(dims: [usize; 3], spacing: DVec3) -> GridFrame {
        GridFrame {
            dims,
            origin: DVec3::new(-3.0, 1.0, 2.0),
            spacing,
        }
    }

    #[test]
    fn axis_view_samples_every_voxel_plane() {
        // 11 points along x at unit spacing: a step of 1 gives 11 samples,
        // a step of 0.5 gives 21, from the eye (+x side) backwards.
        let grid = frame([11, 6, 6], DVec3::ONE);
        let bounds = (grid.origin, grid.origin + DVec3::new(10.0, 5.0, 5.0));
        let view = OrthographicView::frame(&Camera::default(), bounds, 8, 8).unwrap();
        for (step, count) in [(1.0, 11), (0.5, 21), (0.25, 41)] {
            let ray = grid.ray(&view, 3, 4, step).unwrap();
            assert_eq!(ray.count(), count, "step {step}");
            assert!((ray.position(ray.first, grid.dims).x - 10.0).abs() < 1e-9);
            assert!(ray.position(ray.last, grid.dims).x.abs() < 1e-9);
        }
    }

    #[test]
    fn anisotropic_spacing_maps_world_to_index() {
        let grid = frame([5, 9, 3], DVec3::new(2.0, 0.5, 4.0));
        let bounds = (grid.origin, grid.origin + DVec3::new(8.0, 4.0, 8.0));
        let view = OrthographicView::frame(&Camera::default(), bounds, 16, 32).unwrap();
        let ray = grid.ray(&view, 0, 0, 0.5).unwrap();
        // 8 world units along x at 0.5 per sample: 17 samples.
        assert_eq!(ray.count(), 17);
        let p = ray.position(ray.first, grid.dims);
        let world = view.pixel_centre(0, 0);
        assert!(((world.y - grid.origin.y) / 0.5 - p.y).abs() < 1e-9);
        assert!(((world.z - grid.origin.z) / 4.0 - p.z).abs() < 1e-9);
    }

    #[test]
    fn rays_outside_the_box_miss() {
        let grid = frame([4, 4, 4], DVec3::ONE);
        let bounds = (grid.origin, grid.origin + DVec3::splat(3.0));
        let default = OrthographicView::frame(&Camera::default(), bounds, 4, 4).unwrap();
        let far = OrthographicView {
            centre: default.centre + DVec3::new(0.0, 100.0, 0.0),
            ..default
        };
        assert!(grid.ray(&default, 1, 1, 1.0).is_some());
        assert!(grid.ray(&far, 1, 1, 1.0).is_none());
    }
}
