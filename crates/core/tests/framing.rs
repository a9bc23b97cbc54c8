//! How a camera frames the volume's box: the screen axes and window of
//! the default view and of views from anywhere, orbits, zoom, fits and an
//! explicit frame box, and the settings refused by name.

use volray_core::camera::{
    Camera, CameraError, Fit, OrthographicView, PerspectiveView, Projection, View,
};
use volray_core::glam::DVec3;

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
        if c.abs() < 1e-9 || (c - 80.0).abs() < 1e-9 || r.abs() < 1e-9 || (r - 60.0).abs() < 1e-9 {
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
