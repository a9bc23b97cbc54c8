//! Post-classified compositing on its fast path (`cpu/post/`),
//! held to the reference path (the oracle) within 1/255 per channel: a
//! smooth ball, the Marschner–Lobb signal and a step edge; views along an
//! axis, oblique and in perspective (the eye outside and inside the
//! volume); steps of 0.5 and 1; lit and unlit; crop boxes, clip planes and
//! jitter; Levoy's iso-surfaces and gradient-magnitude opacity;
//! anisotropic spacing. Also: bit-identical images for any thread count.
//! (The brick walk's skipping is tested in `cpu/post/skipping.rs`, where its work
//! counts can be seen.)

mod common;

use common::{
    Cut, assert_uniform_medium, constant_tf, looking, render_on_threads, tf, uniform_medium,
};
use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::{
    Classification, ClipPlane, IsoSurface, RenderSettings, Renderer, TransferFunction, Volume,
};
use volray_core::{FrameRequest, Render};

/// `common::assert_matches` for a post-classified frame: the fast path
/// within 1/255 per channel of the reference, which shows at least 10
/// pixels; returns the largest difference.
fn assert_matches(renderer: &Renderer, settings: &RenderSettings, what: &str) -> f32 {
    assert_eq!(settings.classification, Classification::Post);
    common::assert_matches(renderer, settings, what, 10)
}

/// Opacity zero below t = 0.25, so that empty bricks are skipped, a bump
/// and a plateau; colours from blue through grey to red (not
/// `common::colorful`).
fn bump_and_plateau() -> TransferFunction {
    tf(
        r#"{"opacity": [[0, 0], [0.25, 0], [0.5, 0.35], [0.7, 0.15], [1, 0.8]],
           "color": [[0, 0.23, 0.3, 0.75], [0.5, 0.87, 0.87, 0.87], [1, 0.7, 0.02, 0.15]]}"#,
    )
}

/// The cube [−1, 1]³ with `n` points per side.
fn cube(n: usize, f: impl Fn(DVec3) -> f64) -> Volume {
    let h = 2.0 / (n - 1) as f64;
    Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
        f(p) as f32
    })
    .unwrap()
}

/// A ball of radius 0.6, density falling smoothly from 1 at its centre
/// (off the grid's centre, so that no ray meets a zero gradient by
/// symmetry) to 0 at its edge and beyond.
fn smooth_ball(n: usize) -> Volume {
    let centre = DVec3::new(0.07, -0.05, 0.11);
    cube(n, |p| {
        (1.0 - ((p - centre).length() / 0.6).powi(2)).max(0.0)
    })
}

/// The Marschner–Lobb test signal (S. R. Marschner and R. J. Lobb, "An
/// evaluation of reconstruction filters for volume rendering", 1994):
/// `(1 − sin(πz/2) + α(1 + cos(2π f_M cos(πr/2))))/(2(1 + α))`,
/// `r = √(x² + y²)`, `f_M = 6`, `α = 0.25`.
fn marschner_lobb(n: usize) -> Volume {
    use std::f64::consts::PI;
    let (fm, alpha) = (6.0, 0.25);
    cube(n, |p| {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let rho = (2.0 * PI * fm * (PI * r / 2.0).cos()).cos();
        (1.0 - (PI * p.z / 2.0).sin() + alpha * (1.0 + rho)) / (2.0 * (1.0 + alpha))
    })
}

/// A step edge: 0.9 on one side of an oblique plane, 0.1 on the other,
/// the step across one cell (on a grid whose last bricks are partial).
fn step_edge() -> Volume {
    Volume::from_fn([30, 26, 22], DVec3::ONE, DVec3::ZERO, |p| {
        if p.x + 0.3 * p.y - 0.2 * p.z > 12.1 {
            0.9
        } else {
            0.1
        }
    })
    .unwrap()
}

fn views() -> Vec<(&'static str, Camera)> {
    vec![
        ("along -x", Camera::default()),
        (
            "oblique",
            Camera {
                view_point: Some(DVec3::new(150.0, 150.0, 500.0)),
                ..Camera::default()
            },
        ),
        (
            "orbit",
            Camera {
                azimuth: -115.0,
                elevation: 35.0,
                ..Camera::default()
            },
        ),
        (
            "perspective",
            Camera {
                projection: Projection::Perspective { fov_degrees: 40.0 },
                azimuth: 30.0,
                elevation: 20.0,
                ..Camera::default()
            },
        ),
    ]
}

fn settings(camera: Camera, step: f64, shading: bool) -> RenderSettings {
    RenderSettings {
        width: 36,
        height: 30,
        camera,
        step,
        shading,
        classification: Classification::Post,
        transfer_function: bump_and_plateau(),
        background: [0.1, 0.1, 0.3],
        ..RenderSettings::default()
    }
}

#[test]
fn the_fast_path_matches_the_reference_on_several_volumes_views_and_steps() {
    let mut worst = 0.0f32;
    for (name, volume) in [
        ("ball", smooth_ball(27)),
        ("marschner-lobb", marschner_lobb(25)),
        ("step edge", step_edge()),
    ] {
        let renderer = Renderer::new(&volume).unwrap();
        for (view, camera) in views() {
            for step in [1.0, 0.5] {
                for shading in [false, true] {
                    let what = format!("{name}, {view}, step {step}, lit {shading}");
                    let s = settings(camera, step, shading);
                    worst = worst.max(assert_matches(&renderer, &s, &what));
                }
            }
        }
    }
    println!("largest fast-vs-reference difference: {worst:.6}");
}

#[test]
fn the_default_ramp_and_a_sharp_table_match_the_reference() {
    // The paper's ramp (opacity 0 only at the volume's minimum), and a
    // table whose opacity rises steeply about t = 0.5: post-classification
    // resolves the rise at each sample, as the reference does.
    let volume = marschner_lobb(25);
    let renderer = Renderer::new(&volume).unwrap();
    let sharp =
        tf(r#"{"opacity": [[0.49, 0], [0.51, 0.6]], "color": [[0, 1, 0.5, 0], [1, 0, 0.5, 1]]}"#);
    for transfer_function in [TransferFunction::default(), sharp] {
        for (view, camera) in views() {
            let s = RenderSettings {
                transfer_function: transfer_function.clone(),
                ..settings(camera, 0.7, true)
            };
            assert_matches(&renderer, &s, view);
        }
    }
}

#[test]
fn crops_clip_planes_and_jitter_match_the_reference() {
    let volume = Volume::from_fn(
        [33, 25, 29],
        DVec3::new(1.0, 1.5, 0.75),
        DVec3::new(-2.0, 5.0, 1.0),
        |p| {
            let c = DVec3::new(14.0, 23.0, 12.0);
            let d = (p - c) / DVec3::new(11.0, 14.0, 9.0);
            (1.0 - d.length_squared()).max(0.0) as f32
        },
    )
    .unwrap();
    let renderer = Renderer::new(&volume).unwrap();
    let (lo, hi) = volume.bounds();
    let centre = 0.5 * (lo + hi);
    let cuts: Vec<Cut> = vec![
        (
            Some((
                centre - DVec3::new(6.0, 20.0, 5.0),
                centre + DVec3::new(3.3, 4.1, 20.0),
            )),
            vec![],
        ),
        (
            None,
            vec![
                ClipPlane {
                    point: centre,
                    normal: DVec3::new(1.0, -0.4, 0.7),
                },
                ClipPlane {
                    point: centre + DVec3::new(0.0, 3.0, 0.0),
                    normal: DVec3::new(0.1, -1.0, 0.2),
                },
            ],
        ),
    ];
    for (view, camera) in views() {
        for (crop, planes) in &cuts {
            for (jitter, step) in [(false, 1.0), (true, 0.6), (true, 1.0)] {
                let s = RenderSettings {
                    crop: *crop,
                    clip_planes: planes.clone(),
                    jitter,
                    ..settings(camera, step, true)
                };
                let what = format!(
                    "{view}, crop {crop:?}, {} planes, jitter {jitter}",
                    planes.len()
                );
                assert_matches(&renderer, &s, &what);
            }
        }
    }
}

#[test]
fn iso_surfaces_and_gradient_opacity_match_the_reference() {
    // Levoy's contour needs the gradient at every sample for the opacity
    // itself; gradient-magnitude opacity fades the flat inside of the ball
    // and the flat sides of the step.
    let cases = [
        ("ball", smooth_ball(27), 0.45f32),
        ("marschner-lobb", marschner_lobb(25), 0.5),
        ("step edge", step_edge(), 0.5),
    ];
    for (name, volume, iso) in cases {
        let renderer = Renderer::new(&volume).unwrap();
        for (view, camera) in views() {
            for shading in [false, true] {
                let contour = RenderSettings {
                    iso: Some(IsoSurface {
                        value: iso,
                        thickness: 1.5,
                    }),
                    ..settings(camera, 0.5, shading)
                };
                assert_matches(
                    &renderer,
                    &contour,
                    &format!("{name} iso, {view}, {shading}"),
                );
                let graded = RenderSettings {
                    gradient_opacity: Some((0.1, 0.6)),
                    transfer_function: TransferFunction::default(),
                    opacity_ramp: (0.2, 0.9),
                    ..settings(camera, 1.0, shading)
                };
                assert_matches(
                    &renderer,
                    &graded,
                    &format!("{name} |∇f|, {view}, {shading}"),
                );
            }
        }
    }
}

#[test]
fn anisotropic_grids_and_eyes_inside_the_volume_match_the_reference() {
    let volume = Volume::from_fn([37, 26, 45], DVec3::new(1.0, 2.0, 0.6), DVec3::ZERO, |p| {
        let u = p / DVec3::new(36.0, 50.0, 26.4);
        let blob = |c: DVec3, w: f64| (-(u - c).length_squared() / (2.0 * w * w)).exp();
        (blob(DVec3::new(0.3, 0.4, 0.5), 0.18) + 0.8 * blob(DVec3::new(0.7, 0.6, 0.3), 0.1)) as f32
    })
    .unwrap();
    let renderer = Renderer::new(&volume).unwrap();
    let cameras = [
        ("orthographic", Camera::default()),
        (
            "eye inside",
            looking(
                DVec3::new(14.0, 22.0, 11.0),
                DVec3::new(30.0, 40.0, 5.0),
                70.0,
            ),
        ),
        (
            "eye on a brick corner",
            looking(
                DVec3::new(8.0, 16.0, 4.8),
                DVec3::new(20.0, 25.0, 13.0),
                90.0,
            ),
        ),
        (
            "eye far away",
            looking(
                DVec3::new(900.0, -700.0, 400.0),
                DVec3::new(18.0, 25.0, 13.0),
                3.0,
            ),
        ),
    ];
    for (view, camera) in cameras {
        for step in [1.0, 0.5] {
            assert_matches(
                &renderer,
                &settings(camera, step, true),
                &format!("{view}, step {step}"),
            );
        }
    }
}

#[test]
fn a_uniform_medium_has_the_closed_form_colour_on_the_fast_path() {
    // K = 10/step + 1 samples of colour c and opacity α_s = 1 − (1 − α)^step
    // give c(1 − (1 − α_s)^K) + bg(1 − α_s)^K; lit, the medium has no
    // gradient, so only the ambient 0.1 lights it.
    let volume = uniform_medium();
    let renderer = Renderer::new(&volume).unwrap();
    let (alpha, c, bg) = (0.3f64, [0.9, 0.5, 0.2], [0.1, 0.2, 1.0]);
    let constant = constant_tf(alpha as f32, c);
    for (step, k) in [(1.0, 11), (0.5, 21)] {
        for shading in [false, true] {
            let s = RenderSettings {
                width: 14,
                height: 10,
                step,
                shading,
                classification: Classification::Post,
                transfer_function: constant.clone(),
                background: bg,
                ..RenderSettings::default()
            };
            let keep = (1.0 - alpha).powf(step * k as f64);
            let light = if shading { 0.1 } else { 1.0 };
            let image = renderer.render(FrameRequest::new(&s)).unwrap().image();
            let what = format!("step {step}, lit {shading}");
            assert_uniform_medium(&image, light, c, bg, keep, 1e-5, &what);
        }
    }
}

#[test]
fn images_are_bit_identical_for_any_thread_count() {
    let volume = marschner_lobb(25);
    let renderer = Renderer::new(&volume).unwrap();
    for (view, camera) in views() {
        let s = RenderSettings {
            jitter: true,
            gradient_opacity: Some((0.05, 0.5)),
            ..settings(camera, 0.6, true)
        };
        let images = [1, 2, 3].map(|threads| render_on_threads(&renderer, &s, threads));
        assert!(images[0] == images[1] && images[1] == images[2], "{view}");
    }
}
