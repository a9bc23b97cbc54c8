//! Where the camera stands and which way it faces: the view point, the view
//! reference and the screen axes, after the camera's azimuth and elevation
//! orbits. Both projections ([`OrthographicView`](crate::camera::OrthographicView)
//! and [`PerspectiveView`](crate::camera::PerspectiveView)) start from here.
//!
//! The orbits follow VTK's `vtkCamera` (checked against VTK 9.7.2):
//!
//! - `Azimuth(θ)` rotates the view point by θ about the view-up vector,
//!   centred at the focal point (our view reference). Rotations are
//!   right-handed (`vtkTransform::RotateWXYZ`), so from the default view
//!   point on +x with up +z, azimuth 90 moves the eye to +y.
//! - `Elevation(θ)` then rotates the view point by θ about the cross product
//!   of the view-plane normal (reference → eye) and the view-up vector,
//!   centred at the focal point: that axis is minus screen right, so a
//!   positive elevation raises the eye (elevation 90 from +x looks straight
//!   down −z).
//!
//! VTK's `Elevation` computes the new view transform with the view-up vector
//! rotated along with the eye (it restores the stored view-up afterwards,
//! which is why VTK scripts follow it with `OrthogonalizeViewUp`). We do the
//! same: the up vector tilts with the elevation, so the whole orbit is one
//! rotation of the camera about the reference, screen axes included, and an
//! elevation of ±90° is a well-defined view down (or up) the up axis rather
//! than a degenerate one. Angles that are whole multiples of 90° use exact
//! sines and cosines, so quarter-turn orbits of an axis-aligned view stay
//! exactly axis-aligned.

use crate::camera::{Camera, CameraError, CameraPoint};
use glam::DVec3;

/// A camera placed in the world: eye, reference and unit screen axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The view point (after the orbits).
    pub eye: DVec3,
    /// The view reference: the point looked at.
    pub reference: DVec3,
    /// Unit vector from the eye towards the reference.
    pub direction: DVec3,
    /// Unit screen right, `direction × up` (as in VTK and OpenGL).
    pub right: DVec3,
    /// Unit screen up: the up vector made orthogonal, `right × direction`.
    pub up: DVec3,
    /// Distance from the eye to the reference.
    pub distance: f64,
}

impl Pose {
    /// Places `camera` looking at `reference`; a camera without a view point
    /// stands `default_distance` from the reference on its +x side. Then
    /// applies the camera's azimuth and elevation.
    pub fn new(
        camera: &Camera,
        reference: DVec3,
        default_distance: f64,
    ) -> Result<Pose, CameraError> {
        let view_point = camera
            .view_point
            .unwrap_or(reference + DVec3::X * default_distance);
        for (name, v) in [
            (CameraPoint::ViewPoint, view_point),
            (CameraPoint::ViewReference, reference),
            (CameraPoint::Up, camera.up),
        ] {
            if !v.is_finite() {
                return Err(CameraError::NotFinite(name, v));
            }
        }
        let pose = Pose::facing(view_point, reference, camera.up)?;
        if camera.azimuth == 0.0 && camera.elevation == 0.0 {
            return Ok(pose);
        }
        let (offset, up) = orbit(
            view_point - reference,
            camera.up,
            camera.azimuth,
            camera.elevation,
        );
        Pose::facing(reference + offset, reference, up)
    }

    /// The pose of an eye at `eye` looking at `reference` with `up` up.
    fn facing(eye: DVec3, reference: DVec3, up: DVec3) -> Result<Pose, CameraError> {
        // Divide by the length (rather than multiply by its reciprocal) so
        // that axis-aligned views get exactly axis-aligned rays.
        let towards = reference - eye;
        let distance = towards.length();
        if distance == 0.0 || !distance.is_finite() {
            return Err(CameraError::NoDirection(eye));
        }
        let direction = towards / distance;
        let right = direction
            .cross(up)
            .try_normalize()
            .filter(|r| r.cross(direction).length() > 1e-9)
            .ok_or(CameraError::UpParallel { up, direction })?;
        let screen_up = right.cross(direction);
        Ok(Pose {
            eye,
            reference,
            direction,
            right,
            up: screen_up,
            distance,
        })
    }
}

/// VTK's `Azimuth(azimuth)` then `Elevation(elevation)` (degrees) of the
/// eye at `offset` from the reference, with the up vector tilted by the
/// elevation (see the module notes). Returns the new offset and up vector.
/// `offset` must not be parallel to `up` (the caller has framed it).
pub fn orbit(offset: DVec3, up: DVec3, azimuth: f64, elevation: f64) -> (DVec3, DVec3) {
    let offset = rotate(offset, unit(up), azimuth);
    // View-plane normal × view-up, the axis of vtkCamera::Elevation.
    let axis = unit(offset.cross(up));
    (rotate(offset, axis, elevation), rotate(up, axis, elevation))
}

/// `v` rotated by `degrees` about the unit `axis`, right-handed (Rodrigues'
/// formula, the rotation `vtkTransform::RotateWXYZ` makes).
pub fn rotate(v: DVec3, axis: DVec3, degrees: f64) -> DVec3 {
    let (sin, cos) = sin_cos_degrees(degrees);
    v * cos + axis.cross(v) * sin + axis * (axis.dot(v) * (1.0 - cos))
}

/// Sine and cosine of an angle in degrees, exact at whole quarter turns.
fn sin_cos_degrees(degrees: f64) -> (f64, f64) {
    let reduced = degrees.rem_euclid(360.0);
    if reduced == 0.0 {
        (0.0, 1.0)
    } else if reduced == 90.0 {
        (1.0, 0.0)
    } else if reduced == 180.0 {
        (0.0, -1.0)
    } else if reduced == 270.0 {
        (-1.0, 0.0)
    } else {
        reduced.to_radians().sin_cos()
    }
}

/// `v` divided by its length (exact for vectors along an axis).
fn unit(v: DVec3) -> DVec3 {
    v / v.length()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn quarter_turns_are_exact() {
        for (deg, want) in [
            (0.0, (0.0, 1.0)),
            (90.0, (1.0, 0.0)),
            (-270.0, (1.0, 0.0)),
            (180.0, (0.0, -1.0)),
            (-90.0, (-1.0, 0.0)),
            (720.0, (0.0, 1.0)),
        ] {
            assert_eq!(sin_cos_degrees(deg), want, "{deg}");
        }
        let (s, c) = sin_cos_degrees(30.0);
        assert!((s - 0.5).abs() < 1e-15 && (c - 0.75f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn rotation_is_right_handed() {
        // +90° about +z takes +x to +y, +y to −x.
        assert_eq!(rotate(DVec3::X, DVec3::Z, 90.0), DVec3::Y);
        assert_eq!(rotate(DVec3::Y, DVec3::Z, 90.0), -DVec3::X);
        // The axis is fixed; lengths are kept.
        let axis = DVec3::new(1.0, 2.0, 2.0) / 3.0;
        assert!(close(rotate(axis, axis, 37.0), axis));
        let v = DVec3::new(0.3, -1.2, 2.5);
        assert!((rotate(v, axis, 37.0).length() - v.length()).abs() < 1e-12);
        // Three turns of 120° about the diagonal cycle the axes.
        let d = DVec3::ONE / 3f64.sqrt();
        assert!(close(rotate(DVec3::X, d, 120.0), DVec3::Y));
    }

    /// Positions and orthogonalised view-ups that VTK 9.7.2 gives for a
    /// camera at (1, 0, 0) looking at the origin (`vtkCamera::Azimuth`,
    /// `Elevation`, then `OrthogonalizeViewUp`).
    #[test]
    fn orbits_match_vtk() {
        let cases = [
            // (view up, azimuth, elevation, position, orthogonal view up)
            (
                DVec3::Z,
                40.0,
                25.0,
                DVec3::new(0.6942720440148838, 0.5825634160695854, 0.4226182617406995),
                DVec3::new(
                    -0.32374437096706465,
                    -0.27165378227418446,
                    0.9063077870366499,
                ),
            ),
            (
                DVec3::new(0.3, 0.2, 1.0),
                40.0,
                25.0,
                DVec3::new(0.7379293986859771, 0.5654496307095438, 0.36841134304659107),
                DVec3::new(
                    -0.2742117928208694,
                    -0.24758687284345213,
                    0.9292516521769358,
                ),
            ),
            (
                DVec3::Z,
                0.0,
                30.0,
                DVec3::new(0.8660254037844387, 0.0, 0.5),
                DVec3::new(-0.5, 0.0, 0.8660254037844387),
            ),
        ];
        for (up, azimuth, elevation, position, view_up) in cases {
            let camera = Camera {
                view_point: Some(DVec3::X),
                look_at: Some(DVec3::ZERO),
                up,
                azimuth,
                elevation,
                ..Camera::default()
            };
            let pose = Pose::new(&camera, DVec3::ZERO, 1.0).unwrap();
            assert!(close(pose.eye, position), "{:?} vs {position}", pose.eye);
            assert!(close(pose.up, view_up), "{:?} vs {view_up}", pose.up);
            assert!(close(pose.direction, -position));
        }
    }

    #[test]
    fn the_frame_stays_orthonormal_and_the_distance_is_kept() {
        let camera = Camera {
            view_point: Some(DVec3::new(3.0, -1.0, 2.0)),
            up: DVec3::new(0.1, 0.2, 1.0),
            azimuth: 123.0,
            elevation: -71.0,
            ..Camera::default()
        };
        let reference = DVec3::new(0.5, 0.25, -1.0);
        let pose = Pose::new(&camera, reference, 1.0).unwrap();
        let before = (DVec3::new(3.0, -1.0, 2.0) - reference).length();
        assert!((pose.distance - before).abs() < 1e-12);
        assert!((pose.eye + pose.distance * pose.direction - reference).length() < 1e-12);
        for (a, b) in [
            (pose.right, pose.up),
            (pose.up, pose.direction),
            (pose.direction, pose.right),
        ] {
            assert!(a.dot(b).abs() < 1e-12);
            assert!((a.length() - 1.0).abs() < 1e-12);
        }
        assert!(close(pose.direction.cross(pose.up), pose.right));
    }
}
