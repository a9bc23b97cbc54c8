//! Perspective views on the bricked fast path, held to the reference path
//! (the oracle) within 1/255 per channel: several fields of view, the eye
//! outside near the volume, inside it and on brick faces and corners,
//! oblique orbits, crop boxes, clip planes and jitter, steps of 0.5 and 1,
//! anisotropic spacing; opaque plates whose picture depends on the order
//! the bricks are composited in; and thread invariance.

mod common;

use common::{
    assert_matches, assert_within_a_level, both_paths, looking, on_brick_boundaries, perspective,
    render_on_threads, scattered_voxels, sparse_tf, tf,
};
use volray_core::camera::{Camera, View};
use volray_core::glam::DVec3;
use volray_core::{ClipPlane, FrameRequest, Image, Render, RenderSettings, Renderer, Volume};

/// The fewest pixels of opacity above 0.2 the reference must show for a
/// comparison to count.
const SHOWN: usize = 4;

/// `common::blobs` on `dims` points of `spacing` from the world origin.
fn blobs(dims: [usize; 3], spacing: DVec3) -> Volume {
    common::blobs(dims, spacing, DVec3::ZERO)
}

/// The world point at index-space position `i` of `volume`.
fn at_index(volume: &Volume, i: DVec3) -> DVec3 {
    volume.origin() + i * volume.spacing()
}

/// The cameras every volume is seen through: the default eye (the bounding
/// sphere fills the view) at several fields of view, oblique orbits (one
/// zoomed, so that only part of the volume is in view), the eye just
/// outside a face and near a corner with a wide view, and the eye inside
/// the volume (at its centre, off centre, exactly on a brick corner, on a
/// brick face), looking along an axis and obliquely.
fn cameras(volume: &Volume) -> Vec<(String, Camera)> {
    let c = volume.centre();
    let (lo, hi) = volume.bounds();
    let index = |x: f64, y: f64, z: f64| at_index(volume, DVec3::new(x, y, z));
    let mut cameras = Vec::new();
    for fov in [10.0, 30.0, 60.0, 120.0] {
        cameras.push((format!("default eye, fov {fov}"), perspective(fov)));
    }
    for (azimuth, elevation) in [(37.0, 21.0), (-115.0, -48.0), (200.0, 75.0)] {
        cameras.push((
            format!("orbit {azimuth},{elevation}"),
            Camera {
                azimuth,
                elevation,
                ..perspective(40.0)
            },
        ));
    }
    cameras.push((
        "zoom 2.5, orbit 70,-30".into(),
        Camera {
            zoom: 2.5,
            azimuth: 70.0,
            elevation: -30.0,
            ..perspective(45.0)
        },
    ));
    let just_outside = DVec3::new(hi.x + 0.3 * volume.spacing().x, c.y + 0.1, c.z - 0.2);
    cameras.push((
        "eye just outside the +x face".into(),
        looking(just_outside, c, 90.0),
    ));
    cameras.push((
        "eye near the low corner".into(),
        looking(lo - 0.05 * (hi - lo), c + DVec3::new(0.3, -0.2, 0.1), 70.0),
    ));
    cameras.push((
        "eye at the centre, along -x".into(),
        looking(c, c - DVec3::X, 80.0),
    ));
    cameras.push((
        "eye inside, oblique".into(),
        looking(index(13.3, 6.1, 9.7), index(30.0, 14.0, 2.0), 60.0),
    ));
    cameras.push((
        "eye on a brick corner".into(),
        looking(index(8.0, 8.0, 8.0), index(30.0, 3.0, 13.0), 100.0),
    ));
    cameras.push((
        "eye on a brick face, looking back".into(),
        looking(index(16.0, 5.5, 6.5), index(2.0, 9.0, 9.0), 75.0),
    ));
    cameras
}

fn base_settings(camera: Camera, step: f64) -> RenderSettings {
    RenderSettings {
        width: 37,
        height: 29,
        camera,
        step,
        transfer_function: sparse_tf(),
        background: [0.1, 0.1, 0.3],
        ..RenderSettings::default()
    }
}

#[test]
fn perspective_views_of_features_on_brick_boundaries_match_the_reference() {
    let volume = on_brick_boundaries([41, 17, 17], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    let mut worst = 0.0f32;
    for (what, camera) in cameras(&volume) {
        for step in [1.0, 0.5] {
            let settings = base_settings(camera, step);
            let what = format!("{what}, step {step}");
            worst = worst.max(assert_matches(&renderer, &settings, &what, SHOWN));
        }
    }
    println!("largest fast-vs-reference difference: {worst:.6}");
}

#[test]
fn anisotropic_grids_in_perspective_match_the_reference() {
    // Cells 0.5 × 1.25 × 0.8: the bricks are boxes of unequal sides, the
    // Voronoi cells of a rectangular lattice of sites.
    for volume in [
        on_brick_boundaries([41, 17, 17], DVec3::new(0.5, 1.25, 0.8)),
        blobs([37, 26, 45], DVec3::new(1.0, 2.0, 0.6)),
    ] {
        let renderer = Renderer::new(&volume).unwrap();
        for (what, camera) in cameras(&volume) {
            for step in [1.0, 0.5] {
                let settings = RenderSettings {
                    width: 31,
                    height: 40,
                    ..base_settings(camera, step)
                };
                let what = format!("{:?}: {what}, step {step}", volume.dims());
                assert_matches(&renderer, &settings, &what, SHOWN);
            }
        }
    }
}

#[test]
fn crops_clip_planes_and_jitter_in_perspective_match_the_reference() {
    let volume = blobs([37, 26, 45], DVec3::new(1.0, 2.0, 0.6));
    let renderer = Renderer::new(&volume).unwrap();
    let c = volume.centre();
    let (lo, hi) = volume.bounds();
    let crop = (
        lo + 0.2 * (hi - lo),
        lo + DVec3::new(0.85, 0.7, 0.9) * (hi - lo),
    );
    let planes = vec![
        ClipPlane {
            point: c,
            normal: DVec3::new(1.0, 0.4, -0.3),
        },
        ClipPlane {
            point: c + DVec3::new(0.0, 0.0, 6.0),
            normal: DVec3::new(0.0, -0.2, -1.0),
        },
    ];
    let cut = |crop, clip_planes: &[ClipPlane], jitter| RenderSettings {
        crop,
        clip_planes: clip_planes.to_vec(),
        jitter,
        ..RenderSettings::default()
    };
    let options = [
        ("jitter", cut(None, &[], true)),
        ("crop", cut(Some(crop), &[], false)),
        ("clip planes, jitter", cut(None, &planes, true)),
        ("crop, clip planes, jitter", cut(Some(crop), &planes, true)),
    ];
    let mut cases = 0;
    for (what, camera) in cameras(&volume) {
        for (options, cut) in &options {
            for step in [1.0, 0.5] {
                let settings = RenderSettings {
                    crop: cut.crop,
                    clip_planes: cut.clip_planes.clone(),
                    jitter: cut.jitter,
                    ..base_settings(camera, step)
                };
                // Some cuts leave nothing in front of an inner eye.
                let (fast, reference) = both_paths(&renderer, &settings);
                let what = format!("{what}, {options}, step {step}");
                assert_within_a_level(&fast, &reference, &what);
                cases += reference.pixels().iter().any(|p| p[3] > 0.2) as usize;
            }
        }
    }
    assert!(cases > 80, "only {cases} frames showed something");
}

/// Two opaque plates, one red and one green, across the middle of a 49³
/// grid at x = 12 and x = 36, each a few voxels thick: where they overlap
/// on screen the nearer one hides the other, so compositing the bricks in
/// the wrong order changes the colour completely.
fn plates() -> Volume {
    Volume::from_fn([49, 49, 49], DVec3::ONE, DVec3::ZERO, |p| {
        let inside = (6.0..=42.0).contains(&p.y) && (6.0..=42.0).contains(&p.z);
        if inside && (10.0..=14.0).contains(&p.x) {
            0.4
        } else if inside && (34.0..=38.0).contains(&p.x) {
            1.0
        } else {
            0.0
        }
    })
    .unwrap()
}

#[test]
fn the_nearer_of_two_opaque_plates_hides_the_other_from_either_side() {
    let volume = plates();
    let renderer = Renderer::new(&volume).unwrap();
    // Values 0.4 → red, 1 → green, both opaque within a voxel; the empty
    // voxels are black, so that the plates' edges (where pre-classification
    // interpolates their colour with the empty voxels') add no other hue.
    let two_colours = tf(r#"{"opacity": [[0, 0], [0.2, 0], [0.3, 1], [1, 1]],
        "color": [[0, 0, 0, 0], [0.2, 0, 0, 0], [0.3, 1, 0, 0], [0.6, 1, 0, 0],
                  [0.7, 0, 1, 0], [1, 0, 1, 0]]}"#);
    let c = DVec3::splat(24.0);
    for (eye, near_is_green) in [
        // Outside, on either side, and between the plates facing each.
        (DVec3::new(70.0, 21.0, 27.0), true),
        (DVec3::new(-20.0, 26.0, 23.0), false),
        (DVec3::new(25.0, 24.5, 23.5), true),
    ] {
        for look in [c, c + DVec3::new(0.0, 5.0, -3.0)] {
            let look_at = if (eye.x - 24.0).abs() < 2.0 {
                // Between the plates: look at the green one (+x).
                look + DVec3::new(20.0, 0.0, 0.0)
            } else {
                look
            };
            let settings = RenderSettings {
                width: 40,
                height: 40,
                camera: looking(eye, look_at, 50.0),
                transfer_function: two_colours.clone(),
                shading: false,
                ..RenderSettings::default()
            };
            let (fast, reference) = both_paths(&renderer, &settings);
            assert!(fast.max_abs_diff(&reference).unwrap() <= 1.0 / 255.0);
            let centre = fast.get(20, 20);
            let (near, far) = if near_is_green { (1, 0) } else { (0, 1) };
            assert!(
                centre[near] > 0.5 && centre[far] < 0.01,
                "eye {eye}: {centre:?}"
            );
        }
    }
}

#[test]
fn scattered_voxels_in_a_large_empty_volume_match_in_perspective() {
    // A few bright voxels through 50³ (partial last bricks): most rays
    // cross several occupied bricks separated by empty ones.
    let volume = scattered_voxels(50, 80);
    let renderer = Renderer::new(&volume).unwrap();
    let c = volume.centre();
    for (what, camera) in [
        ("default eye", perspective(35.0)),
        (
            "close, wide",
            looking(c + DVec3::new(30.0, 8.0, -5.0), c, 110.0),
        ),
        ("inside", looking(c, c + DVec3::new(-1.0, 0.5, 0.3), 90.0)),
    ] {
        for step in [0.5, 1.0] {
            let settings = RenderSettings {
                width: 61,
                height: 47,
                ..base_settings(camera, step)
            };
            assert_matches(&renderer, &settings, &format!("{what}, step {step}"), SHOWN);
        }
    }
}

#[test]
fn the_eye_far_away_with_a_narrow_view_matches_the_reference() {
    // A million grid spacings away, the view 50 spacings wide there: the
    // rays count their samples from near the volume, so their f32
    // positions lose nothing to the distance (counted from the eye, they
    // would be off by a hundredth of a voxel, 0.017 in colour).
    let volume = blobs([30, 33, 27], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    let c = volume.centre();
    let distance: f64 = 1.0e6;
    let fov = 2.0 * (25.0 / distance).atan().to_degrees();
    let away = DVec3::new(1500.0, -900.0, 1000.0).normalize();
    let settings = RenderSettings {
        width: 40,
        height: 40,
        camera: looking(c + distance * away, c, fov),
        transfer_function: sparse_tf(),
        ..RenderSettings::default()
    };
    assert_matches(&renderer, &settings, "far eye", SHOWN);
}

#[test]
fn perspective_frames_are_bit_identical_for_any_thread_count() {
    let volume = on_brick_boundaries([41, 17, 17], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    for (what, camera) in cameras(&volume) {
        let settings = RenderSettings {
            jitter: true,
            ..base_settings(camera, 0.5)
        };
        let images = [1, 2, 7].map(|n| render_on_threads(&renderer, &settings, n));
        assert!(images[0] == images[1] && images[1] == images[2], "{what}");
    }
}

#[test]
fn perspective_frames_run_on_the_bricked_path() {
    // The frame times its parts as a bricked frame does.
    let volume = blobs([20, 20, 20], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    let settings = base_settings(perspective(30.0), 1.0);
    let request = FrameRequest::new(&settings).reusing(Image::new(1, 1, [0.0; 4]));
    let (image, times) = renderer.render(request).unwrap().image_and_times();
    assert!(times.bricks > 0);
    let view = View::frame(&perspective(30.0), volume.bounds(), 37, 29).unwrap();
    assert!(matches!(view, View::Perspective(_)));
    assert_eq!((image.width(), image.height()), (37, 29));
}
