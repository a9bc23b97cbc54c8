//! Stage 2 geometry: the orthographic camera and the image window.
//!
//! A camera is a view point, a view reference (the point looked at) and an
//! up vector. Rays are parallel to the eye vector `d = (reference − view
//! point)/|…|`, one through each pixel centre (the paper's "beam of rays sent
//! parallel to the eye vector through the viewing plane"). As in VTK and
//! OpenGL, screen right is `d × up` and screen up is `up` made orthogonal to
//! `d`: `right × d`.
//!
//! The image plane passes through the view reference, which is the centre of
//! the image. By default the window is the smallest one, centred there,
//! that covers the projection of the volume's bounding box with square
//! pixels; for a view along an axis of a volume centred on the reference it
//! is exactly that face of the box.

use glam::DVec3;
use thiserror::Error;

/// A camera that cannot frame a picture.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CameraError {
    #[error("view point {0} coincides with the view reference: no view direction")]
    NoDirection(DVec3),
    #[error("up vector {up} is parallel to the view direction {direction}")]
    UpParallel { up: DVec3, direction: DVec3 },
    #[error("{0} vector {1} must be finite")]
    NotFinite(&'static str, DVec3),
}

/// Where the eye is, what it looks at and which way is up (world coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The view point; `None`: on the +x axis through the view reference
    /// (the paper's Fig. 1a), looking along −x.
    pub view_point: Option<DVec3>,
    /// The view reference; `None`: the centre of the volume.
    pub look_at: Option<DVec3>,
    /// Up direction; default +z.
    pub up: DVec3,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            view_point: None,
            look_at: None,
            up: DVec3::Z,
        }
    }
}

/// A framed orthographic view: image size, screen axes and pixel size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrthographicView {
    /// Unit direction of every ray, from the eye into the scene.
    pub direction: DVec3,
    /// Unit screen axes in world space.
    pub right: DVec3,
    pub up: DVec3,
    /// The view reference: centre of the image, on the image plane.
    pub centre: DVec3,
    /// World size of one (square) pixel.
    pub pixel_size: f64,
    pub width: usize,
    pub height: usize,
}

impl OrthographicView {
    /// Frames `camera` on the bounding box `bounds` for a `width × height` image.
    pub fn frame(
        camera: &Camera,
        bounds: (DVec3, DVec3),
        width: usize,
        height: usize,
    ) -> Result<Self, CameraError> {
        let (lo, hi) = bounds;
        let centre = camera.look_at.unwrap_or(0.5 * (lo + hi));
        let diagonal = (hi - lo).length();
        let view_point = camera
            .view_point
            .unwrap_or(centre + DVec3::X * 2.0 * diagonal.max(1.0));
        for (name, v) in [
            ("view point", view_point),
            ("view reference", centre),
            ("up", camera.up),
        ] {
            if !v.is_finite() {
                return Err(CameraError::NotFinite(name, v));
            }
        }
        // Divide by the length (rather than multiply by its reciprocal) so
        // that axis-aligned views get exactly axis-aligned rays.
        let towards = centre - view_point;
        let distance = towards.length();
        if distance == 0.0 || !distance.is_finite() {
            return Err(CameraError::NoDirection(view_point));
        }
        let direction = towards / distance;
        let right = direction
            .cross(camera.up)
            .try_normalize()
            .filter(|r| r.cross(direction).length() > 1e-9)
            .ok_or(CameraError::UpParallel {
                up: camera.up,
                direction,
            })?;
        let up = right.cross(direction);

        // Half-widths of the bounding box's projection, about the centre.
        let mut half = (0.0f64, 0.0f64);
        for corner in 0..8 {
            let p = DVec3::new(
                if corner & 1 == 0 { lo.x } else { hi.x },
                if corner & 2 == 0 { lo.y } else { hi.y },
                if corner & 4 == 0 { lo.z } else { hi.z },
            ) - centre;
            half.0 = half.0.max(p.dot(right).abs());
            half.1 = half.1.max(p.dot(up).abs());
        }
        let pixel_size = (2.0 * half.0 / width as f64).max(2.0 * half.1 / height as f64);
        Ok(OrthographicView {
            direction,
            right,
            up,
            centre,
            pixel_size,
            width,
            height,
        })
    }

    /// World position of the centre of pixel (`col`, `row`), row 0 at the top,
    /// on the image plane (through the view reference, normal to the rays).
    #[inline]
    pub fn pixel_centre(&self, col: usize, row: usize) -> DVec3 {
        let u = (col as f64 + 0.5 - 0.5 * self.width as f64) * self.pixel_size;
        let v = (row as f64 + 0.5 - 0.5 * self.height as f64) * self.pixel_size;
        self.centre + u * self.right - v * self.up
    }

    /// Continuous image coordinates (column, row) where the ray through the
    /// world point `p` crosses the image: pixel (c, r) covers
    /// `[c, c+1) × [r, r+1)`.
    pub fn project(&self, p: DVec3) -> (f64, f64) {
        let d = p - self.centre;
        (
            d.dot(self.right) / self.pixel_size + 0.5 * self.width as f64,
            -d.dot(self.up) / self.pixel_size + 0.5 * self.height as f64,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> (DVec3, DVec3) {
        (DVec3::ZERO, DVec3::new(10.0, 20.0, 40.0))
    }

    #[test]
    fn default_view_looks_down_minus_x_with_z_up() {
        let v = OrthographicView::frame(&Camera::default(), cube(), 100, 100).unwrap();
        assert_eq!(v.direction, -DVec3::X);
        // right = d × up = (−x) × z = +y; screen up = right × d = +z.
        assert!((v.right - DVec3::Y).length() < 1e-12);
        assert!((v.up - DVec3::Z).length() < 1e-12);
        assert_eq!(v.centre, DVec3::new(5.0, 10.0, 20.0));
        // The y-z face is 20 × 40: 40 world units over 100 pixels.
        assert!((v.pixel_size - 0.4).abs() < 1e-12);
    }

    #[test]
    fn view_along_plus_x_has_minus_y_right() {
        let cam = Camera {
            view_point: Some(DVec3::new(-100.0, 10.0, 20.0)),
            ..Camera::default()
        };
        let v = OrthographicView::frame(&cam, cube(), 50, 100).unwrap();
        assert!((v.right + DVec3::Y).length() < 1e-12);
        // The window fits both 20 (width, 50 px) and 40 (height, 100 px).
        assert!((v.pixel_size - 0.4).abs() < 1e-12);
    }

    #[test]
    fn window_covers_the_face_exactly() {
        let v = OrthographicView::frame(&Camera::default(), cube(), 64, 128).unwrap();
        // Corners of the y-z face land on the image's corners.
        let (c, r) = v.project(DVec3::new(0.0, 0.0, 40.0));
        assert!(c.abs() < 1e-9 && r.abs() < 1e-9, "{c} {r}");
        let (c, r) = v.project(DVec3::new(10.0, 20.0, 0.0));
        assert!(
            (c - 64.0).abs() < 1e-9 && (r - 128.0).abs() < 1e-9,
            "{c} {r}"
        );
        // Pixel centres project back to themselves.
        let (c, r) = v.project(v.pixel_centre(3, 7));
        assert!((c - 3.5).abs() < 1e-9 && (r - 7.5).abs() < 1e-9);
    }

    #[test]
    fn oblique_window_covers_every_corner() {
        let cam = Camera {
            view_point: Some(DVec3::new(150.0, 150.0, 500.0)),
            look_at: Some(DVec3::new(5.0, 10.0, 20.0)),
            ..Camera::default()
        };
        let v = OrthographicView::frame(&cam, cube(), 80, 60).unwrap();
        let mut touches = 0;
        for corner in 0..8 {
            let p = DVec3::new(
                if corner & 1 == 0 { 0.0 } else { 10.0 },
                if corner & 2 == 0 { 0.0 } else { 20.0 },
                if corner & 4 == 0 { 0.0 } else { 40.0 },
            );
            let (c, r) = v.project(p);
            assert!((-1e-9..=80.0 + 1e-9).contains(&c) && (-1e-9..=60.0 + 1e-9).contains(&r));
            if c.abs() < 1e-9
                || (c - 80.0).abs() < 1e-9
                || r.abs() < 1e-9
                || (r - 60.0).abs() < 1e-9
            {
                touches += 1;
            }
        }
        assert!(touches >= 2, "the window must be tight");
    }

    #[test]
    fn degenerate_cameras_are_refused() {
        let cam = Camera {
            view_point: Some(DVec3::new(5.0, 10.0, 20.0)),
            ..Camera::default()
        };
        assert!(matches!(
            OrthographicView::frame(&cam, cube(), 10, 10),
            Err(CameraError::NoDirection(_))
        ));
        let cam = Camera {
            view_point: Some(DVec3::new(5.0, 10.0, 100.0)),
            ..Camera::default()
        };
        assert!(matches!(
            OrthographicView::frame(&cam, cube(), 10, 10),
            Err(CameraError::UpParallel { .. })
        ));
    }
}
