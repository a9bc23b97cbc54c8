//! The fast path's own mechanisms, each held to the reference path (the
//! oracle) within 1/255 per channel: empty-space skipping by bricks and
//! cells across brick faces and edges, rays lying exactly on brick faces,
//! tiles cut by the image's edges, early ray termination, the classified
//! bricks kept between frames, and thread invariance on all of these.

use volray_core::camera::Camera;
use volray_core::glam::DVec3;
use volray_core::{Image, Method, RenderSettings, Renderer, TransferFunction, Volume};

/// The fast and the reference image of one frame.
fn both_paths(renderer: &Renderer, settings: &RenderSettings) -> (Image, Image) {
    let fast = renderer.render(settings).unwrap();
    let reference = renderer
        .render(&RenderSettings {
            method: Method::Reference,
            ..settings.clone()
        })
        .unwrap();
    (fast, reference)
}

/// Asserts the fast path equals the reference within 1/255, and that the
/// image shows something (so the comparison means something).
fn assert_matches(renderer: &Renderer, settings: &RenderSettings, what: &str) -> f32 {
    let (fast, reference) = both_paths(renderer, settings);
    let diff = fast.max_abs_diff(&reference).unwrap();
    assert!(diff <= 1.0 / 255.0, "{what}: {diff}");
    assert!(
        reference.pixels().iter().any(|p| p[3] > 0.2),
        "{what}: the image is empty"
    );
    diff
}

fn tf(json: &str) -> TransferFunction {
    TransferFunction::from_json(json).unwrap()
}

/// Opacity zero below t = 0.3: most of a sparse volume is empty space.
fn sparse_tf() -> TransferFunction {
    tf(r#"{"opacity": [[0, 0], [0.3, 0], [1, 0.9]],
           "color": [[0, 0.2, 0.3, 0.8], [0.5, 0.9, 0.9, 0.9], [1, 0.8, 0.1, 0.1]]}"#)
}

/// Features on brick faces, edges and corners (bricks are 8 cells wide):
/// a plate on the face x = 16, a rod along the edge y = z = 8, single
/// voxels at brick corners, and a faint blob crossing several bricks.
fn on_brick_boundaries(dims: [usize; 3]) -> Volume {
    Volume::from_fn(dims, DVec3::ONE, DVec3::ZERO, |p| {
        let (x, y, z) = (p.x, p.y, p.z);
        let plate = x == 16.0 && (2.0..=13.0).contains(&y) && (3.0..=12.0).contains(&z);
        let rod = y == 8.0 && z == 8.0 && x >= 4.0;
        let corners = [(8.0, 8.0, 8.0), (24.0, 16.0, 8.0), (32.0, 0.0, 16.0)].contains(&(x, y, z));
        let blob =
            0.6 * (-((x - 20.0).powi(2) + (y - 9.0).powi(2) + (z - 7.0).powi(2)) / 18.0).exp();
        if plate || rod || corners {
            1.0
        } else {
            blob as f32
        }
    })
    .unwrap()
}

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
    let volume = on_brick_boundaries([41, 17, 17]);
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
                worst = worst.max(assert_matches(&renderer, &settings, &what));
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
    let volume = on_brick_boundaries([41, 17, 17]);
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
    let n = 50;
    let mut data = vec![0.0f32; n * n * n];
    let mut s = 0.123_456_789f64;
    for _ in 0..60 {
        let mut c = [0usize; 3];
        for a in &mut c {
            s = (s * 9301.0 + 0.492_97).fract();
            *a = (s * n as f64) as usize;
        }
        data[c[0] + n * (c[1] + n * c[2])] = 1.0;
    }
    let volume = Volume::new([n, n, n], data).unwrap();
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
            assert_matches(&renderer, &settings, &format!("{camera:?} step {step}"));
        }
    }
}

#[test]
fn tiles_cut_by_the_image_edges_match_the_reference() {
    // 37 × 23 pixels: the last column and row of 16 × 16 tiles are partial.
    let volume = on_brick_boundaries([41, 17, 17]);
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
            let diff = fast.max_abs_diff(&reference).unwrap();
            assert!(diff <= 1.0 / 255.0, "{width}x{height} {camera:?}: {diff}");
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
fn classification_follows_the_transfer_function_between_frames() {
    // One renderer, the transfer function changed and changed back: each
    // frame equals a fresh renderer's.
    let volume = on_brick_boundaries([41, 17, 17]);
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
        let fresh = Renderer::new(&volume).unwrap().render(&settings).unwrap();
        assert_eq!(renderer.render(&settings).unwrap(), fresh);
    }
}

#[test]
fn every_mechanism_is_bit_identical_for_any_thread_count() {
    let volume = on_brick_boundaries([41, 17, 17]);
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
        let images: Vec<Image> = [1, 2, 7]
            .iter()
            .map(|&n| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .unwrap();
                pool.install(|| renderer.render(&settings).unwrap())
            })
            .collect();
        assert!(
            images[0] == images[1] && images[1] == images[2],
            "{camera:?}"
        );
    }
}
