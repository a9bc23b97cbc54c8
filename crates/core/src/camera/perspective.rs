//! Perspective framing: rays leave the eye and fan out through the pixels.
//!
//! The image plane lies one unit in front of the eye, normal to the central
//! view direction `d`; pixels are square and the image's height spans the
//! vertical field of view, so a pixel is `2·tan(fov/2)/(zoom·height)` units
//! of that plane (VTK's view angle is vertical too, and `vtkCamera::Zoom`
//! narrows it: `tan(fov/2)` shrinks by the zoom). The ray through pixel
//! (col, row) leaves the eye along `d + u·right − v·up`, normalised, where
//! (u, v) is the pixel centre on that plane; `t` along it is the distance
//! from the eye.
//!
//! Without a view point the eye stands on the +x side of the view reference
//! (after the orbits) at `d = r / sin(θ/2)` from it, where `r` is the
//! radius of the framed box's bounding sphere and θ the narrower of the
//! vertical and horizontal fields of view: the sphere just fits the picture,
//! as VTK's `vtkRenderer::ResetCamera` places it. The distance is measured
//! from the view reference, so with the default one (the box's centre) the
//! framing does not change as the camera orbits.

use crate::camera::pose::Pose;
use crate::camera::{Camera, CameraError, Projection, check_size};
use glam::DVec3;

/// A framed perspective view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerspectiveView {
    /// Where every ray starts.
    pub eye: DVec3,
    /// Unit central view direction, from the eye towards the reference.
    pub direction: DVec3,
    /// Unit screen axes in world space.
    pub right: DVec3,
    pub up: DVec3,
    /// The view reference, seen at the centre of the image.
    pub reference: DVec3,
    /// Size of one (square) pixel on the image plane one unit in front of
    /// the eye: `2·tan(fov/2)/(zoom·height)`.
    pub pixel_size: f64,
    pub width: usize,
    pub height: usize,
}

impl PerspectiveView {
    /// Frames the perspective `camera` on the box `bounds` (the volume's,
    /// unless the camera names its own) for a `width × height` image.
    pub fn frame(
        camera: &Camera,
        bounds: (DVec3, DVec3),
        width: usize,
        height: usize,
    ) -> Result<Self, CameraError> {
        camera.validate()?;
        check_size(width, height)?;
        let Projection::Perspective { fov_degrees } = camera.projection else {
            return Err(CameraError::WrongProjection {
                camera: "orthographic",
                view: "perspective",
            });
        };
        let (lo, hi) = camera.framed_bounds(bounds);
        let reference = camera.look_at.unwrap_or(0.5 * (lo + hi));
        let radius = 0.5 * (hi - lo).length();
        let tan_half = (0.5 * fov_degrees).to_radians().tan();
        // The narrower half-angle: the horizontal one in a portrait image
        // (as ResetCamera does for a vertical view angle).
        let aspect = width as f64 / height as f64;
        let half_angle = (tan_half * aspect.min(1.0)).atan();
        let pose = Pose::new(camera, reference, radius / half_angle.sin())?;
        Ok(PerspectiveView {
            eye: pose.eye,
            direction: pose.direction,
            right: pose.right,
            up: pose.up,
            reference,
            pixel_size: 2.0 * tan_half / camera.zoom / height as f64,
            width,
            height,
        })
    }

    /// The ray through the centre of pixel (`col`, `row`), row 0 at the
    /// top: (the eye, unit direction).
    #[inline]
    pub fn pixel_ray(&self, col: usize, row: usize) -> (DVec3, DVec3) {
        let u = (col as f64 + 0.5 - 0.5 * self.width as f64) * self.pixel_size;
        let v = (row as f64 + 0.5 - 0.5 * self.height as f64) * self.pixel_size;
        let through = self.direction + u * self.right - v * self.up;
        (self.eye, through / through.length())
    }

    /// Continuous image coordinates (column, row) where the ray to the
    /// world point `p` crosses the image; `None` for points on or behind
    /// the plane of the eye.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let q = p - self.eye;
        let depth = q.dot(self.direction);
        (depth > 0.0).then(|| {
            (
                q.dot(self.right) / depth / self.pixel_size + 0.5 * self.width as f64,
                -q.dot(self.up) / depth / self.pixel_size + 0.5 * self.height as f64,
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Fit, View};

    fn cube() -> (DVec3, DVec3) {
        (DVec3::ZERO, DVec3::new(10.0, 20.0, 40.0))
    }

    fn perspective(fov_degrees: f64) -> Camera {
        Camera {
            projection: Projection::Perspective { fov_degrees },
            ..Camera::default()
        }
    }

    fn frame(camera: &Camera, w: usize, h: usize) -> PerspectiveView {
        PerspectiveView::frame(camera, cube(), w, h).unwrap()
    }

    #[test]
    fn a_near_segment_looks_larger_than_an_equal_far_one() {
        let v = frame(&perspective(40.0), 64, 64);
        // Two segments of length 6 along screen right (y), 15 in front of
        // and 15 behind the reference, which lies on the view axis.
        let length = |x: f64| {
            let a = v.project(DVec3::new(x, 7.0, 20.0)).unwrap();
            let b = v.project(DVec3::new(x, 13.0, 20.0)).unwrap();
            (b.0 - a.0).hypot(b.1 - a.1)
        };
        let (near, far) = (length(20.0), length(-10.0));
        let eye = v.eye.x;
        // Pinhole projection: the image length is inversely proportional to
        // the depth.
        let depth = |x: f64| eye - x;
        assert!(near > 1.4 * far, "{near} {far}");
        assert!((near / far - depth(-10.0) / depth(20.0)).abs() < 1e-9);
        assert!((near - 6.0 / depth(20.0) / v.pixel_size).abs() < 1e-9);
        // The orthographic view of the same segments shows them alike.
        let ortho = View::frame(&Camera::default(), cube(), 64, 64).unwrap();
        let length = |x: f64| {
            let a = ortho.project(DVec3::new(x, 7.0, 20.0)).unwrap();
            let b = ortho.project(DVec3::new(x, 13.0, 20.0)).unwrap();
            (b.0 - a.0).hypot(b.1 - a.1)
        };
        assert!((length(20.0) - length(-10.0)).abs() < 1e-9);
    }

    #[test]
    fn pixel_rays_leave_the_eye_and_the_centre_ray_hits_the_reference() {
        let camera = Camera {
            azimuth: 33.0,
            elevation: -12.0,
            ..perspective(50.0)
        };
        let v = frame(&camera, 31, 21);
        let view = View::Perspective(v);
        for (col, row) in [(0, 0), (30, 0), (0, 20), (30, 20), (7, 13)] {
            let (origin, dir) = view.pixel_ray(col, row);
            assert_eq!(origin, v.eye);
            assert!((dir.length() - 1.0).abs() < 1e-12);
            // Any point along the ray projects to the pixel's centre.
            for t in [0.5, 40.0, 300.0] {
                let (c, r) = view.project(origin + t * dir).unwrap();
                assert!((c - (col as f64 + 0.5)).abs() < 1e-9, "{c} {col}");
                assert!((r - (row as f64 + 0.5)).abs() < 1e-9, "{r} {row}");
            }
        }
        let (eye, dir) = view.pixel_ray(15, 10);
        assert!((dir - v.direction).length() < 1e-15);
        let distance = (v.reference - eye).length();
        assert!((eye + distance * dir - v.reference).length() < 1e-9);
        assert_eq!(v.reference, DVec3::new(5.0, 10.0, 20.0));
    }

    #[test]
    fn the_image_height_spans_the_vertical_field_of_view_and_zoom_narrows_it() {
        let fov: f64 = 50.0;
        let tan_half = (0.5 * fov).to_radians().tan();
        for zoom in [1.0, 2.0] {
            let v = frame(
                &Camera {
                    zoom,
                    ..perspective(fov)
                },
                40,
                30,
            );
            // A point at tan(fov/2)/zoom above the axis, one unit out,
            // lies on the top edge; to the right it lies at 30/2 pixel
            // heights from the centre (square pixels).
            let top = v
                .project(v.eye + v.direction + tan_half / zoom * v.up)
                .unwrap();
            assert!((top.0 - 20.0).abs() < 1e-9 && top.1.abs() < 1e-9, "{top:?}");
            let side = v
                .project(v.eye + 7.0 * (v.direction + tan_half / zoom * v.right))
                .unwrap();
            assert!((side.0 - 35.0).abs() < 1e-9 && (side.1 - 15.0).abs() < 1e-9);
        }
        let one = frame(&perspective(fov), 40, 30);
        let two = frame(
            &Camera {
                zoom: 2.0,
                ..perspective(fov)
            },
            40,
            30,
        );
        assert_eq!(two.pixel_size, 0.5 * one.pixel_size);
        // Zoom narrows the angle; the eye stays where it was (VTK).
        assert_eq!(two.eye, one.eye);
    }

    /// Distances `vtkRenderer::ResetCamera(0, 10, 0, 20, 0, 40)` gives with a
    /// 30° view angle (VTK 9.7.2): square viewport and a 100 × 200 one.
    #[test]
    fn the_default_eye_stands_where_vtk_resets_it() {
        let v = frame(&perspective(30.0), 64, 64);
        assert!(((v.eye - v.reference).length() - 88.52856429364843).abs() < 1e-9);
        assert_eq!(v.direction, -DVec3::X);
        let v = frame(&perspective(30.0), 100, 200);
        assert!(((v.eye - v.reference).length() - 172.5520987515903).abs() < 1e-9);
        // A landscape image keeps the vertical angle's distance.
        let v = frame(&perspective(30.0), 200, 100);
        assert!(((v.eye - v.reference).length() - 88.52856429364843).abs() < 1e-9);
    }

    #[test]
    fn the_whole_box_is_in_the_picture_from_every_side() {
        for (w, h) in [(64, 64), (40, 90), (90, 40)] {
            for step in 0..12 {
                let camera = Camera {
                    azimuth: 30.0 * step as f64,
                    elevation: 15.0 * step as f64 - 80.0,
                    fit: Fit::Sphere,
                    ..perspective(35.0)
                };
                let v = frame(&camera, w, h);
                for corner in 0..8 {
                    let p = DVec3::new(
                        if corner & 1 == 0 { 0.0 } else { 10.0 },
                        if corner & 2 == 0 { 0.0 } else { 20.0 },
                        if corner & 4 == 0 { 0.0 } else { 40.0 },
                    );
                    let (c, r) = v.project(p).unwrap();
                    assert!((0.0..=w as f64).contains(&c) && (0.0..=h as f64).contains(&r));
                }
            }
        }
    }

    #[test]
    fn orbits_keep_the_distance_and_azimuth_90_looks_from_plus_y() {
        let base = frame(&perspective(30.0), 32, 32);
        let v = frame(
            &Camera {
                azimuth: 90.0,
                ..perspective(30.0)
            },
            32,
            32,
        );
        let d = (base.eye - base.reference).length();
        assert_eq!(v.direction, -DVec3::Y);
        assert!((v.eye - (v.reference + d * DVec3::Y)).length() < 1e-12);
    }

    #[test]
    fn points_behind_the_eye_do_not_project() {
        let v = frame(&perspective(30.0), 16, 16);
        assert!(v.project(v.eye - v.direction).is_none());
        assert!(v.project(v.eye + v.right).is_none());
        assert!(v.project(v.eye + 1e-3 * v.direction).is_some());
    }
}
