//! The fast path's own mechanisms, each held to the reference path (the
//! oracle) within 1/255 per channel: empty-space skipping by bricks and
//! cells across brick faces and edges, rays lying exactly on brick faces,
//! tiles cut by the image's edges, early ray termination, the classified
//! bricks kept between frames, and thread invariance on all of these.

mod common;

use common::{
    assert_matches, assert_within_a_level, both_paths, on_brick_boundaries, render_on_threads,
    scattered_voxels, sparse_tf, tf,
};
use volray_core::camera::Camera;
use volray_core::glam::DVec3;
use volray_core::{FrameRequest, Render};
use volray_core::{Image, RenderSettings, Renderer, TransferFunction, Volume};

/// The fewest pixels of opacity above 0.2 the reference must show for a
/// comparison to count: one.
const SHOWN: usize = 1;

/// The cameras the mechanisms are seen through: along −x (the default;
/// rays on brick faces and edges), along +x, two oblique views, and along
/// +y with the up vector tilted.
fn views() -> Vec<Camera> {
    let at = |x: f64, y: f64, z: f64| Camera {
        view_point: Some(DVec3::new(x, y, z)),
        ..Camera::default()
    };
    vec![
        Camera::default(),
        at(-100.0, 8.0, 8.0),
        at(150.0, 150.0, 500.0),
        at(-40.0, 12.0, -9.0),
        Camera {
            view_point: Some(DVec3::new(3.0, -50.0, 4.0)),
            up: DVec3::new(0.2, 0.0, 1.0),
            ..Camera::default()
        },
    ]
}

#[test]
fn skipping_across_brick_faces_edges_and_corners_matches_the_reference() {
    let volume = on_brick_boundaries([41, 17, 17], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    let mut worst = 0.0f32;
    for camera in views() {
        for step in [1.0, 0.5, 0.3] {
            // 9 × 9 pixels on the 16 × 16 face: along ±x the middle ray lies
            // exactly on the brick edge y = z = 8, and pixel rows and
            // columns straddle the faces y = 8 and z = 8.
            for (width, height) in [(9, 9), (40, 33)] {
                let settings = RenderSettings {
                    width,
                    height,
                    camera,
                    step,
                    transfer_function: sparse_tf(),
                    background: [0.1, 0.1, 0.3],
                    ..RenderSettings::default()
                };
                let what = format!("{camera:?} step {step} {width}x{height}");
                worst = worst.max(assert_matches(&renderer, &settings, &what, SHOWN));
            }
        }
    }
    println!("largest fast-vs-reference difference: {worst:.6}");
}

#[test]
fn the_ray_on_a_brick_edge_sees_the_rod_along_it() {
    // Along −x the middle pixel's ray runs inside the rod on y = z = 8,
    // which the four bricks around the edge all hold: it must be nearly
    // opaque, on both paths.
    let volume = on_brick_boundaries([41, 17, 17], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    let settings = RenderSettings {
        width: 9,
        height: 9,
        step: 0.5,
        transfer_function: sparse_tf(),
        ..RenderSettings::default()
    };
    let (fast, reference) = both_paths(&renderer, &settings);
    assert!(reference.get(4, 4)[3] > 0.99, "{:?}", reference.get(4, 4));
    assert!(fast.get(4, 4)[3] > 0.99, "{:?}", fast.get(4, 4));
    assert!(fast.max_abs_diff(&reference).unwrap() <= 1.0 / 255.0);
}

#[test]
fn sparse_voxels_in_a_large_empty_volume_match_the_reference() {
    // A few bright voxels scattered through 50³ (partial last bricks, like
    // the peers' 50³ volumes): most bricks are empty, most rays cross
    // several occupied bricks separated by empty ones.
    let volume = scattered_voxels(50, 60);
    let renderer = Renderer::new(&volume).unwrap();
    for camera in views() {
        for step in [0.5, 0.8] {
            let settings = RenderSettings {
                width: 61,
                height: 47,
                camera,
                step,
                transfer_function: sparse_tf(),
                ..RenderSettings::default()
            };
            assert_matches(
                &renderer,
                &settings,
                &format!("{camera:?} step {step}"),
                SHOWN,
            );
        }
    }
}

#[test]
fn tiles_cut_by_the_image_edges_match_the_reference() {
    // 37 × 23 pixels: the last column and row of 16 × 16 tiles are partial.
    let volume = on_brick_boundaries([41, 17, 17], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    for (width, height) in [(37, 23), (1, 1), (17, 5), (3, 40)] {
        for camera in views() {
            let settings = RenderSettings {
                width,
                height,
                camera,
                step: 0.5,
                transfer_function: sparse_tf(),
                ..RenderSettings::default()
            };
            let (fast, reference) = both_paths(&renderer, &settings);
            assert_within_a_level(&fast, &reference, &format!("{width}x{height} {camera:?}"));
        }
    }
}

#[test]
fn early_termination_stays_within_a_level_in_an_opaque_volume() {
    // A dense, nearly opaque medium with structure: rays stop after a few
    // voxels, once less than 1/1024 of the light gets through.
    let volume = Volume::from_fn([40, 36, 30], DVec3::ONE, DVec3::ZERO, |p| {
        (0.8 + 0.2 * (p.x * 0.7).sin() * (p.y * 0.5).cos()) as f32
    })
    .unwrap();
    let renderer = Renderer::new(&volume).unwrap();
    let settings = RenderSettings {
        width: 50,
        height: 44,
        step: 0.5,
        camera: views()[2],
        transfer_function: tf(r#"{"opacity": [[0, 0.6], [1, 0.95]],
            "color": [[0, 0.1, 0.5, 0.9], [1, 0.9, 0.6, 0.1]]}"#),
        background: [1.0, 1.0, 1.0],
        ..RenderSettings::default()
    };
    let (fast, reference) = both_paths(&renderer, &settings);
    assert!(fast.max_abs_diff(&reference).unwrap() <= 1.0 / 255.0);
    // Opaque: the white background does not show through.
    let centre = reference.get(25, 22);
    assert!(centre[3] > 0.999, "{centre:?}");
}

#[test]
fn bricks_hidden_behind_an_opaque_surface_are_not_lit() {
    // An opaque slab, 80 voxels deep along the view (ten bricks): rays
    // terminate in its first brick, so the nine behind it are never lit,
    // and the image is still the reference's.
    let volume = Volume::from_fn([81, 24, 24], DVec3::ONE, DVec3::ZERO, |p| {
        (0.9 + 0.1 * (p.y * 0.4).sin() * (p.z * 0.3).cos()) as f32
    })
    .unwrap();
    let renderer = Renderer::new(&volume).unwrap();
    let settings = RenderSettings {
        width: 40,
        height: 40,
        step: 0.5,
        camera: Camera {
            view_point: Some(DVec3::new(-200.0, 12.0, 12.0)),
            ..Camera::default()
        },
        transfer_function: tf(r#"{"opacity": [[0, 0.9], [1, 0.99]],
            "color": [[0, 0.2, 0.6, 0.9], [1, 0.9, 0.5, 0.2]]}"#),
        ..RenderSettings::default()
    };
    let times = renderer.render(FrameRequest::new(&settings)).unwrap().times;
    // 10 × 3 × 3 bricks, all occupied; the front layer's 9 are lit (a
    // ray on a brick face may also reach the second layer).
    assert_eq!(times.bricks, 90);
    assert!(times.lit >= 9 && times.lit <= 18, "{} lit", times.lit);
    let (fast, reference) = both_paths(&renderer, &settings);
    assert!(fast.max_abs_diff(&reference).unwrap() <= 1.0 / 255.0);
    // Nearly transparent instead, light crosses the slab: every brick is lit.
    let faint = RenderSettings {
        transfer_function: tf(r#"{"opacity": [[0, 0.001], [1, 0.002]],
            "color": [[0, 0.2, 0.6, 0.9], [1, 0.9, 0.5, 0.2]]}"#),
        ..settings
    };
    let times = renderer.render(FrameRequest::new(&faint)).unwrap().times;
    assert_eq!(times.lit, 90);
}

#[test]
fn classification_follows_the_transfer_function_between_frames() {
    // One renderer, the transfer function changed and changed back: each
    // frame equals a fresh renderer's.
    let volume = on_brick_boundaries([41, 17, 17], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    let frame = |tf: TransferFunction, step: f64| RenderSettings {
        width: 30,
        height: 20,
        step,
        camera: views()[2],
        transfer_function: tf,
        ..RenderSettings::default()
    };
    let other = tf(r#"{"opacity": [[0, 0.1], [1, 0.5]]}"#);
    for settings in [
        frame(sparse_tf(), 0.5),
        frame(other.clone(), 0.5),
        frame(other, 1.0),
        frame(sparse_tf(), 0.5),
    ] {
        let fresh = Renderer::new(&volume)
            .unwrap()
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        assert_eq!(
            renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image(),
            fresh
        );
    }
}

#[test]
fn every_mechanism_is_bit_identical_for_any_thread_count() {
    let volume = on_brick_boundaries([41, 17, 17], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    for camera in views() {
        let settings = RenderSettings {
            width: 37,
            height: 23,
            step: 0.5,
            camera,
            transfer_function: sparse_tf(),
            ..RenderSettings::default()
        };
        let images = [1, 2, 7].map(|n| render_on_threads(&renderer, &settings, n));
        assert!(
            images[0] == images[1] && images[1] == images[2],
            "{camera:?}"
        );
    }
}

#[test]
fn a_faint_dense_volume_beyond_the_cache_budget_is_lit_once_a_frame() {
    // 129³, every brick occupied under a faint ramp (α ≤ 0.05 a voxel: no
    // ray terminates), so each frame lights all 4096 bricks: 47.8 MB of lit
    // voxels, 24.3 MB classified. The budget (19.4 MB) holds a quarter of
    // that, but the bricks of the tiles in flight fit: each brick must
    // still be lit once a frame and classified at most once, as when
    // everything fits, with the same pixels. (Before, the bricks beyond
    // the budget were classified and lit again for every tile that listed
    // them: 7563 bricks lit in the first frame.)
    let volume = Volume::from_fn([129; 3], DVec3::ONE, DVec3::ZERO, |p| {
        (1.0 + 0.3 * (0.11 * p.x).sin() * (0.07 * p.y).cos() + 0.002 * p.z) as f32
    })
    .unwrap();
    let bricks = 16 * 16 * 16;
    // 80 % of the classified slots (5928 bytes a brick), for the lit
    // ones too.
    let budget = bricks * 5928 * 80 / 100;
    let frames: Vec<RenderSettings> = [0.0, 0.5, 30.0]
        .into_iter()
        .map(|azimuth| RenderSettings {
            width: 256,
            height: 256,
            step: 0.5,
            opacity_ramp: (0.0, 0.05),
            camera: Camera {
                azimuth,
                ..Camera::default()
            },
            ..RenderSettings::default()
        })
        .collect();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let roomy = Renderer::new(&volume).unwrap();
            let tight = Renderer::new(&volume).unwrap().with_cache_budget(budget);
            let (mut want, mut got) = (Image::new(0, 0, [0.0; 4]), Image::new(0, 0, [0.0; 4]));
            for settings in &frames {
                let request = FrameRequest::new(settings).reusing(want);
                let all;
                (want, all) = roomy.render(request).unwrap().image_and_times();
                assert_eq!((all.bricks, all.lit, all.classified), (bricks, bricks, 0));
                let request = FrameRequest::new(settings).reusing(got);
                let some;
                (got, some) = tight.render(request).unwrap().image_and_times();
                assert!(got == want, "{threads} threads");
                assert!(some.cached_bytes <= budget);
                // Each brick lit once; classified once where the cache
                // lost it, which it must for some (it holds about half).
                assert_eq!(some.lit, bricks, "{threads} threads");
                assert!(
                    some.classified > 0 && some.classified <= bricks,
                    "{threads} threads: {} classified",
                    some.classified
                );
            }
        });
    }
}
