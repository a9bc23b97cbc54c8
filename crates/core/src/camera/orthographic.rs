//! Orthographic framing (the paper's): parallel rays, one through each
//! pixel centre of an image plane through the view reference.
//!
//! With [`Fit::Box`] the window is the smallest one, centred on the view
//! reference, that covers the projection of the bounding box with square
//! pixels; with [`Fit::Sphere`] it covers the box's bounding sphere (VTK's
//! parallel scale after `ResetCamera`), so that it does not change as the
//! camera orbits. The zoom shrinks the window (`vtkCamera::Zoom`).

use crate::camera::pose::Pose;
use crate::camera::{Camera, CameraError, Fit, Projection, check_size};
use glam::DVec3;

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
    /// Frames the orthographic `camera` on the box `bounds` (the volume's,
    /// unless the camera names its own) for a `width × height` image,
    /// honouring its fit, zoom and orbits.
    pub fn frame(
        camera: &Camera,
        bounds: (DVec3, DVec3),
        width: usize,
        height: usize,
    ) -> Result<Self, CameraError> {
        camera.validate()?;
        check_size(width, height)?;
        if camera.projection != Projection::Orthographic {
            return Err(CameraError::WrongProjection {
                camera: "perspective",
                view: "orthographic",
            });
        }
        let (lo, hi) = camera.framed_bounds(bounds);
        let centre = camera.look_at.unwrap_or(0.5 * (lo + hi));
        let diagonal = (hi - lo).length();
        // Any distance gives the same parallel rays; this one keeps the
        // default view point outside the volume.
        let pose = Pose::new(camera, centre, 2.0 * diagonal.max(1.0))?;
        let (right, up) = (pose.right, pose.up);

        // Half-widths of the window about the centre.
        let mut half = (0.0f64, 0.0f64);
        match camera.fit {
            Fit::Box => {
                for corner in 0..8 {
                    let p = DVec3::new(
                        if corner & 1 == 0 { lo.x } else { hi.x },
                        if corner & 2 == 0 { lo.y } else { hi.y },
                        if corner & 4 == 0 { lo.z } else { hi.z },
                    ) - centre;
                    half.0 = half.0.max(p.dot(right).abs());
                    half.1 = half.1.max(p.dot(up).abs());
                }
            }
            Fit::Sphere => {
                // The sphere's outline is a disc about the projection of
                // the box's centre.
                let radius = 0.5 * diagonal;
                let offset = 0.5 * (lo + hi) - centre;
                half = (
                    offset.dot(right).abs() + radius,
                    offset.dot(up).abs() + radius,
                );
            }
        }
        let pixel_size =
            (2.0 * half.0 / width as f64).max(2.0 * half.1 / height as f64) / camera.zoom;
        Ok(OrthographicView {
            direction: pose.direction,
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
