//! End-to-end properties of the renderer: closed forms, the reference path
//! as oracle for the fast path, thread invariance and geometry.

mod common;

use common::{
    assert_uniform_medium, assert_within_a_level, both_paths, colorful, constant_tf,
    render_on_threads, uniform_medium,
};
use volray_core::camera::{Camera, OrthographicView};
use volray_core::glam::DVec3;
use volray_core::{FrameRequest, Render};
use volray_core::{Image, Method, RenderSettings, Renderer, TransferFunction, Volume};

/// `settings` rendered by a new renderer of `volume`.
fn render(volume: &Volume, settings: &RenderSettings) -> Image {
    Renderer::new(volume)
        .unwrap()
        .render(FrameRequest::new(settings))
        .unwrap()
        .image()
}

/// `common::blobs` on `dims` points of `spacing` from (−2, 5, 1).
fn blobs(dims: [usize; 3], spacing: DVec3) -> Volume {
    common::blobs(dims, spacing, DVec3::new(-2.0, 5.0, 1.0))
}

#[test]
fn all_transparent_volume_gives_exactly_the_background() {
    let volume = blobs([12, 10, 9], DVec3::ONE);
    let settings = RenderSettings {
        width: 24,
        height: 20,
        transfer_function: constant_tf(0.0, [1.0, 1.0, 1.0]),
        background: [0.2, 0.4, 0.6],
        camera: Camera {
            view_point: Some(DVec3::new(150.0, 150.0, 500.0)),
            ..Camera::default()
        },
        ..RenderSettings::default()
    };
    let (fast, reference) = both_paths(&Renderer::new(&volume).unwrap(), &settings);
    for image in [fast, reference] {
        for px in image.pixels() {
            assert_eq!(*px, [0.2, 0.4, 0.6, 0.0]);
        }
    }
}

#[test]
fn uniform_medium_has_the_closed_form_colour() {
    // 11 points along x: every ray of the default view (along −x) takes
    // K = 10/step + 1 samples of colour c and per-voxel opacity α, so the
    // pixel is c(1 − (1 − α_s)^K) + bg(1 − α_s)^K with α_s = 1 − (1 − α)^step.
    let volume = uniform_medium();
    let (alpha, c, bg) = (0.3f64, [0.9, 0.5, 0.2], [0.1, 0.2, 1.0]);
    for (step, k) in [(1.0, 11), (0.5, 21), (0.25, 41)] {
        let settings = RenderSettings {
            width: 14,
            height: 10,
            step,
            shading: false,
            transfer_function: constant_tf(alpha as f32, c),
            background: bg,
            ..RenderSettings::default()
        };
        let keep = (1.0 - alpha).powf(step * k as f64);
        let (fast, reference) = both_paths(&Renderer::new(&volume).unwrap(), &settings);
        for (image, tol) in [(reference, 1e-5), (fast, 1.0 / 255.0)] {
            assert_uniform_medium(&image, 1.0, c, bg, keep, tol, &format!("step {step}"));
        }
    }
}

#[test]
fn uniform_medium_on_anisotropic_grid_steps_by_the_smallest_spacing() {
    // x spacing 2 over 6 points: 10 world units, sampled every 1 (the y
    // spacing, the smallest): 11 samples, as on the isotropic grid.
    let volume = Volume::new([6, 5, 5], vec![1.0; 150])
        .unwrap()
        .with_spacing(DVec3::new(2.0, 1.0, 1.5))
        .unwrap();
    // The y-z face is 4 × 6: an 8 × 12 window fills it with 0.5-unit pixels.
    let settings = RenderSettings {
        width: 8,
        height: 12,
        shading: false,
        transfer_function: constant_tf(0.2, [1.0, 1.0, 1.0]),
        method: Method::Reference,
        ..RenderSettings::default()
    };
    let want = 1.0 - 0.8f64.powi(11);
    for px in render(&volume, &settings).pixels() {
        assert!((px[0] as f64 - want).abs() < 1e-5, "{px:?} vs {want}");
    }
}

#[test]
fn constant_volume_with_shading_gets_ambient_light_only() {
    // Zero gradient everywhere: the normal is undefined, so only ka lights it.
    let volume = Volume::new([5, 5, 5], vec![2.0; 125]).unwrap();
    let settings = RenderSettings {
        width: 6,
        height: 6,
        transfer_function: constant_tf(1.0, [0.5, 1.0, 1.0]),
        ..RenderSettings::default()
    };
    // The fast path stores colours in 16 bits: half a step is 7.6e-6.
    let (fast, reference) = both_paths(&Renderer::new(&volume).unwrap(), &settings);
    for (image, tol) in [(reference, 1e-6), (fast, 1e-5)] {
        for px in image.pixels() {
            assert!(
                (px[0] - 0.05).abs() < tol && (px[1] - 0.1).abs() < tol,
                "{px:?}"
            );
        }
    }
}

fn views() -> Vec<Camera> {
    let at = |x: f64, y: f64, z: f64| Camera {
        view_point: Some(DVec3::new(x, y, z)),
        ..Camera::default()
    };
    vec![
        Camera::default(),
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
fn fast_path_matches_the_reference_within_one_level() {
    let volumes = [
        blobs([24, 20, 28], DVec3::ONE),
        blobs([16, 30, 12], DVec3::new(1.5, 0.5, 2.0)),
    ];
    let mut worst = 0.0f32;
    for volume in &volumes {
        for camera in views() {
            for (step, tf, shading) in [
                (1.0, TransferFunction::default(), true),
                (0.5, colorful(), true),
                (0.7, colorful(), false),
            ] {
                let settings = RenderSettings {
                    width: 40,
                    height: 32,
                    camera,
                    step,
                    opacity_ramp: (0.0, 0.8),
                    transfer_function: tf,
                    shading,
                    background: [0.1, 0.1, 0.3],
                    ..RenderSettings::default()
                };
                let (fast, reference) = both_paths(&Renderer::new(volume).unwrap(), &settings);
                let what = format!("{camera:?} step {step}");
                worst = worst.max(assert_within_a_level(&fast, &reference, &what));
            }
        }
    }
    // The images are not trivially empty: the comparison means something.
    let image = render(
        &volumes[0],
        &RenderSettings {
            width: 40,
            height: 32,
            ..Default::default()
        },
    );
    assert!(image.pixels().iter().any(|p| p[0] > 0.3));
    println!(
        "largest fast-vs-reference difference: {worst:.6} ({:.3} of 1/255)",
        worst * 255.0
    );
}

#[test]
fn fast_path_is_bit_identical_for_any_thread_count() {
    let volume = blobs([30, 26, 22], DVec3::ONE);
    let settings = RenderSettings {
        width: 70,
        height: 50,
        step: 0.5,
        camera: views()[1],
        transfer_function: colorful(),
        ..RenderSettings::default()
    };
    let renderer = Renderer::new(&volume).unwrap();
    let images = [1, 2, 7].map(|n| render_on_threads(&renderer, &settings, n));
    assert!(images[0].pixels().iter().any(|p| p[3] > 0.5));
    assert!(images[0] == images[1] && images[1] == images[2]);
}

#[test]
fn opposite_views_of_a_mirror_symmetric_volume_are_mirror_images() {
    // Symmetric under x ↦ −x about the centre plane, asymmetric in y and z.
    let volume = Volume::from_fn([21, 18, 15], DVec3::ONE, DVec3::new(-10.0, 0.0, 0.0), |p| {
        let (y, z) = (p.y / 17.0, p.z / 14.0);
        let r2 = (p.x / 10.0).powi(2) + (y - 0.35).powi(2) + (z - 0.6).powi(2);
        ((1.0 - 2.0 * r2).max(0.0) * (0.5 + y * z)) as f32
    })
    .unwrap();
    let from = |x: f64| RenderSettings {
        width: 36,
        height: 30,
        camera: Camera {
            view_point: Some(DVec3::new(x, 8.5, 7.0)),
            ..Camera::default()
        },
        transfer_function: colorful(),
        ..RenderSettings::default()
    };
    let plus = render(&volume, &from(100.0));
    let minus = render(&volume, &from(-100.0));
    let mut differs_from_itself_mirrored = false;
    for row in 0..30 {
        for col in 0..36 {
            let (a, b) = (plus.get(col, row), minus.get(35 - col, row));
            for c in 0..4 {
                assert!((a[c] - b[c]).abs() < 1e-5, "({col}, {row}): {a:?} vs {b:?}");
            }
            differs_from_itself_mirrored |= (a[0] - plus.get(35 - col, row)[0]).abs() > 0.05;
        }
    }
    assert!(
        differs_from_itself_mirrored,
        "the test volume must not be symmetric in y"
    );
}

/// Intensity-weighted centroid (column, row) of channel 0, in pixel units
/// where pixel (c, r) covers [c, c+1) × [r, r+1).
fn centroid(image: &Image) -> (f64, f64) {
    let (mut sum, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for row in 0..image.height() {
        for col in 0..image.width() {
            let w = image.get(col, row)[0] as f64;
            sum += w;
            cx += w * (col as f64 + 0.5);
            cy += w * (row as f64 + 0.5);
        }
    }
    (cx / sum, cy / sum)
}

#[test]
fn a_one_voxel_feature_lands_where_the_projection_says() {
    let (dims, spacing, origin) = (
        [21, 33, 17],
        DVec3::new(1.0, 0.5, 2.0),
        DVec3::new(10.0, -4.0, 3.0),
    );
    let feature = (5, 7, 11);
    let mut data = vec![0.0f32; 21 * 33 * 17];
    data[feature.0 + 21 * (feature.1 + 33 * feature.2)] = 1.0;
    let volume = Volume::new(dims, data)
        .unwrap()
        .with_spacing(spacing)
        .unwrap()
        .with_origin(origin)
        .unwrap();
    let world = volume.world_position(feature.0, feature.1, feature.2);
    let (lo, hi) = volume.bounds();

    // Along −x (the default): screen right is +y, up is +z; the y-z face
    // (16 × 32 world units) fills a 32 × 64 image with 0.5-unit pixels.
    let settings = RenderSettings {
        width: 32,
        height: 64,
        shading: false,
        opacity_ramp: (0.0, 1.0),
        ..RenderSettings::default()
    };
    let image = render(&volume, &settings);
    let expect = ((world.y - lo.y) / 0.5, (hi.z - world.z) / 0.5);
    let got = centroid(&image);
    assert!(
        (got.0 - expect.0).abs() < 0.05 && (got.1 - expect.1).abs() < 0.05,
        "{got:?} vs {expect:?}"
    );

    // Along −y: screen right is −x.
    let settings = RenderSettings {
        width: 40,
        height: 64,
        camera: Camera {
            view_point: Some(volume.centre() + DVec3::new(0.0, 100.0, 0.0)),
            ..Camera::default()
        },
        ..settings
    };
    let image = render(&volume, &settings);
    let view = OrthographicView::frame(&settings.camera, volume.bounds(), 40, 64).unwrap();
    assert!((view.pixel_size - 0.5).abs() < 1e-12);
    let expect = ((hi.x - world.x) / 0.5, (hi.z - world.z) / 0.5);
    assert_eq!(view.project(world), expect);
    let got = centroid(&image);
    assert!(
        (got.0 - expect.0).abs() < 0.05 && (got.1 - expect.1).abs() < 0.05,
        "{got:?} vs {expect:?}"
    );
}

#[test]
fn anisotropic_spacing_keeps_the_physical_aspect() {
    // The same ball of radius 6 sampled on a cubic and on a stretched grid
    // must cover the same round silhouette.
    let ball = |dims: [usize; 3], spacing: DVec3| {
        Volume::from_fn(dims, spacing, DVec3::splat(-8.0), |p| {
            (6.0 - p.length()).max(0.0) as f32
        })
        .unwrap()
    };
    let silhouette = |volume: &Volume| {
        let settings = RenderSettings {
            width: 64,
            height: 64,
            opacity_ramp: (0.0, 1.0),
            camera: Camera {
                view_point: Some(DVec3::new(-30.0, -20.0, 10.0)),
                ..Camera::default()
            },
            ..RenderSettings::default()
        };
        let image = render(volume, &settings);
        let covered: Vec<(usize, usize)> = (0..64)
            .flat_map(|r| (0..64).map(move |c| (c, r)))
            .filter(|&(c, r)| image.get(c, r)[3] > 0.5)
            .collect();
        let width =
            covered.iter().map(|p| p.0).max().unwrap() - covered.iter().map(|p| p.0).min().unwrap();
        let height =
            covered.iter().map(|p| p.1).max().unwrap() - covered.iter().map(|p| p.1).min().unwrap();
        (width as i64, height as i64, covered.len() as i64)
    };
    let cubic = silhouette(&ball([33, 33, 33], DVec3::splat(0.5)));
    let stretched = silhouette(&ball([33, 17, 9], DVec3::new(0.5, 1.0, 2.0)));
    assert!((cubic.0 - cubic.1).abs() <= 1, "{cubic:?}");
    assert!((stretched.0 - stretched.1).abs() <= 1, "{stretched:?}");
    assert!(
        (cubic.0 - stretched.0).abs() <= 1,
        "{cubic:?} vs {stretched:?}"
    );
    // Coarser z sampling reconstructs the edge a little differently.
    assert!(
        (cubic.2 - stretched.2).abs() * 10 < cubic.2,
        "areas {cubic:?} vs {stretched:?}"
    );
}

#[test]
fn non_finite_values_are_refused_with_their_count() {
    let mut data = vec![0.5f32; 27];
    data[3] = f32::NAN;
    data[9] = f32::INFINITY;
    let volume = Volume::new([3, 3, 3], data).unwrap();
    let err = Renderer::new(&volume).err().unwrap().to_string();
    assert_eq!(err, "2 of 27 values are not finite (NaN or infinite)");
}

#[test]
fn invalid_settings_are_refused_by_name() {
    let volume = blobs([5, 5, 5], DVec3::ONE);
    let renderer = Renderer::new(&volume).unwrap();
    let cases: Vec<(RenderSettings, &str)> = vec![
        (
            RenderSettings {
                width: 0,
                ..Default::default()
            },
            "width 0",
        ),
        (
            RenderSettings {
                step: 0.0,
                ..Default::default()
            },
            "step 0",
        ),
        (
            RenderSettings {
                step: -1.0,
                ..Default::default()
            },
            "step -1",
        ),
        (
            RenderSettings {
                step: 1e-9,
                ..Default::default()
            },
            "too small",
        ),
        (
            RenderSettings {
                opacity_ramp: (0.5, 0.5),
                ..Default::default()
            },
            "0 <= p < q <= 1",
        ),
        (
            RenderSettings {
                background: [2.0, 0.0, 0.0],
                ..Default::default()
            },
            "background",
        ),
        (
            RenderSettings {
                camera: Camera {
                    up: DVec3::X,
                    ..Camera::default()
                },
                ..Default::default()
            },
            "parallel",
        ),
    ];
    for (settings, expect) in cases {
        let err = renderer
            .render(FrameRequest::new(&settings))
            .unwrap_err()
            .to_string();
        assert!(err.contains(expect), "{err}");
    }
}
