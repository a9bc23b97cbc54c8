//! The grid in the world: where a world ray is inside the volume.
//!
//! Positions are computed in *index space* (voxel (i, j, k) at (i, j, k)),
//! where the volume is the box `[0, n−1]³` and trilinear interpolation is
//! simplest; [`GridFrame`] maps world positions there, and
//! [`GridFrame::span`] gives where any world ray (parallel, or from a
//! perspective eye) is inside the box, by the slab test.

use glam::DVec3;

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
    /// The grid of `volume`'s voxels.
    pub fn of(volume: &crate::volume::Volume) -> Self {
        GridFrame {
            dims: volume.dims(),
            origin: volume.origin(),
            spacing: volume.spacing(),
        }
    }

    /// The world size of the grid's box, `(n − 1)·spacing` on each axis.
    pub fn extent(&self) -> DVec3 {
        let n = |a: usize| (self.dims[a] - 1) as f64;
        DVec3::new(n(0), n(1), n(2)) * self.spacing
    }

    /// The grid's box in the world: its first and last voxels' positions.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.origin, self.origin + self.extent())
    }

    /// Where a world ray `origin + t·dir` (`dir` a unit vector) is inside
    /// the grid's box: `(t_enter, t_exit)` in world units of `t`, the same
    /// `t` as the ray's. `None` if the line misses the box. The
    /// whole line counts: `t_enter` may be negative (behind a perspective
    /// eye, or in front of an orthographic image plane); callers clip.
    pub fn span(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        let (t_enter, t_exit) =
            self.slabs((origin - self.origin) / self.spacing, dir / self.spacing)?;
        (t_enter <= t_exit).then_some((t_enter, t_exit))
    }

    /// The slab test (Kay and Kajiya 1986) of the index-space line
    /// `origin + t·direction` against `[0, n−1]³`: the largest entry and the
    /// smallest exit `t` over the three axes (`t_enter > t_exit` when it
    /// misses), or `None` if it runs parallel to an axis outside the box.
    fn slabs(&self, origin: DVec3, direction: DVec3) -> Option<(f64, f64)> {
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
        Some((t_enter, t_exit))
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
    fn span_gives_entry_and_exit_in_world_t() {
        // Box x ∈ [−3, 5], y ∈ [1, 5], z ∈ [2, 10] (anisotropic spacing).
        let grid = frame([5, 9, 3], DVec3::new(2.0, 0.5, 4.0));
        let (lo, hi) = (DVec3::new(-3.0, 1.0, 2.0), DVec3::new(5.0, 5.0, 10.0));
        // Along −x from x = 20: enters at x = 5, leaves at x = −3.
        let span = grid.span(DVec3::new(20.0, 3.0, 6.0), -DVec3::X).unwrap();
        assert_eq!(span, (15.0, 23.0));
        // Along the box's diagonal, 6 units before its low corner: the
        // diagonal is 12 long.
        let dir = (hi - lo) / 12.0;
        let (enter, exit) = grid.span(lo - 6.0 * dir, dir).unwrap();
        assert!((enter - 6.0).abs() < 1e-12 && (exit - 18.0).abs() < 1e-12);
        // From inside, the entry lies behind the origin.
        let (enter, exit) = grid.span(DVec3::new(0.0, 3.0, 6.0), DVec3::Z).unwrap();
        assert_eq!((enter, exit), (-4.0, 4.0));
        // Misses: parallel outside, and oblique past a corner.
        assert!(grid.span(DVec3::new(20.0, 6.0, 6.0), -DVec3::X).is_none());
        let past = DVec3::new(1.0, -1.0, 0.0).normalize();
        assert!(grid.span(DVec3::new(-10.0, 0.0, 6.0), past).is_none());
        // A line rising towards the box from below it hits it.
        let towards = DVec3::new(1.0, 1.0, 0.0).normalize();
        assert!(grid.span(DVec3::new(-10.0, -6.0, 6.0), towards).is_some());
    }

    #[test]
    fn a_perspective_ray_enters_and_leaves_on_the_box_faces() {
        use crate::camera::{Projection, View};
        let grid = frame([9, 9, 9], DVec3::splat(0.25));
        let bounds = (grid.origin, grid.origin + DVec3::splat(2.0));
        let camera = Camera {
            projection: Projection::Perspective { fov_degrees: 45.0 },
            azimuth: 20.0,
            elevation: 35.0,
            ..Camera::default()
        };
        let view = View::frame(&camera, bounds, 9, 9).unwrap();
        let on_face = |p: DVec3| {
            let inside = (p - bounds.0).cmpge(DVec3::splat(-1e-9)).all()
                && (bounds.1 - p).cmpge(DVec3::splat(-1e-9)).all();
            let touches = (0..3)
                .any(|a| (p[a] - bounds.0[a]).abs() < 1e-9 || (p[a] - bounds.1[a]).abs() < 1e-9);
            inside && touches
        };
        let (eye, dir) = view.pixel_ray(4, 4);
        let (enter, exit) = grid.span(eye, dir).unwrap();
        assert!(0.0 < enter && enter < exit, "the eye is outside the box");
        assert!(on_face(eye + enter * dir) && on_face(eye + exit * dir));
        // The corner pixel's ray misses the box: it fits the sphere.
        assert!(
            grid.span(view.pixel_ray(0, 0).0, view.pixel_ray(0, 0).1)
                .is_none()
        );
    }
}
