//! The camera options seen in rendered pictures: orbits render the view
//! from where they move the eye, zoom magnifies about the image centre, and
//! a framing box makes different volumes frame alike. Both stage-2 paths.

mod common;

use common::{both_paths, tf};
use volray_core::camera::{Camera, Fit};
use volray_core::glam::DVec3;
use volray_core::{Image, RenderSettings, Renderer, Volume};

/// Two Gaussian blobs off the centre, no symmetry, on a non-cubic grid (in
/// world units from its corner: not `common::blobs`).
fn two_blobs() -> Volume {
    let origin = DVec3::new(-1.0, 2.0, 0.5);
    Volume::from_fn([14, 11, 17], DVec3::new(0.2, 0.25, 0.15), origin, |p| {
        let u = p - origin;
        let a = (-(u - DVec3::new(0.8, 1.0, 1.5)).length_squared() / 0.3).exp();
        let b = 0.7 * (-(u - DVec3::new(2.0, 1.6, 0.7)).length_squared() / 0.1).exp();
        (a + b) as f32
    })
    .unwrap()
}

/// Renders `camera` on both paths at `w × h`: the fast image, then the
/// reference.
fn render(volume: &Volume, camera: Camera, w: usize, h: usize) -> [Image; 2] {
    let renderer = Renderer::new(volume).unwrap();
    let settings = RenderSettings {
        width: w,
        height: h,
        camera,
        transfer_function: tf(r#"{"opacity": [[0, 0], [0.2, 0], [1, 0.8]],
            "color": [[0, 0.2, 0.3, 0.9], [1, 0.9, 0.4, 0.1]]}"#),
        ..RenderSettings::default()
    };
    let (fast, reference) = both_paths(&renderer, &settings);
    [fast, reference]
}

fn lit_pixels(image: &Image) -> usize {
    image.pixels().iter().filter(|p| p[3] > 0.01).count()
}

#[test]
fn orbits_render_the_view_from_where_they_move_the_eye() {
    let volume = two_blobs();
    let (lo, hi) = volume.bounds();
    let centre = 0.5 * (lo + hi);
    // Azimuth 90 from the default +x eye: the view from +y (VTK).
    let orbited = render(
        &volume,
        Camera {
            azimuth: 90.0,
            ..Camera::default()
        },
        40,
        30,
    );
    let from_y = render(
        &volume,
        Camera {
            view_point: Some(centre + 10.0 * DVec3::Y),
            ..Camera::default()
        },
        40,
        30,
    );
    // Elevation 90: the view from +z, the picture's top towards −x.
    let raised = render(
        &volume,
        Camera {
            elevation: 90.0,
            ..Camera::default()
        },
        40,
        30,
    );
    let from_z = render(
        &volume,
        Camera {
            view_point: Some(centre + 10.0 * DVec3::Z),
            up: -DVec3::X,
            ..Camera::default()
        },
        40,
        30,
    );
    let unorbited = render(&volume, Camera::default(), 40, 30);
    for path in 0..2 {
        assert!(lit_pixels(&orbited[path]) > 50);
        assert_eq!(orbited[path], from_y[path]);
        assert_eq!(raised[path], from_z[path]);
        // The orbits did move the eye.
        assert!(orbited[path].max_abs_diff(&unorbited[path]).unwrap() > 0.1);
        assert!(raised[path].max_abs_diff(&unorbited[path]).unwrap() > 0.1);
    }
}

#[test]
fn zoom_two_is_the_centre_of_a_picture_twice_as_large() {
    // Same pixel size, same image plane, the same pixel centres: the
    // zoomed picture is the middle of the unzoomed one, sample for sample.
    let volume = two_blobs();
    let camera = Camera {
        view_point: Some(DVec3::new(9.0, -4.0, 6.0)),
        ..Camera::default()
    };
    let zoomed = render(
        &volume,
        Camera {
            zoom: 2.0,
            ..camera
        },
        32,
        24,
    );
    let large = render(&volume, camera, 64, 48);
    for path in 0..2 {
        let mut crop = Image::new(32, 24, [0.0; 4]);
        for row in 0..24 {
            for col in 0..32 {
                crop.set(col, row, large[path].get(col + 16, row + 12));
            }
        }
        assert!(lit_pixels(&crop) > 100);
        let diff = zoomed[path].max_abs_diff(&crop).unwrap();
        assert!(diff < 1e-6, "path {path}: {diff}");
    }
}

#[test]
fn a_framing_box_frames_different_volumes_alike() {
    // A volume and its copy shifted inside a common box: with the box as
    // the frame, the copy's picture is the original's shifted by whole
    // pixels.
    let volume = two_blobs();
    let (lo, hi) = volume.bounds();
    let shift = DVec3::new(0.0, 0.5, -0.5);
    let moved = volume.clone().with_origin(volume.origin() + shift).unwrap();
    // The box spans both; 8 × 8 world units over 64 px: 1/8 unit pixels.
    let frame = (
        DVec3::new(lo.x, lo.y, -4.0),
        DVec3::new(hi.x, lo.y + 8.0, 4.0),
    );
    let camera = Camera {
        bounds: Some(frame),
        fit: Fit::Box,
        ..Camera::default()
    };
    let a = render(&volume, camera, 64, 64);
    let b = render(&moved, camera, 64, 64);
    for path in 0..2 {
        // Screen right is +y, screen up +z: +0.5 in y is 4 columns right,
        // −0.5 in z is 4 rows down.
        let mut worst = 0.0f32;
        for row in 0..60 {
            for col in 0..60 {
                let (p, q) = (a[path].get(col, row), b[path].get(col + 4, row + 4));
                for c in 0..4 {
                    worst = worst.max((p[c] - q[c]).abs());
                }
            }
        }
        assert!(lit_pixels(&a[path]) > 100);
        assert!(worst < 1e-5, "path {path}: {worst}");
    }
}
