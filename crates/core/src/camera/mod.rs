//! Stage 2 framing: where the eye is, which way the rays run and how the
//! image covers the volume.
//!
//! A camera is a view point, a view reference (the point looked at) and an
//! up vector, with the options users of VTK and ParaView expect: a
//! projection, a zoom, azimuth and elevation orbits, a fit and a box to
//! frame. As in VTK and OpenGL, screen right is `d × up` and screen up is
//! `up` made orthogonal to the view direction `d`: `right × d`.
//!
//! - **Orthographic** (the paper's): rays are parallel to the eye vector
//!   `d = (reference − view point)/|…|`, one through each pixel centre (the
//!   paper's "beam of rays sent parallel to the eye vector through the
//!   viewing plane"). The image plane passes through the view reference,
//!   the centre of the image. With [`Fit::Box`] the window is the smallest
//!   one, centred there, that covers the projection of the bounding box
//!   with square pixels: for a view along an axis of a volume centred on
//!   the reference it is exactly that face of the box. With [`Fit::Sphere`]
//!   it covers the box's bounding sphere instead (VTK's `ResetCamera` sets
//!   the parallel scale to the sphere's radius), so it does not change as
//!   the camera orbits: turntables keep their framing.
//! - **Perspective** ([`PerspectiveView`]): rays leave the eye, one through
//!   each pixel centre of an image plane one unit in front of it, the
//!   vertical field of view spanning the image's height (VTK's view angle).
//!   Without a view point the eye stands where the bounding sphere just fits
//!   the field of view (VTK's `ResetCamera`), whatever the fit.
//! - **Zoom** magnifies as `vtkCamera::Zoom` does: the orthographic window
//!   shrinks by the factor, the perspective `tan(fov/2)` likewise (VTK
//!   narrows the view angle; the eye does not move).
//! - **Azimuth and elevation** orbit the eye about the reference with VTK's
//!   conventions (`pose.rs` has the details and the signs).
//! - **Bounds**: frame this box rather than the volume's, so that a series
//!   of volumes is framed alike.
//!
//! [`Camera::default()`] is the paper's view: orthographic, on the +x axis
//! through the volume's centre looking along −x, up +z, the box fitted.

mod orthographic;
mod perspective;
mod pose;

use glam::DVec3;
pub use orthographic::OrthographicView;
pub use perspective::PerspectiveView;
use std::fmt;
use thiserror::Error;

/// A camera that cannot frame a picture.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CameraError {
    #[error("view point {0} coincides with the view reference: no view direction")]
    NoDirection(DVec3),
    #[error("up vector {up} is parallel to the view direction {direction}")]
    UpParallel { up: DVec3, direction: DVec3 },
    #[error("{0} {1} must be finite")]
    NotFinite(CameraPoint, DVec3),
    #[error("field of view {0} must lie strictly between 0 and 180 degrees")]
    FieldOfView(f64),
    #[error("zoom {0} must be a finite number greater than 0")]
    Zoom(f64),
    #[error("{0} {1} must be a finite angle in degrees")]
    Angle(Orbit, f64),
    #[error(
        "frame bounds {lo} to {hi} must be finite, ordered (low ≤ high) and not a single point"
    )]
    Bounds { lo: DVec3, hi: DVec3 },
    #[error("image size {width}x{height} must be at least 1x1 pixel")]
    EmptyImage { width: usize, height: usize },
    #[error("a {camera} camera cannot be framed as a {view} view")]
    WrongProjection {
        camera: &'static str,
        view: &'static str,
    },
}

/// The camera's points and directions, as [`CameraError::NotFinite`] names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraPoint {
    /// [`Camera::view_point`] (the eye).
    ViewPoint,
    /// [`Camera::look_at`], or the framed box's centre without one.
    ViewReference,
    /// [`Camera::up`].
    Up,
}

impl fmt::Display for CameraPoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CameraPoint::ViewPoint => "view point",
            CameraPoint::ViewReference => "view reference",
            CameraPoint::Up => "up vector",
        })
    }
}

/// The camera's orbits, as [`CameraError::Angle`] names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Orbit {
    Azimuth,
    Elevation,
}

impl fmt::Display for Orbit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Orbit::Azimuth => "azimuth",
            Orbit::Elevation => "elevation",
        })
    }
}

/// How rays leave the eye.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Projection {
    /// Parallel rays (the paper's).
    #[default]
    Orthographic,
    /// Rays from the eye; `fov_degrees` is the full vertical field of view.
    Perspective { fov_degrees: f64 },
}

/// What the orthographic window covers. (A perspective eye without a view
/// point stands where the bounding sphere fits the field of view, VTK's
/// `ResetCamera`, under either fit; an explicit view point has nothing to
/// fit.)
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Fit {
    /// The tightest window around the bounding box (the paper's framing).
    #[default]
    Box,
    /// The box's bounding sphere: the framing does not change as the
    /// camera orbits the box's centre.
    Sphere,
}

/// Where the eye is, what it looks at and which way is up (world
/// coordinates), and how the picture is taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The view point; `None`: on the +x side of the view reference (the
    /// paper's Fig. 1a), looking along −x.
    pub view_point: Option<DVec3>,
    /// The view reference; `None`: the centre of the framed box.
    pub look_at: Option<DVec3>,
    /// Up direction; default +z.
    pub up: DVec3,
    /// Orthographic (default) or perspective.
    pub projection: Projection,
    /// Magnification, > 0 (1: none).
    pub zoom: f64,
    /// Degrees the view point turns about the up vector through the view
    /// reference (`vtkCamera::Azimuth`).
    pub azimuth: f64,
    /// Degrees the view point then turns about minus screen right through
    /// the view reference, positive raising it (`vtkCamera::Elevation`).
    pub elevation: f64,
    /// What the default framing covers.
    pub fit: Fit,
    /// Frame this world box (low, high corners) instead of the volume's.
    pub bounds: Option<(DVec3, DVec3)>,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            view_point: None,
            look_at: None,
            up: DVec3::Z,
            projection: Projection::Orthographic,
            zoom: 1.0,
            azimuth: 0.0,
            elevation: 0.0,
            fit: Fit::Box,
            bounds: None,
        }
    }
}

impl Camera {
    /// Checks the settings that do not depend on the volume, naming the
    /// one that is wrong: `0 < fov < 180`, zoom finite and positive, angles
    /// finite, an explicit frame box finite, ordered and not a point.
    pub fn validate(&self) -> Result<(), CameraError> {
        if let Projection::Perspective { fov_degrees } = self.projection
            && !(fov_degrees > 0.0 && fov_degrees < 180.0)
        {
            return Err(CameraError::FieldOfView(fov_degrees));
        }
        if !(self.zoom.is_finite() && self.zoom > 0.0) {
            return Err(CameraError::Zoom(self.zoom));
        }
        for (name, angle) in [
            (Orbit::Azimuth, self.azimuth),
            (Orbit::Elevation, self.elevation),
        ] {
            if !angle.is_finite() {
                return Err(CameraError::Angle(name, angle));
            }
        }
        if let Some((lo, hi)) = self.bounds
            && !(lo.is_finite() && hi.is_finite() && lo.cmple(hi).all() && lo != hi)
        {
            return Err(CameraError::Bounds { lo, hi });
        }
        Ok(())
    }

    /// The box to frame: the camera's own, else `volume_bounds`.
    pub fn framed_bounds(&self, volume_bounds: (DVec3, DVec3)) -> (DVec3, DVec3) {
        self.bounds.unwrap_or(volume_bounds)
    }
}

pub(crate) fn check_size(width: usize, height: usize) -> Result<(), CameraError> {
    if width == 0 || height == 0 {
        return Err(CameraError::EmptyImage { width, height });
    }
    Ok(())
}

/// A framed view of either projection: what the renderers need per pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum View {
    Orthographic(OrthographicView),
    Perspective(PerspectiveView),
}

impl View {
    /// Frames `camera` on the box `bounds` (the volume's, unless the camera
    /// names its own) for a `width × height` image.
    pub fn frame(
        camera: &Camera,
        bounds: (DVec3, DVec3),
        width: usize,
        height: usize,
    ) -> Result<View, CameraError> {
        Ok(match camera.projection {
            Projection::Orthographic => {
                View::Orthographic(OrthographicView::frame(camera, bounds, width, height)?)
            }
            Projection::Perspective { .. } => {
                View::Perspective(PerspectiveView::frame(camera, bounds, width, height)?)
            }
        })
    }

    pub fn width(&self) -> usize {
        match self {
            View::Orthographic(v) => v.width,
            View::Perspective(v) => v.width,
        }
    }

    pub fn height(&self) -> usize {
        match self {
            View::Orthographic(v) => v.height,
            View::Perspective(v) => v.height,
        }
    }

    /// The central view direction (unit, from the eye into the scene), the
    /// direction a headlight shines.
    pub fn direction(&self) -> DVec3 {
        match self {
            View::Orthographic(v) => v.direction,
            View::Perspective(v) => v.direction,
        }
    }

    /// World ray through the centre of pixel (`col`, `row`), row 0 at the
    /// top: (origin, unit direction). Orthographic: the origin lies on the
    /// image plane through the view reference (`t = 0` there, samples at
    /// `t = k·step` for integer `k`, negative `k` allowed). Perspective: the
    /// origin is the eye and `t ≥ 0` is the distance from it.
    #[inline]
    pub fn pixel_ray(&self, col: usize, row: usize) -> (DVec3, DVec3) {
        match self {
            View::Orthographic(v) => (v.pixel_centre(col, row), v.direction),
            View::Perspective(v) => v.pixel_ray(col, row),
        }
    }

    /// The world size of one pixel where the view first meets the box
    /// `bounds`: an orthographic pixel's size; for a perspective view, the
    /// size of a pixel at the point of the box nearest the eye (0 with the
    /// eye inside the box). The detail a picture of the box can show: a
    /// grid whose voxels are no larger shows all of it (what `--level
    /// auto` chooses a multiscale image's level by).
    pub fn pixel_footprint(&self, bounds: (DVec3, DVec3)) -> f64 {
        match self {
            View::Orthographic(v) => v.pixel_size,
            View::Perspective(v) => {
                let nearest = v.eye.clamp(bounds.0, bounds.1);
                v.eye.distance(nearest) * v.pixel_size
            }
        }
    }

    /// Continuous image coordinates (column, row) of the world point `p`:
    /// pixel (c, r) covers `[c, c+1) × [r, r+1)`. `None` for a point on or
    /// behind the eye's plane in a perspective view.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        match self {
            View::Orthographic(v) => Some(v.project(p)),
            View::Perspective(v) => v.project(p),
        }
    }

    /// The orthographic view, for the paths that render only those.
    pub fn as_orthographic(&self) -> Option<&OrthographicView> {
        match self {
            View::Orthographic(v) => Some(v),
            View::Perspective(_) => None,
        }
    }
}
