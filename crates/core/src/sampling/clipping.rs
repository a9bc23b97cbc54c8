//! Cropping and clip planes: the part of the volume that is rendered, as
//! an interval along each ray.
//!
//! A crop box is an axis-aligned world box (VTK's cropping region planes,
//! `vtkVolumeMapper::SetCroppingRegionPlanes`, in world rather than index
//! coordinates); a clip plane keeps the half-space `(p − point)·normal ≥ 0`
//! (VTK's `vtkPlane` as a clipping plane keeps the side its normal points
//! to). Both are convex, so along a ray `p(t) = o + t·d` what they keep is
//! one interval of `t`, found by the slab method (Kay & Kajiya, "Ray
//! tracing complex scenes", SIGGRAPH 1986) for the box and one bound per
//! plane. Samples outside it are skipped, exactly as samples outside the
//! volume are; the samples inside are those of the uncut volume.

use glam::DVec3;

/// A clip plane through `point`: keeps `(p − point)·normal ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipPlane {
    pub point: DVec3,
    /// Points into the kept half-space; any non-zero length.
    pub normal: DVec3,
}

impl ClipPlane {
    /// Whether world point `p` is kept.
    pub fn keeps(&self, p: DVec3) -> bool {
        (p - self.point).dot(self.normal) >= 0.0
    }
}

/// What the crop box and the clip planes of one frame keep.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Clipping {
    /// World box `(lo, hi)`, `lo < hi` on every axis.
    pub crop: Option<(DVec3, DVec3)>,
    pub planes: Vec<ClipPlane>,
}

impl Clipping {
    /// Whether anything is cut away.
    pub fn is_active(&self) -> bool {
        self.crop.is_some() || !self.planes.is_empty()
    }

    /// Whether world point `p` is kept.
    pub fn keeps(&self, p: DVec3) -> bool {
        self.crop
            .is_none_or(|(lo, hi)| p.cmpge(lo).all() && p.cmple(hi).all())
            && self.planes.iter().all(|plane| plane.keeps(p))
    }

    /// The part `(t0, t1)` of `interval` along the ray `o + t·d` that is
    /// kept, or `None` if nothing is (an interval of one point is kept).
    pub fn clip(&self, o: DVec3, d: DVec3, interval: (f64, f64)) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = interval;
        if let Some((lo, hi)) = self.crop {
            for axis in 0..3 {
                let (o, d) = (o[axis], d[axis]);
                if d == 0.0 {
                    if !(lo[axis]..=hi[axis]).contains(&o) {
                        return None;
                    }
                } else {
                    let (a, b) = ((lo[axis] - o) / d, (hi[axis] - o) / d);
                    t0 = t0.max(a.min(b));
                    t1 = t1.min(a.max(b));
                }
            }
        }
        for plane in &self.planes {
            // (o + t·d − point)·n ≥ 0  ⇔  t·(d·n) ≥ −(o − point)·n.
            let (height, rate) = ((o - plane.point).dot(plane.normal), d.dot(plane.normal));
            if rate == 0.0 {
                if height < 0.0 {
                    return None;
                }
            } else if rate > 0.0 {
                t0 = t0.max(-height / rate);
            } else {
                t1 = t1.min(-height / rate);
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// Whether the world box `(lo, hi)` may hold a kept point: `false` only
    /// if the box lies wholly outside the crop box or wholly behind a
    /// plane (a box touching the boundary counts as kept).
    pub fn may_keep_box(&self, (lo, hi): (DVec3, DVec3)) -> bool {
        if let Some((clo, chi)) = self.crop
            && (hi.cmplt(clo).any() || lo.cmpgt(chi).any())
        {
            return false;
        }
        self.planes.iter().all(|plane| {
            // The corner farthest along the normal.
            let n = plane.normal;
            let far = DVec3::select(n.cmpge(DVec3::ZERO), hi, lo);
            plane.keeps(far)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crop_box_cuts_the_ray_at_its_faces() {
        let c = Clipping {
            crop: Some((DVec3::new(-1.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 1.0))),
            planes: vec![],
        };
        // Along −x from x = 10: enters the box at x = 2 (t = 8), leaves at
        // x = −1 (t = 11).
        let o = DVec3::new(10.0, 0.5, 0.5);
        assert_eq!(c.clip(o, -DVec3::X, (-100.0, 100.0)), Some((8.0, 11.0)));
        // The given interval cuts further.
        assert_eq!(c.clip(o, -DVec3::X, (9.0, 100.0)), Some((9.0, 11.0)));
        // Parallel to a face, outside the slab: nothing is kept.
        let off = DVec3::new(10.0, 1.5, 0.5);
        assert_eq!(c.clip(off, -DVec3::X, (-100.0, 100.0)), None);
        // On the face: kept.
        let on = DVec3::new(10.0, 1.0, 0.5);
        assert!(c.clip(on, -DVec3::X, (-100.0, 100.0)).is_some());
    }

    #[test]
    fn clip_plane_keeps_the_side_its_normal_points_to() {
        let c = Clipping {
            crop: None,
            planes: vec![ClipPlane {
                point: DVec3::new(0.5, 0.0, 0.0),
                normal: DVec3::new(-2.0, 0.0, 0.0),
            }],
        };
        // Keeps x ≤ 0.5. Along −x from x = 3: from t = 2.5 on.
        let o = DVec3::new(3.0, 7.0, -4.0);
        assert_eq!(c.clip(o, -DVec3::X, (0.0, 10.0)), Some((2.5, 10.0)));
        // Along +x from x = 3 nothing is kept; from x = −3, up to x = 0.5.
        assert_eq!(c.clip(o, DVec3::X, (0.0, 10.0)), None);
        assert_eq!(c.clip(-o, DVec3::X, (0.0, 10.0)), Some((0.0, 3.5)));
        // Parallel to the plane: all or nothing.
        assert_eq!(c.clip(o, DVec3::Y, (0.0, 10.0)), None);
        assert_eq!(c.clip(-o, DVec3::Y, (0.0, 10.0)), Some((0.0, 10.0)));
        assert!(c.keeps(DVec3::new(0.5, 1.0, 1.0)) && !c.keeps(DVec3::new(0.6, 0.0, 0.0)));
    }

    #[test]
    fn the_interval_is_exactly_the_kept_points() {
        // An oblique ray through a crop box and two oblique planes: points
        // just inside the interval are kept, points just outside are not.
        let planes = vec![
            ClipPlane {
                point: DVec3::new(0.1, 0.2, 0.3),
                normal: DVec3::new(1.0, -0.5, 0.25),
            },
            ClipPlane {
                point: DVec3::new(0.4, 0.4, 0.4),
                normal: DVec3::new(-0.3, -1.0, 0.7),
            },
        ];
        let c = Clipping {
            crop: Some((DVec3::new(-0.8, -0.9, -0.7), DVec3::new(0.9, 0.8, 1.0))),
            planes,
        };
        let o = DVec3::new(-2.0, -1.5, -1.0);
        let d = DVec3::new(0.7, 0.5, 0.4).normalize();
        let (t0, t1) = c.clip(o, d, (-50.0, 50.0)).unwrap();
        assert!(t1 > t0 + 0.1);
        for t in [t0 + 1e-9, 0.5 * (t0 + t1), t1 - 1e-9] {
            assert!(c.keeps(o + t * d), "{t}");
        }
        for t in [t0 - 1e-6, t1 + 1e-6] {
            assert!(!c.keeps(o + t * d), "{t}");
        }
    }

    #[test]
    fn boxes_wholly_cut_away_are_found() {
        let c = Clipping {
            crop: Some((DVec3::splat(-1.0), DVec3::splat(1.0))),
            planes: vec![ClipPlane {
                point: DVec3::ZERO,
                normal: DVec3::new(1.0, 1.0, 0.0),
            }],
        };
        let cube = |lo: f64, hi: f64| (DVec3::splat(lo), DVec3::splat(hi));
        assert!(c.may_keep_box(cube(-0.5, 0.5)));
        assert!(!c.may_keep_box(cube(1.5, 2.0)));
        // Touching the crop box counts.
        assert!(c.may_keep_box(cube(1.0, 2.0)));
        // Wholly behind the plane x + y ≥ 0.
        assert!(!c.may_keep_box(cube(-0.9, -0.1)));
        assert!(c.may_keep_box((DVec3::new(-0.9, 0.0, 0.0), DVec3::new(-0.5, 0.6, 0.1))));
        assert!(Clipping::default().may_keep_box(cube(5.0, 6.0)));
    }
}
