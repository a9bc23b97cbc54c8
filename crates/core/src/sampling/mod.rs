//! Which samples each pixel's ray takes, with every option of the frame:
//! orthographic or perspective rays, the crop box and clip planes, and
//! jitter.
//!
//! A pixel's world ray `p(t) = o + t·d` ([`View::pixel_ray`]) is sampled at
//! `t = (k + u)·step` for the integers `k` whose `t` lies in the ray's
//! interval: where it is inside the grid ([`GridFrame::span`]), cut by the
//! crop box and the clip planes ([`crate::sampling::clipping`]), and, for a
//! perspective ray, in front of the eye (`t ≥ 0`). `u` is 0, or the pixel's
//! jitter offset ([`crate::sampling::jitter`]). Without options the samples
//! of parallel rays lie on planes parallel to the image, `t = k·step` from
//! it (sample 0 the nearest to the eye, errata 4): neighbouring rays sample
//! the same depths, which avoids the wood-grain pattern that per-ray start
//! offsets cause. Samples within a millionth of a step of the interval's
//! ends count as inside.
//!
//! Both paths take their samples from here (the fast path for its rays'
//! exact ranges), so they sample the very same points.

pub mod clipping;
pub mod grid;
pub mod jitter;

use crate::camera::View;
use crate::sampling::clipping::Clipping;
use crate::sampling::grid::{GridFrame, clamp_to_grid};
use crate::volume::piece::Ownership;
use glam::DVec3;

/// The sample positions of one frame's rays.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampling {
    pub grid: GridFrame,
    /// World distance between samples.
    pub step: f64,
    pub clipping: Clipping,
    /// Offset each pixel's samples by its jitter.
    pub jitter: bool,
    /// Rays start at the eye (perspective): only `t ≥ 0` is sampled.
    pub from_eye: bool,
    /// A piece of a larger volume ([`crate::volume::piece`]): rays are bounded by
    /// the whole grid, and take only the samples the piece owns.
    pub ownership: Option<Ownership>,
}

/// The samples of one pixel's ray: `k` from `first` to `last` (inclusive).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelSamples {
    /// Index-space point where `t = 0`.
    pub origin: DVec3,
    /// Index-space displacement per world unit of `t`.
    pub direction: DVec3,
    /// World distance between samples.
    pub step: f64,
    /// Sample `k` is at `t = (k + offset)·step`.
    pub offset: f64,
    pub first: i64,
    pub last: i64,
}

impl PixelSamples {
    /// Number of samples.
    pub fn count(&self) -> usize {
        (self.last - self.first + 1) as usize
    }

    /// The ray parameter of sample `k`.
    #[inline]
    pub fn t(&self, k: i64) -> f64 {
        (k as f64 + self.offset) * self.step
    }

    /// Index-space position of sample `k`, clamped into the grid.
    #[inline]
    pub fn position(&self, k: i64, dims: [usize; 3]) -> DVec3 {
        clamp_to_grid(self.origin + self.t(k) * self.direction, dims)
    }
}

impl Sampling {
    /// The samples of pixel (`col`, `row`) of `view`, or `None` if its ray
    /// takes none.
    pub fn pixel(&self, view: &View, col: usize, row: usize) -> Option<PixelSamples> {
        let (origin, direction) = view.pixel_ray(col, row);
        self.ray(col, row, origin, direction)
    }

    /// The samples of pixel (`col`, `row`) whose world ray is
    /// `origin + t·direction` (`direction` a unit vector), or `None`.
    pub fn ray(
        &self,
        col: usize,
        row: usize,
        origin: DVec3,
        direction: DVec3,
    ) -> Option<PixelSamples> {
        let bounds = self.ownership.as_ref().map_or(&self.grid, |o| &o.whole);
        let (mut t0, t1) = bounds.span(origin, direction)?;
        if self.from_eye {
            t0 = t0.max(0.0);
        }
        let (t0, t1) = if self.clipping.is_active() {
            self.clipping.clip(origin, direction, (t0, t1))?
        } else {
            (t0, t1)
        };
        let offset = if self.jitter {
            jitter::offset(col, row)
        } else {
            0.0
        };
        let step = self.step;
        let tolerance = 1e-6 * step;
        let first = ((t0 - tolerance) / step - offset).ceil();
        let last = ((t1 + tolerance) / step - offset).floor();
        if first > last {
            return None;
        }
        let (first, last) = (first as i64, last as i64);
        let (first, last) = match &self.ownership {
            Some(owned) => owned.restrict(origin, direction, step, offset, (first, last))?,
            None => (first, last),
        };
        Some(PixelSamples {
            origin: (origin - self.grid.origin) / self.grid.spacing,
            direction: direction / self.grid.spacing,
            step,
            offset,
            first,
            last,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Camera, OrthographicView, Projection};

    fn grid() -> GridFrame {
        GridFrame {
            dims: [11, 7, 9],
            origin: DVec3::new(-3.0, 1.0, 2.0),
            spacing: DVec3::new(1.0, 0.5, 0.75),
        }
    }

    fn sampling(jitter: bool, clipping: Clipping, from_eye: bool) -> Sampling {
        Sampling {
            grid: grid(),
            step: 0.4,
            clipping,
            jitter,
            from_eye,
            ownership: None,
        }
    }

    fn oblique() -> View {
        let g = grid();
        let bounds = (g.origin, g.origin + DVec3::new(10.0, 3.0, 6.0));
        let camera = Camera {
            view_point: Some(DVec3::new(40.0, -25.0, 30.0)),
            ..Camera::default()
        };
        View::Orthographic(OrthographicView::frame(&camera, bounds, 20, 16).unwrap())
    }

    /// Samples without options of the default view (along −x) through
    /// pixel (`col`, `row`) of an `size` image of a grid with `dims` and
    /// `spacing`, `step` apart.
    fn axis_ray(
        dims: [usize; 3],
        spacing: DVec3,
        size: (usize, usize),
        (col, row): (usize, usize),
        step: f64,
    ) -> (View, Option<PixelSamples>) {
        let grid = GridFrame {
            dims,
            origin: DVec3::new(-3.0, 1.0, 2.0),
            spacing,
        };
        let extent = DVec3::new(
            (dims[0] - 1) as f64,
            (dims[1] - 1) as f64,
            (dims[2] - 1) as f64,
        ) * spacing;
        let bounds = (grid.origin, grid.origin + extent);
        let view = View::frame(&Camera::default(), bounds, size.0, size.1).unwrap();
        let s = Sampling {
            grid,
            step,
            clipping: Clipping::default(),
            jitter: false,
            from_eye: false,
            ownership: None,
        };
        let samples = s.pixel(&view, col, row);
        (view, samples)
    }

    #[test]
    fn an_axis_view_samples_every_voxel_plane() {
        // 11 points along x at unit spacing: a step of 1 gives 11 samples,
        // a step of 0.5 gives 21, from the eye (+x side) backwards.
        for (step, count) in [(1.0, 11), (0.5, 21), (0.25, 41)] {
            let (_, ray) = axis_ray([11, 6, 6], DVec3::ONE, (8, 8), (3, 4), step);
            let ray = ray.unwrap();
            assert_eq!(ray.count(), count, "step {step}");
            assert!((ray.position(ray.first, [11, 6, 6]).x - 10.0).abs() < 1e-9);
            assert!(ray.position(ray.last, [11, 6, 6]).x.abs() < 1e-9);
        }
    }

    #[test]
    fn anisotropic_spacing_maps_world_to_index() {
        let dims = [5, 9, 3];
        let spacing = DVec3::new(2.0, 0.5, 4.0);
        let (view, ray) = axis_ray(dims, spacing, (16, 32), (0, 0), 0.5);
        let ray = ray.unwrap();
        // 8 world units along x at 0.5 per sample: 17 samples.
        assert_eq!(ray.count(), 17);
        let p = ray.position(ray.first, dims);
        let world = view.pixel_ray(0, 0).0;
        assert!(((world.y - 1.0) / 0.5 - p.y).abs() < 1e-9);
        assert!(((world.z - 2.0) / 4.0 - p.z).abs() < 1e-9);
    }

    #[test]
    fn without_options_the_samples_lie_on_planes_k_steps_from_the_image() {
        // Every ray's samples are t = k·step for the k whose t lies in its
        // span through the grid (within a millionth of a step), and rays
        // that miss the grid, or graze it between samples, have none.
        let (view, s) = (oblique(), sampling(false, Clipping::default(), false));
        let step = s.step;
        let mut hits = 0;
        for row in 0..16 {
            for col in 0..20 {
                let (o, d) = view.pixel_ray(col, row);
                let span = grid().span(o, d);
                let Some(ray) = s.pixel(&view, col, row) else {
                    if let Some((enter, exit)) = span {
                        assert!((enter / step).ceil() > (exit / step).floor() + 0.5);
                    }
                    continue;
                };
                hits += 1;
                let (enter, exit) = span.unwrap();
                assert_eq!(
                    (ray.first, ray.last),
                    ((enter / step).ceil() as i64, (exit / step).floor() as i64)
                );
                assert_eq!(ray.offset, 0.0);
                for k in [ray.first, ray.last] {
                    let world = o + ray.t(k) * d;
                    let index = (world - grid().origin) / grid().spacing;
                    assert!((ray.position(k, grid().dims) - index).abs().max_element() < 1e-9);
                }
            }
        }
        assert!(hits > 100, "{hits}");
        // A view beside the grid misses it.
        let View::Orthographic(o) = view else {
            unreachable!()
        };
        let beside = View::Orthographic(OrthographicView {
            centre: o.centre + DVec3::new(0.0, 100.0, 0.0),
            ..o
        });
        assert!((0..16).all(|row| (0..20).all(|col| s.pixel(&beside, col, row).is_none())));
    }

    #[test]
    fn jitter_moves_each_pixel_by_its_offset_within_the_same_interval() {
        let view = oblique();
        let (plain, jittered) = (
            sampling(false, Clipping::default(), false),
            sampling(true, Clipping::default(), false),
        );
        let mut hits = 0;
        for (col, row) in (0..16).flat_map(|row| (0..20).map(move |col| (col, row))) {
            let (Some(a), Some(b)) = (
                plain.pixel(&view, col, row),
                jittered.pixel(&view, col, row),
            ) else {
                continue;
            };
            hits += 1;
            let u = jitter::offset(col, row);
            assert_eq!(b.offset, u);
            // t = (k + u)·step: every jittered sample lies in the grid,
            // the ones before and after it do not, and the first one lies
            // within a step of the first plain one.
            let (t0, t1) = grid()
                .span(view.pixel_ray(col, row).0, view.direction())
                .unwrap();
            assert!(b.t(b.first) >= t0 - 1e-6 && b.t(b.last) <= t1 + 1e-6);
            assert!(b.t(b.first - 1) < t0 && b.t(b.last + 1) > t1);
            assert!((b.t(b.first) - a.t(a.first)).abs() < 0.4);
        }
        assert!(hits > 100);
    }

    #[test]
    fn perspective_rays_sample_only_ahead_of_the_eye() {
        // The eye inside the grid: samples start at t = 0, the eye itself.
        let g = grid();
        let bounds = (g.origin, g.origin + DVec3::new(10.0, 3.0, 6.0));
        let camera = Camera {
            view_point: Some(g.origin + DVec3::new(5.0, 1.5, 3.0)),
            look_at: Some(g.origin),
            projection: Projection::Perspective { fov_degrees: 60.0 },
            ..Camera::default()
        };
        let view = View::frame(&camera, bounds, 8, 8).unwrap();
        let s = sampling(false, Clipping::default(), true)
            .pixel(&view, 4, 4)
            .unwrap();
        assert_eq!(s.first, 0);
        let unbounded = sampling(false, Clipping::default(), false)
            .pixel(&view, 4, 4)
            .unwrap();
        assert!(unbounded.first < 0);
        assert_eq!(unbounded.last, s.last);
    }

    #[test]
    fn crops_cut_the_samples_to_the_box() {
        let view = oblique();
        let crop = (DVec3::new(-1.0, 1.5, 3.0), DVec3::new(4.0, 2.5, 5.0));
        let cropped = sampling(
            false,
            Clipping {
                crop: Some(crop),
                planes: vec![],
            },
            false,
        );
        let mut inside = 0;
        for row in 0..16 {
            for col in 0..20 {
                let Some(s) = cropped.pixel(&view, col, row) else {
                    continue;
                };
                let (o, d) = view.pixel_ray(col, row);
                for k in s.first..=s.last {
                    let p = o + s.t(k) * d;
                    assert!(p.cmpge(crop.0 - 1e-9).all() && p.cmple(crop.1 + 1e-9).all());
                    inside += 1;
                }
                for k in [s.first - 1, s.last + 1] {
                    let p = o + s.t(k) * d;
                    assert!(!(p.cmpge(crop.0).all() && p.cmple(crop.1).all()));
                }
            }
        }
        assert!(inside > 50);
    }
}
