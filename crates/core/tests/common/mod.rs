//! What the renderer's integration tests share: running one frame on the
//! fast and the reference path and holding the one to the other, and
//! rendering on a thread pool of a given size; the transfer functions
//! several files use; the test volumes several files render (Gaussian
//! blobs, features on brick boundaries, scattered voxels, a uniform
//! medium) and the uniform medium's closed form; perspective cameras; and
//! the crop-and-clip-planes pair.
//!
//! Each test binary compiles this module for itself and uses only part of
//! it, hence the `allow(dead_code)`.
#![allow(dead_code)]

use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::{
    ClipPlane, Image, Method, PiecewiseLinear, RenderSettings, Renderer, TransferFunction, Volume,
};
use volray_core::{FrameRequest, Render};

// ---- the two paths ----

/// The same settings on the reference path (the oracle).
pub fn on_the_reference(settings: &RenderSettings) -> RenderSettings {
    RenderSettings {
        method: Method::Reference,
        ..settings.clone()
    }
}

/// The fast and the reference image of one frame, after checking that the
/// frame is set for the fast path (else both would be the reference).
pub fn both_paths(renderer: &Renderer, settings: &RenderSettings) -> (Image, Image) {
    assert_eq!(settings.method, Method::Fast);
    let fast = renderer
        .render(FrameRequest::new(settings))
        .unwrap()
        .image();
    let reference = renderer
        .render(FrameRequest::new(&on_the_reference(settings)))
        .unwrap()
        .image();
    (fast, reference)
}

/// Asserts that `fast` is within 1/255 per channel of `reference` (one
/// level of an 8-bit picture); returns the largest difference. `what`
/// starts the message of a failure.
pub fn assert_within_a_level(fast: &Image, reference: &Image, what: &str) -> f32 {
    let diff = fast.max_abs_diff(reference).unwrap();
    assert!(diff <= 1.0 / 255.0, "{what}: fast vs reference {diff}");
    diff
}

/// Asserts that the fast path renders `settings` within 1/255 per channel
/// of the reference, and that the reference shows something, at least
/// `min_shown` pixels of opacity above 0.2 (so that the comparison means
/// something); returns the largest difference.
pub fn assert_matches(
    renderer: &Renderer,
    settings: &RenderSettings,
    what: &str,
    min_shown: usize,
) -> f32 {
    let (fast, reference) = both_paths(renderer, settings);
    let diff = assert_within_a_level(&fast, &reference, what);
    let shown = reference.pixels().iter().filter(|p| p[3] > 0.2).count();
    assert!(
        shown >= min_shown,
        "{what}: the image is (nearly) empty ({shown} pixels shown, {min_shown} wanted)"
    );
    diff
}

/// `settings` rendered by `renderer` on a thread pool of `threads`
/// threads.
pub fn render_on_threads(renderer: &Renderer, settings: &RenderSettings, threads: usize) -> Image {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        renderer
            .render(FrameRequest::new(settings))
            .unwrap()
            .image()
    })
}

// ---- transfer functions ----

/// The transfer function of `json` (the CLI's `--tf` format).
pub fn tf(json: &str) -> TransferFunction {
    TransferFunction::from_json(json).unwrap()
}

/// Opacity `alpha` and colour `color` at every value.
pub fn constant_tf(alpha: f32, color: [f32; 3]) -> TransferFunction {
    TransferFunction {
        domain: None,
        opacity: Some(PiecewiseLinear::constant([alpha])),
        color: Some(PiecewiseLinear::constant(color)),
    }
}

/// Opacity zero below t = 0.1, rising to 0.9; colours from blue through
/// grey to red (a cool-to-warm map).
pub fn colorful() -> TransferFunction {
    tf(r#"{"opacity": [[0, 0], [0.1, 0], [0.6, 0.4], [1, 0.9]],
            "color": [[0, 0.23, 0.299, 0.754], [0.5, 0.865, 0.865, 0.865], [1, 0.706, 0.016, 0.15]]}"#)
}

/// Opacity zero below t = 0.3: most of a sparse volume is empty space.
pub fn sparse_tf() -> TransferFunction {
    tf(r#"{"opacity": [[0, 0], [0.3, 0], [1, 0.9]],
           "color": [[0, 0.2, 0.3, 0.8], [0.5, 0.9, 0.9, 0.9], [1, 0.8, 0.1, 0.1]]}"#)
}

/// Grey levels `t = f` for values in [0, 1], for the projections.
pub fn grey_unit_window() -> TransferFunction {
    TransferFunction {
        domain: Some((0.0, 1.0)),
        opacity: None,
        color: None,
    }
}

// ---- volumes ----

/// Three Gaussian blobs (values in about [0, 1]) on `dims` points of
/// `spacing` from `origin`: smooth, no symmetry, empty space around them.
/// The grid is mapped onto the unit cube, its first point to 0 and its
/// last to 1 on each axis; the blobs' centres, widths and heights are in
/// those coordinates.
pub fn blobs(dims: [usize; 3], spacing: DVec3, origin: DVec3) -> Volume {
    let centres = [
        (DVec3::new(0.3, 0.4, 0.5), 0.18, 1.0),
        (DVec3::new(0.7, 0.6, 0.3), 0.12, 0.7),
        (DVec3::new(0.5, 0.25, 0.75), 0.08, 0.9),
    ];
    let extent = DVec3::new(
        (dims[0] - 1) as f64,
        (dims[1] - 1) as f64,
        (dims[2] - 1) as f64,
    ) * spacing;
    Volume::from_fn(dims, spacing, origin, |p| {
        let u = (p - origin) / extent;
        centres
            .iter()
            .map(|(c, w, h)| h * (-(u - *c).length_squared() / (2.0 * w * w)).exp())
            .sum::<f64>() as f32
    })
    .unwrap()
}

/// Features on brick faces, edges and corners (bricks are 8 cells wide),
/// on `dims` points of `spacing` from the world origin, in index space: a
/// plate on the face x = 16, a rod along the edge y = z = 8, single voxels
/// at brick corners, and a faint blob crossing several bricks.
pub fn on_brick_boundaries(dims: [usize; 3], spacing: DVec3) -> Volume {
    Volume::from_fn(dims, spacing, DVec3::ZERO, |p| {
        let q = p / spacing;
        let (x, y, z) = (q.x.round(), q.y.round(), q.z.round());
        let plate = x == 16.0 && (2.0..=13.0).contains(&y) && (3.0..=12.0).contains(&z);
        let rod = y == 8.0 && z == 8.0 && x >= 4.0;
        let corners = [(8.0, 8.0, 8.0), (24.0, 16.0, 8.0), (32.0, 0.0, 16.0)].contains(&(x, y, z));
        let blob = 0.6
            * (-((q.x - 20.0).powi(2) + (q.y - 9.0).powi(2) + (q.z - 7.0).powi(2)) / 18.0).exp();
        if plate || rod || corners {
            1.0
        } else {
            blob as f32
        }
    })
    .unwrap()
}

/// `count` bright voxels (value 1) scattered through `n`³ unit voxels of
/// zero, at positions from a fixed pseudo-random sequence (the same for
/// every `count`; a voxel may be drawn twice).
pub fn scattered_voxels(n: usize, count: usize) -> Volume {
    let mut data = vec![0.0f32; n * n * n];
    let mut s = 0.123_456_789f64;
    for _ in 0..count {
        let mut c = [0usize; 3];
        for a in &mut c {
            s = (s * 9301.0 + 0.492_97).fract();
            *a = (s * n as f64) as usize;
        }
        data[c[0] + n * (c[1] + n * c[2])] = 1.0;
    }
    Volume::new([n, n, n], data).unwrap()
}

/// The uniform medium of the closed-form tests: the value 3 on 11 × 7 × 5
/// unit voxels. Seen along −x (the default view) every ray takes
/// K = 10/step + 1 samples of the same colour and opacity, at x = 0, step,
/// …, 10.
pub fn uniform_medium() -> Volume {
    Volume::new([11, 7, 5], vec![3.0; 11 * 7 * 5]).unwrap()
}

/// Asserts that every pixel of `image` is the closed form of a uniform
/// medium of colour `c` lit by `light` in front of `bg`, letting through
/// the fraction `keep` of the light: colour `light·c(1 − keep) + bg·keep`
/// and opacity `1 − keep`, each channel within `tol`. `what` starts the
/// message of a failure.
pub fn assert_uniform_medium(
    image: &Image,
    light: f64,
    c: [f32; 3],
    bg: [f32; 3],
    keep: f64,
    tol: f64,
    what: &str,
) {
    for px in image.pixels() {
        for ch in 0..3 {
            let want = light * c[ch] as f64 * (1.0 - keep) + bg[ch] as f64 * keep;
            assert!(
                (px[ch] as f64 - want).abs() < tol,
                "{what}: {px:?} vs {want}"
            );
        }
        assert!(
            (px[3] as f64 - (1.0 - keep)).abs() < tol,
            "{what}: {px:?} vs opacity {}",
            1.0 - keep
        );
    }
}

// ---- cameras ----

/// The default camera with a perspective projection of `fov_degrees`.
pub fn perspective(fov_degrees: f64) -> Camera {
    Camera {
        projection: Projection::Perspective { fov_degrees },
        ..Camera::default()
    }
}

/// A perspective camera at `eye` looking at `at` (world units).
pub fn looking(eye: DVec3, at: DVec3, fov_degrees: f64) -> Camera {
    Camera {
        view_point: Some(eye),
        look_at: Some(at),
        ..perspective(fov_degrees)
    }
}

// ---- cuts ----

/// A crop box (`RenderSettings::crop`) and clip planes
/// (`RenderSettings::clip_planes`).
pub type Cut = (Option<(DVec3, DVec3)>, Vec<ClipPlane>);
