//! Ambient occlusion (`RenderSettings::ambient_occlusion`, see
//! `volray_core::shadows::ambient`): closed forms of its rays on known
//! geometry, the fast path's ambient volume against the reference's
//! marched rays, the pictures of both paths, thread invariance, and what
//! is refused.

mod common;

use common::{blobs, colorful, on_the_reference, render_on_threads, tf};
use volray_core::camera::Camera;
use volray_core::glam::DVec3;
use volray_core::scene::{Look, Mix, Scene, SceneSettings};
use volray_core::shadows::ambient::{AmbientRays, reference_occlusion};
use volray_core::shadows::ambient_volume::AmbientVolume;
use volray_core::{
    Blend, Classification, Image, Phong, RenderError, RenderSettings, Renderer, SettingError,
    Volume,
};
use volray_core::{FrameRequest, Render, Rendered};

/// The reference's and the fast path's occlusion of every voxel of a grid
/// of unit opacities `alpha`, the rays' spacing apart.
fn both(alpha: &[f32], dims: [usize; 3], rays: &AmbientRays) -> (Vec<f32>, AmbientVolume) {
    let [nx, ny, _] = dims;
    let marched = reference_occlusion(alpha, dims, rays);
    let at = |i, j, k| alpha[i + nx * (j + ny * k)];
    let computed = AmbientVolume::compute(dims, rays, at);
    (marched, computed)
}

/// Both paths' occlusion at `voxel` is `want`: the march's to 1e-6, the
/// fast path's (kept in 16 bits) to 1e-4.
fn assert_occlusion((marched, computed): &(Vec<f32>, AmbientVolume), voxel: [usize; 3], want: f64) {
    let [nx, ny, _] = computed.dims();
    let [i, j, k] = voxel;
    let m = marched[i + nx * (j + ny * k)] as f64;
    let c = computed.at(voxel) as f64;
    assert!(
        (m - want).abs() < 1e-6,
        "{voxel:?}: marched {m}, want {want}"
    );
    assert!(
        (c - want).abs() < 1e-4,
        "{voxel:?}: computed {c}, want {want}"
    );
}

/// The weights of the rays up from a surface facing +z: 1 straight up,
/// `1/√2` on the four edges, `1/√3` on the four corners.
const UP: f64 = 1.0 + 4.0 * std::f64::consts::FRAC_1_SQRT_2 + 4.0 / 1.732_050_807_568_877_2;

#[test]
fn a_flat_open_surface_sees_the_whole_sky_and_a_crease_less() {
    // An opaque slab fills z = 0..=6 of a 20³ grid, and a wall x = 0..=6
    // stands on it along y. On the slab's top away from the wall, the
    // rays of the hemisphere facing up (+z, the way out of the slab) all
    // leave: A = 1. Next to the wall, the three leaning into it are
    // stopped at their first sample: A = 1 − (1/√2 + 2/√3)/UP. Inside the
    // slab the opacity does not change, every ray counts, and none gets
    // out; far above nothing is in reach.
    let dims = [20, 20, 20];
    let opaque = |i: usize, k: usize| k <= 6 || i <= 6;
    let alpha: Vec<f32> = (0..8000)
        .map(|v| f32::from(u8::from(opaque(v % 20, v / 400))))
        .collect();
    let rays = AmbientRays::new(4.0, DVec3::ONE);
    let both = both(&alpha, dims, &rays);
    let crease = 1.0 - (std::f64::consts::FRAC_1_SQRT_2 + 2.0 / 3f64.sqrt()) / UP;
    for (voxel, want) in [
        ([14, 10, 6], 1.0),
        ([12, 15, 6], 1.0),
        ([7, 10, 6], crease),
        ([14, 10, 3], 0.0),
        ([14, 10, 16], 1.0),
    ] {
        assert_occlusion(&both, voxel, want);
    }
}

#[test]
fn in_a_uniform_medium_each_ray_keeps_the_transmittance_of_its_length() {
    // Opacity 0.1 per voxel's length everywhere; from the centre of a 21³
    // grid no ray of radius 4 reaches a face, so
    // A = 1/26 · Σ_d 0.9^(n_d · |d·spacing|), with n_d the whole steps
    // nearest 4 voxels (of the smallest spacing).
    let dims = [21, 21, 21];
    let alpha = vec![0.1f32; 21 * 21 * 21];
    for spacing in [DVec3::ONE, DVec3::new(1.0, 1.0, 2.0)] {
        let rays = AmbientRays::new(4.0, spacing);
        let want: f64 = (-1..=1)
            .flat_map(|z| (-1..=1).flat_map(move |y| (-1..=1).map(move |x| (x, y, z))))
            .filter(|&d| d != (0, 0, 0))
            .map(|(x, y, z)| {
                let length = (DVec3::new(x as f64, y as f64, z as f64) * spacing).length();
                let steps = (4.0 / length).round().max(1.0);
                0.9f64.powf(steps * length)
            })
            .sum::<f64>()
            / 26.0;
        assert_occlusion(&both(&alpha, dims, &rays), [10, 10, 10], want);
    }
}

#[test]
fn the_ambient_volume_is_the_marched_occlusion_of_every_voxel() {
    // From a voxel the rays' samples are voxels: the fast path's products
    // are the reference's, to rounding and the u16 it keeps. Blobs on two
    // grids, one of unequal spacings, at two radii.
    for (volume, radius) in [
        (blobs([26, 22, 18], DVec3::ONE, DVec3::ZERO), 3.0),
        (
            blobs([20, 24, 14], DVec3::new(1.5, 0.5, 2.0), DVec3::ZERO),
            6.5,
        ),
    ] {
        let dims = volume.dims();
        let alpha: Vec<f32> = (volume.values().iter())
            .map(|&f| (f * 0.8).clamp(0.0, 1.0))
            .collect();
        let rays = AmbientRays::new(radius, volume.spacing());
        let (marched, computed) = both(&alpha, dims, &rays);
        let mut worst = 0.0f32;
        let mut darkest = 1.0f32;
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let m = marched[i + dims[0] * (j + dims[1] * k)];
                    worst = worst.max((m - computed.at([i, j, k])).abs());
                    darkest = darkest.min(m);
                }
            }
        }
        assert!(worst < 2e-5, "{dims:?}: {worst}");
        assert!(darkest < 0.5, "{dims:?}: nothing occluded ({darkest})");
    }
}

/// A ball of radius 6 a voxel over a plate (z = 3..=5) in a 36³
/// grid, seen from above at a slant, unlit or lit, with ambient occlusion
/// of radius 6.
fn ball_near_plate() -> Volume {
    Volume::from_fn([36, 36, 36], DVec3::ONE, DVec3::ZERO, |p| {
        let ball = (p - DVec3::new(18.0, 18.0, 13.0)).length() <= 6.0;
        let plate = (3.0..=5.0).contains(&p.z);
        f32::from(u8::from(ball || plate))
    })
    .unwrap()
}

fn occluded(tf: volray_core::TransferFunction, radius: Option<f64>) -> RenderSettings {
    RenderSettings {
        width: 44,
        height: 40,
        camera: Camera {
            view_point: Some(DVec3::new(40.0, -60.0, 70.0)),
            ..Camera::default()
        },
        transfer_function: tf,
        // Ambient light that shows: 0.5 of the total.
        phong: Phong {
            ambient: [0.5; 3],
            diffuse: [0.4; 3],
            specular: [0.1; 3],
            ..Phong::default()
        },
        ambient_occlusion: radius,
        ..RenderSettings::default()
    }
}

#[test]
fn the_plate_under_the_ball_gets_less_ambient_light_than_the_plate_in_the_open() {
    // The contact shadow ambient occlusion is for: from the plate's top
    // under the ball, the ray straight up and the four on the edges meet
    // the ball; only the four on the corners get past it. In the open all
    // nine leave.
    let volume = ball_near_plate();
    let dims = volume.dims();
    let alpha: Vec<f32> = volume.values().to_vec();
    let rays = AmbientRays::new(6.0, DVec3::ONE);
    let (_, computed) = both(&alpha, dims, &rays);
    let open = computed.at([3, 3, 5]) as f64;
    let under = computed.at([18, 18, 5]) as f64;
    let corners = 4.0 / 3f64.sqrt() / UP;
    assert!((open - 1.0).abs() < 1e-4, "open {open}");
    assert!((under - corners).abs() < 1e-4, "under the ball {under}");
    // The ball's top sees the sky; its bottom faces the plate a voxel
    // away, which every ray of its hemisphere meets.
    let top = computed.at([18, 18, 19]);
    let bottom = computed.at([18, 18, 7]);
    assert!(top > 0.999 && bottom < 1e-4, "top {top}, bottom {bottom}");
}

#[test]
fn the_fast_paths_are_within_a_level_of_the_marched_occlusion() {
    // Both paths light each voxel, or interpolate to each sample, the A
    // the reference marches from the voxels (to the u16 the fast path
    // keeps): the pictures differ as they do without ambient occlusion.
    let volumes = [
        blobs([28, 24, 30], DVec3::ONE, DVec3::new(-2.0, 5.0, 1.0)),
        blobs([20, 32, 16], DVec3::new(1.5, 0.5, 2.0), DVec3::ZERO),
    ];
    let mut worst = [0.0f32; 2];
    for volume in &volumes {
        let renderer = Renderer::new(volume).unwrap();
        for (classification, shading, radius) in [
            (Classification::Pre, true, 8.0),
            (Classification::Pre, false, 3.0),
            (Classification::Post, true, 5.0),
            (Classification::Post, false, 8.0),
        ] {
            let settings = RenderSettings {
                classification,
                shading,
                ..occluded(colorful(), Some(radius))
            };
            let fast = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let reference = renderer
                .render(FrameRequest::new(&on_the_reference(&settings)))
                .unwrap()
                .image();
            let plain = (renderer
                .render(FrameRequest::new(&on_the_reference(&RenderSettings {
                    ambient_occlusion: None,
                    ..settings.clone()
                })))
                .map(Rendered::image))
            .unwrap();
            let diff = fast.max_abs_diff(&reference).unwrap();
            let what = format!("{:?} {classification:?} lit {shading}", volume.dims());
            let n = usize::from(classification == Classification::Post);
            assert!(diff <= 1.0 / 255.0, "{what}: fast vs reference {diff}");
            let change = plain.max_abs_diff(&reference).unwrap();
            assert!(change > 10.0 / 255.0, "{what}: changed only {change}");
            worst[n] = worst[n].max(diff);
        }
    }
    eprintln!(
        "worst fast vs reference with ambient occlusion: pre {}/255, post {}/255",
        worst[0] * 255.0,
        worst[1] * 255.0
    );
}

#[test]
fn ambient_occlusion_is_the_same_on_one_thread_and_on_several() {
    let volume = blobs([30, 26, 22], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    for classification in [Classification::Pre, Classification::Post] {
        let settings = RenderSettings {
            classification,
            shadows: true,
            light_direction: Some(DVec3::new(0.3, 1.0, 0.7)),
            ..occluded(colorful(), Some(5.0))
        };
        let one = render_on_threads(&renderer, &settings, 1);
        let three = render_on_threads(&renderer, &settings, 3);
        assert_eq!(one.pixels(), three.pixels(), "{classification:?}");
    }
}

#[test]
fn without_ambient_occlusion_nothing_is_kept_and_frames_are_as_before() {
    let volume = blobs([20, 20, 20], DVec3::ONE, DVec3::ZERO);
    let settings = occluded(colorful(), None);
    for classification in [Classification::Pre, Classification::Post] {
        let settings = RenderSettings {
            classification,
            ..settings.clone()
        };
        let used = Renderer::new(&volume).unwrap();
        used.render(FrameRequest::new(&RenderSettings {
            ambient_occlusion: Some(4.0),
            ..settings.clone()
        }))
        .unwrap()
        .image();
        let after = used.render(FrameRequest::new(&settings)).unwrap().image();
        let fresh = Renderer::new(&volume)
            .unwrap()
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        assert_eq!(after.pixels(), fresh.pixels(), "{classification:?}");
    }
}

#[test]
fn a_kept_ambient_volume_is_computed_again_for_another_radius_or_transfer_function() {
    // The second frame of each pair must equal a fresh renderer's.
    let volume = blobs([24, 20, 18], DVec3::ONE, DVec3::ZERO);
    let sparse = tf(r#"{"opacity": [[0, 0], [0.5, 0], [1, 1]]}"#);
    let first = occluded(colorful(), Some(3.0));
    for second in [occluded(colorful(), Some(7.0)), occluded(sparse, Some(3.0))] {
        let used = Renderer::new(&volume).unwrap();
        let before: Image = used.render(FrameRequest::new(&first)).unwrap().image();
        let after = used.render(FrameRequest::new(&second)).unwrap().image();
        let fresh = Renderer::new(&volume)
            .unwrap()
            .render(FrameRequest::new(&second))
            .unwrap()
            .image();
        assert_eq!(after.pixels(), fresh.pixels());
        assert_ne!(before.pixels(), after.pixels());
    }
}

#[test]
fn ambient_occlusion_is_refused_for_projections_pieces_odd_radii_and_scenes() {
    let volume = blobs([12, 12, 12], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let on = RenderSettings {
        width: 8,
        height: 8,
        ambient_occlusion: Some(4.0),
        ..RenderSettings::default()
    };
    let refused = |settings: RenderSettings| match renderer
        .render(FrameRequest::new(&settings))
        .map(Rendered::image)
    {
        Err(RenderError::Setting(e)) => e,
        other => panic!("expected a refusal, got {:?}", other.map(|_| ())),
    };
    assert!(matches!(
        refused(RenderSettings {
            blend: Blend::Maximum,
            ..on.clone()
        }),
        SettingError::AmbientOcclusion(_)
    ));
    for radius in [0.5, 33.0, f64::NAN, f64::INFINITY] {
        let e = refused(RenderSettings {
            ambient_occlusion: Some(radius),
            ..on.clone()
        });
        assert!(
            matches!(e, SettingError::AmbientOcclusionRadius(_)),
            "{radius}: {e}"
        );
    }
    // Unlit frames take it: the colour is the ambient light's.
    renderer
        .render(FrameRequest::new(&RenderSettings {
            shading: false,
            ..on.clone()
        }))
        .unwrap()
        .image();
    let layers = vec![
        Renderer::new(&volume).unwrap(),
        Renderer::new(&volume).unwrap(),
    ];
    let scene = Scene::new(layers).unwrap();
    let request = SceneSettings {
        looks: vec![Look::of(&on); 2],
        settings: on,
        mix: Mix::Composite,
    };
    let e = scene.render(FrameRequest::new(&request)).unwrap_err();
    assert!(e.to_string().contains("ambient occlusion"), "{e}");
}
