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
    fn ortho(camera: &Camera, bounds: (DVec3, DVec3), w: usize, h: usize) -> OrthographicView {
        OrthographicView::frame(camera, bounds, w, h).unwrap()
    }

    #[test]
    fn view_frame_of_the_default_camera_is_the_orthographic_view() {
        let v = View::frame(&Camera::default(), cube(), 30, 20).unwrap();
        assert_eq!(
            v,
            View::Orthographic(ortho(&Camera::default(), cube(), 30, 20))
        );
        assert_eq!((v.width(), v.height()), (30, 20));
        assert_eq!(v.direction(), -DVec3::X);
        let (origin, dir) = v.pixel_ray(4, 5);
        assert_eq!(dir, -DVec3::X);
        let (c, r) = v.project(origin).unwrap();
        assert!((c - 4.5).abs() < 1e-9 && (r - 5.5).abs() < 1e-9);
    }

    #[test]
    fn zoom_two_halves_the_orthographic_pixel() {
        for fit in [Fit::Box, Fit::Sphere] {
            let base = Camera {
                fit,
                azimuth: 30.0,
                ..Camera::default()
            };
            let one = ortho(&base, cube(), 64, 48);
            let two = ortho(&Camera { zoom: 2.0, ..base }, cube(), 64, 48);
            assert_eq!(two.pixel_size, 0.5 * one.pixel_size);
            // Same centre and axes: the picture is magnified about its centre.
            assert_eq!(
                (two.centre, two.right, two.up),
                (one.centre, one.right, one.up)
            );
            // So the box's corner lands twice as far from the image centre.
            let (c1, _) = one.project(DVec3::new(10.0, 20.0, 40.0));
            let (c2, _) = two.project(DVec3::new(10.0, 20.0, 40.0));
            assert!(((c2 - 32.0) - 2.0 * (c1 - 32.0)).abs() < 1e-9);
        }
    }

    #[test]
    fn azimuth_90_moves_the_eye_from_plus_x_to_plus_y() {
        // vtkCamera::Azimuth(90) takes a camera at +x (up +z) to +y: the
        // rays then run along −y, screen right becomes −x.
        let v = ortho(
            &Camera {
                azimuth: 90.0,
                ..Camera::default()
            },
            cube(),
            100,
            100,
        );
        assert_eq!(v.direction, -DVec3::Y);
        assert_eq!(v.right, -DVec3::X);
        assert_eq!(v.up, DVec3::Z);
        // The x-z face, 10 × 40, fills the height.
        assert!((v.pixel_size - 0.4).abs() < 1e-12);
        // −90 goes the other way; 180 looks along +x, as the peers' view.
        let v = ortho(
            &Camera {
                azimuth: -90.0,
                ..Camera::default()
            },
            cube(),
            8,
            8,
        );
        assert_eq!(v.direction, DVec3::Y);
        let v = ortho(
            &Camera {
                azimuth: 180.0,
                ..Camera::default()
            },
            cube(),
            8,
            8,
        );
        assert_eq!((v.direction, v.right), (DVec3::X, -DVec3::Y));
    }

    #[test]
    fn elevation_90_from_plus_x_looks_straight_down() {
        let v = ortho(
            &Camera {
                elevation: 90.0,
                ..Camera::default()
            },
            cube(),
            50,
            100,
        );
        assert_eq!(v.direction, -DVec3::Z);
        // The up vector tilts with the eye: the top of the picture is the
        // way the camera looked before (−x), right stays +y.
        assert_eq!(v.up, -DVec3::X);
        assert_eq!(v.right, DVec3::Y);
        // The x-y face, 20 wide (y) over 50 px and 10 high (x) over 100 px.
        assert!((v.pixel_size - 0.4).abs() < 1e-12);
        // −90 looks straight up.
        let v = ortho(
            &Camera {
                elevation: -90.0,
                ..Camera::default()
            },
            cube(),
            8,
            8,
        );
        assert_eq!((v.direction, v.up), (DVec3::Z, DVec3::X));
    }

    #[test]
    fn a_view_along_up_is_refused_with_the_vectors_named() {
        // Up parallel to the view direction before any orbit is refused,
        // with a message that says which vectors clash.
        let cam = Camera {
            view_point: Some(DVec3::new(5.0, 10.0, 100.0)),
            azimuth: 30.0,
            elevation: 10.0,
            ..Camera::default()
        };
        let err = View::frame(&cam, cube(), 10, 10).unwrap_err();
        assert!(matches!(err, CameraError::UpParallel { .. }));
        let message = err.to_string();
        assert!(
            message.contains("up vector") && message.contains("parallel"),
            "{message}"
        );
    }

    #[test]
    fn sphere_fit_keeps_the_window_for_every_azimuth() {
        // A 10 × 20 × 40 box: the sphere's radius is √2100 / 2.
        let radius = 0.5 * 2100f64.sqrt();
        let mut box_sizes = Vec::new();
        for step in 0..24 {
            let azimuth = 15.0 * step as f64;
            let sphere = Camera {
                fit: Fit::Sphere,
                azimuth,
                elevation: 20.0,
                ..Camera::default()
            };
            let v = ortho(&sphere, cube(), 80, 60);
            assert!(
                (v.pixel_size - 2.0 * radius / 60.0).abs() < 1e-12,
                "{azimuth}"
            );
            let boxed = Camera {
                fit: Fit::Box,
                ..sphere
            };
            box_sizes.push(ortho(&boxed, cube(), 80, 60).pixel_size);
        }
        // The box fit does follow the orbit (the test would not see a
        // sphere fit that ignored the angle).
        let (min, max) = box_sizes
            .iter()
            .fold((f64::MAX, 0.0f64), |(a, b), &s| (a.min(s), b.max(s)));
        assert!(max > 1.1 * min, "{min} {max}");
    }

    #[test]
    fn camera_bounds_override_the_volume_box() {
        let framed = (DVec3::new(-1.0, -2.0, -3.0), DVec3::new(1.0, 2.0, 3.0));
        let with_bounds = |volume: (DVec3, DVec3), projection| {
            View::frame(
                &Camera {
                    bounds: Some(framed),
                    projection,
                    azimuth: 25.0,
                    ..Camera::default()
                },
                volume,
                40,
                30,
            )
            .unwrap()
        };
        for projection in [
            Projection::Orthographic,
            Projection::Perspective { fov_degrees: 40.0 },
        ] {
            // Two different volumes framed alike: exactly the view of the box itself.
            let a = with_bounds(cube(), projection);
            let b = with_bounds((DVec3::splat(7.0), DVec3::splat(9.0)), projection);
            let own = View::frame(
                &Camera {
                    projection,
                    azimuth: 25.0,
                    ..Camera::default()
                },
                framed,
                40,
                30,
            )
            .unwrap();
            assert_eq!(a, b);
            assert_eq!(a, own);
            assert_ne!(
                a,
                View::frame(
                    &Camera {
                        projection,
                        azimuth: 25.0,
                        ..Camera::default()
                    },
                    cube(),
                    40,
                    30
                )
                .unwrap()
            );
        }
    }

    #[test]
    fn invalid_settings_are_refused_by_name() {
        let refuse = |camera: Camera, needle: &str| {
            let err = View::frame(&camera, cube(), 10, 10).unwrap_err();
            let message = err.to_string();
            assert!(message.contains(needle), "{message} lacks {needle}");
        };
        for fov in [0.0, -5.0, 180.0, 200.0, f64::NAN, f64::INFINITY] {
            refuse(
                Camera {
                    projection: Projection::Perspective { fov_degrees: fov },
                    ..Camera::default()
                },
                "field of view",
            );
        }
        for zoom in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            for projection in [
                Projection::Orthographic,
                Projection::Perspective { fov_degrees: 30.0 },
            ] {
                refuse(
                    Camera {
                        zoom,
                        projection,
                        ..Camera::default()
                    },
                    "zoom",
                );
            }
        }
        refuse(
            Camera {
                azimuth: f64::NAN,
                ..Camera::default()
            },
            "azimuth",
        );
        refuse(
            Camera {
                elevation: f64::INFINITY,
                ..Camera::default()
            },
            "elevation",
        );
        for bounds in [
            (DVec3::ONE, DVec3::ZERO),
            (DVec3::ONE, DVec3::ONE),
            (DVec3::ZERO, DVec3::new(1.0, f64::NAN, 1.0)),
        ] {
            refuse(
                Camera {
                    bounds: Some(bounds),
                    ..Camera::default()
                },
                "frame bounds",
            );
        }
        let err = View::frame(&Camera::default(), cube(), 0, 10).unwrap_err();
        assert_eq!(
            err.to_string(),
            "image size 0x10 must be at least 1x1 pixel"
        );
        // A wide but valid field of view and a tiny zoom are accepted.
        for camera in [
            Camera {
                projection: Projection::Perspective { fov_degrees: 179.0 },
                ..Camera::default()
            },
            Camera {
                zoom: 1e-3,
                ..Camera::default()
            },
        ] {
            assert!(View::frame(&camera, cube(), 10, 10).is_ok());
        }
    }

    #[test]
    fn each_view_refuses_the_other_projection() {
        let perspective = Camera {
            projection: Projection::Perspective { fov_degrees: 30.0 },
            ..Camera::default()
        };
        assert!(matches!(
            OrthographicView::frame(&perspective, cube(), 10, 10),
            Err(CameraError::WrongProjection { .. })
        ));
        assert!(matches!(
            PerspectiveView::frame(&Camera::default(), cube(), 10, 10),
            Err(CameraError::WrongProjection { .. })
        ));
    }
}
