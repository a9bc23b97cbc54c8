//! Shadows (`RenderSettings::shadows`, see `volray_core::shadows`): the
//! shadow a known geometry casts, the fast path against the reference's
//! marched shadow rays, thread invariance, and what is refused.

mod common;

use common::{blobs, colorful, on_the_reference, render_on_threads, tf};
use volray_core::camera::Camera;
use volray_core::glam::DVec3;
use volray_core::scene::{Look, Mix, Scene, SceneSettings};
use volray_core::shadows::light_volume::LightVolume;
use volray_core::shadows::opacities::VoxelOpacities;
use volray_core::shadows::{ShadowRay, reference_light};
use volray_core::{
    Blend, Classification, Image, RenderError, RenderSettings, Renderer, SettingError, Volume,
};
use volray_core::{FrameRequest, Render, Rendered};

/// A ball of radius 6 voxels centred at (20, 20, 24) over a plate filling
/// z = 4..=6, in a 40³ grid of unit spacing: 1 inside, 0 outside.
fn ball_over_plate() -> Volume {
    Volume::from_fn([40, 40, 40], DVec3::ONE, DVec3::ZERO, |p| {
        let ball = (p - DVec3::new(20.0, 20.0, 24.0)).length() <= 6.0;
        let plate = (4.0..=6.0).contains(&p.z) && (2.0..=37.0).contains(&p.x);
        f32::from(u8::from(ball || (plate && (2.0..=37.0).contains(&p.y))))
    })
    .unwrap()
}

/// Opaque where the value is 1, transparent where it is 0.
fn opaque_above_half() -> volray_core::TransferFunction {
    tf(r#"{"opacity": [[0.0, 0.0], [0.4, 0.0], [0.6, 1.0], [1.0, 1.0]]}"#)
}

/// The shadowed voxels of the plate's top layer (z = 6), light below one
/// half: their centroid, and their extent along x and y through it.
fn shadow_on_the_plate(light: impl Fn(usize, usize) -> f32) -> (f64, f64, f64, f64) {
    let shadowed: Vec<(usize, usize)> = (0..40)
        .flat_map(|j| (0..40).map(move |i| (i, j)))
        .filter(|&(i, j)| (3..=36).contains(&i) && (3..=36).contains(&j) && light(i, j) < 0.5)
        .collect();
    assert!(!shadowed.is_empty(), "no shadow on the plate");
    let n = shadowed.len() as f64;
    let cx = shadowed.iter().map(|p| p.0 as f64).sum::<f64>() / n;
    let cy = shadowed.iter().map(|p| p.1 as f64).sum::<f64>() / n;
    let (row, column) = (cy.round() as usize, cx.round() as usize);
    let along_x = shadowed.iter().filter(|p| p.1 == row).count() as f64;
    let along_y = shadowed.iter().filter(|p| p.0 == column).count() as f64;
    (cx, cy, along_x, along_y)
}

#[test]
fn a_ball_over_a_plate_casts_the_shadow_the_geometry_predicts() {
    // The light from above, tilted towards +x by atan(1/2): the ball's
    // shadow on the plate's top (18 voxels below its centre) is an
    // ellipse centred 9 voxels towards −x, of semi-axes 6 across the tilt
    // and 6·√5/2 ≈ 6.7 along it. The shadow voxels span the diameters to
    // within a voxel at each end.
    let volume = ball_over_plate();
    let dims = volume.dims();
    let alpha: Vec<f32> = volume.values().to_vec();
    let to_light = DVec3::new(1.0, 0.0, 2.0);
    let ray = ShadowRay::new(to_light, dims, DVec3::ONE, 1.0);
    let marched = reference_light(&alpha, dims, &ray);
    let mut opacities = VoxelOpacities::from_fn(dims, 1.0, |i, j, k| alpha[volume.index(i, j, k)]);
    let swept = LightVolume::sweep(DVec3::ONE, to_light, &mut opacities);
    let top = 6;
    for (what, light) in [
        (
            "marched",
            &(|i, j| marched[volume.index(i, j, top)]) as &dyn Fn(usize, usize) -> f32,
        ),
        ("swept", &|i, j| swept.at([i, j, top])),
    ] {
        let (cx, cy, along_x, along_y) = shadow_on_the_plate(light);
        assert!((cx - 11.0).abs() <= 1.0, "{what}: centre x {cx}");
        assert!((cy - 20.0).abs() <= 1.0, "{what}: centre y {cy}");
        let (a, b) = (6.0 * 5f64.sqrt() / 2.0, 6.0);
        assert!(
            (along_x - 2.0 * a).abs() <= 2.0,
            "{what}: {along_x} along x"
        );
        assert!(
            (along_y - 2.0 * b).abs() <= 2.0,
            "{what}: {along_y} along y"
        );
    }
    // Straight down: a disc of radius 6 right under the centre.
    let ray = ShadowRay::new(DVec3::Z, dims, DVec3::ONE, 1.0);
    let marched = reference_light(&alpha, dims, &ray);
    let (cx, cy, along_x, along_y) = shadow_on_the_plate(|i, j| marched[volume.index(i, j, top)]);
    assert!((cx - 20.0).abs() <= 1.0 && (cy - 20.0).abs() <= 1.0);
    assert!((along_x - 12.0).abs() <= 2.0 && (along_y - 12.0).abs() <= 2.0);
}

/// The ball and plate seen from above, lit from `light`.
fn from_above(light: DVec3, shadows: bool) -> RenderSettings {
    RenderSettings {
        width: 40,
        height: 40,
        camera: Camera {
            view_point: Some(DVec3::new(19.5, 19.5, 200.0)),
            up: DVec3::Y,
            ..Camera::default()
        },
        transfer_function: opaque_above_half(),
        light_direction: Some(light),
        shadows,
        ..RenderSettings::default()
    }
}

#[test]
fn in_the_shadow_the_plate_keeps_its_ambient_light_and_elsewhere_all_of_it() {
    let volume = ball_over_plate();
    let renderer = Renderer::new(&volume).unwrap();
    // World (x, y) to the pixel: the window is the box's 40 × 40.
    let px = |image: &Image, x: f64, y: f64| {
        let (col, row) = (x.round() as usize, 39 - y.round() as usize);
        image.pixels()[row * 40 + col]
    };
    for method in [volray_core::Method::Fast, volray_core::Method::Reference] {
        let render = |light, shadows| {
            let settings = from_above(light, shadows);
            let settings = RenderSettings { method, ..settings };
            renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image()
        };
        // Lit from above and +x: inside the shadow, clear of the ball, the
        // plate keeps the ambient term (0.1) only; unshadowed it takes
        // more. Away from the shadow the plate is evenly lit, a little
        // less than without shadows: its surface voxels' shadow rays
        // start inside the cells their own opacity fills, and the
        // interpolated opacity there holds back a tenth of the light.
        let oblique = DVec3::new(1.0, 0.0, 2.0);
        let (lit, shadowed) = (render(oblique, false), render(oblique, true));
        let dark = px(&shadowed, 9.0, 20.0);
        let bright = px(&lit, 9.0, 20.0);
        assert!(dark[0] < 0.13, "{method:?}: shadowed plate {dark:?}");
        assert!(bright[0] > 0.5, "{method:?}: lit plate {bright:?}");
        let away = px(&shadowed, 33.0, 6.0);
        for (x, y) in [(33.0, 33.0), (30.0, 20.0), (6.0, 34.0)] {
            let here = px(&shadowed, x, y);
            assert!(
                (here[0] - away[0]).abs() < 1e-6,
                "{method:?} {x},{y}: {here:?}"
            );
        }
        assert!(
            away[0] > 0.9 * px(&lit, 33.0, 6.0)[0],
            "{method:?}: {away:?}"
        );
        // Lit from straight above, the plate's surface voxels see the light
        // whole: away from the ball, shadows change nothing.
        let (lit, shadowed) = (render(DVec3::Z, false), render(DVec3::Z, true));
        for (x, y) in [(33.0, 6.0), (33.0, 33.0), (30.0, 20.0), (6.0, 34.0)] {
            let (a, b) = (px(&shadowed, x, y), px(&lit, x, y));
            assert!(
                a.iter().zip(&b).all(|(a, b)| (a - b).abs() < 1e-6),
                "{method:?} at {x},{y}: {a:?} vs {b:?}"
            );
        }
    }
}

/// A 48×40 frame with shadows, seen from above and the side, lit from
/// `light` (`None`: the key light).
fn shadowed(
    tf: volray_core::TransferFunction,
    light: Option<DVec3>,
    classification: Classification,
    step: f64,
) -> RenderSettings {
    RenderSettings {
        width: 48,
        height: 40,
        camera: Camera {
            view_point: Some(DVec3::new(60.0, -80.0, 50.0)),
            ..Camera::default()
        },
        step,
        transfer_function: tf,
        light_direction: light,
        classification,
        shadows: true,
        ..RenderSettings::default()
    }
}

#[test]
fn the_fast_paths_are_within_two_levels_of_the_marched_shadows_on_smooth_volumes() {
    // Blobs on two grids (one of unequal spacings) and a torus, lights
    // along an axis and oblique, steps 1 and 0.5, both classifications.
    // Measured: 0.22 to 0.64/255 on the blobs, 2.06/255 post-classified
    // on unequal spacings; 0.24 to 1.16/255 on the torus.
    let torus = Volume::from_fn([30, 30, 20], DVec3::ONE, DVec3::ZERO, |p| {
        let q = p - DVec3::new(14.5, 14.5, 9.5);
        let ring = (q.x.hypot(q.y) - 9.0).hypot(q.z);
        (-(ring / 3.5).powi(2)).exp() as f32
    })
    .unwrap();
    let volumes = [
        blobs([28, 24, 30], DVec3::ONE, DVec3::new(-2.0, 5.0, 1.0)),
        blobs([20, 32, 16], DVec3::new(1.5, 0.5, 2.0), DVec3::ZERO),
        torus,
    ];
    let mut worst = 0.0f32;
    for volume in &volumes {
        let renderer = Renderer::new(volume).unwrap();
        for (light, classification, step) in [
            (DVec3::Z, Classification::Pre, 1.0),
            (DVec3::new(1.0, -0.5, 2.0), Classification::Pre, 0.5),
            (DVec3::new(0.8, -0.3, 0.5), Classification::Pre, 1.0),
            (DVec3::new(-1.0, 1.0, 1.0), Classification::Post, 1.0),
        ] {
            let settings = shadowed(colorful(), Some(light), classification, step);
            let fast = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let reference = renderer
                .render(FrameRequest::new(&on_the_reference(&settings)))
                .unwrap()
                .image();
            let plain = renderer
                .render(FrameRequest::new(&RenderSettings {
                    shadows: false,
                    ..settings.clone()
                }))
                .unwrap()
                .image();
            let diff = fast.max_abs_diff(&reference).unwrap();
            let what = format!("{:?} light {light} {classification:?}", volume.dims());
            // Post-classified samples read the light volume between voxels,
            // the reference marches from each sample: 2.06/255 measured on
            // the grid of unequal spacings.
            let bound = match classification {
                Classification::Pre => 2.0,
                Classification::Post => 2.5,
            };
            assert!(diff <= bound / 255.0, "{what}: fast vs reference {diff}");
            // The shadows change the picture: the comparison means something.
            let change = plain.max_abs_diff(&reference).unwrap();
            assert!(
                change > 10.0 / 255.0,
                "{what}: shadows changed only {change}"
            );
            worst = worst.max(diff);
        }
    }
    eprintln!("worst fast vs reference with shadows: {worst}");
}

#[test]
fn where_the_sweep_is_known_to_part_from_the_march_it_stays_within_its_measured_bounds() {
    // Not yet within 2/255 (see docs/options.md, "Shadows"): the camera's
    // key light on the blobs (3.8/255 measured), and the binary ball over
    // the plate, whose light jumps from 0 to 1 across one voxel at every
    // surface (24/255 under an oblique light, 43/255 post-classified, where
    // samples between voxels interpolate the light volume across the
    // jump). These bounds catch a regression, not a success.
    let cases = [
        (
            blobs([28, 24, 30], DVec3::ONE, DVec3::new(-2.0, 5.0, 1.0)),
            colorful(),
            None,
            Classification::Pre,
            5.0,
        ),
        (
            ball_over_plate(),
            opaque_above_half(),
            Some(DVec3::new(1.0, -0.5, 2.0)),
            Classification::Pre,
            26.0,
        ),
    ];
    for (volume, tf, light, classification, bound) in cases {
        let renderer = Renderer::new(&volume).unwrap();
        let settings = shadowed(tf, light, classification, 0.5);
        let fast = renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        let reference = renderer
            .render(FrameRequest::new(&on_the_reference(&settings)))
            .unwrap()
            .image();
        let diff = fast.max_abs_diff(&reference).unwrap() * 255.0;
        assert!(diff <= bound, "{:?} {light:?}: {diff}/255", volume.dims());
    }
}

#[test]
fn shadows_are_the_same_on_one_thread_and_on_several() {
    let volume = blobs([30, 26, 22], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    for classification in [Classification::Pre, Classification::Post] {
        let settings = RenderSettings {
            width: 36,
            height: 30,
            transfer_function: colorful(),
            light_direction: Some(DVec3::new(0.3, 1.0, 0.7)),
            classification,
            shadows: true,
            ..RenderSettings::default()
        };
        let one = render_on_threads(&renderer, &settings, 1);
        let three = render_on_threads(&renderer, &settings, 3);
        assert_eq!(one.pixels(), three.pixels(), "{classification:?}");
    }
}

#[test]
fn without_shadows_the_light_volume_is_not_kept_and_frames_are_as_before() {
    // A frame with shadows, then one without: the second equals a
    // renderer's that never drew a shadow.
    let volume = blobs([20, 20, 20], DVec3::ONE, DVec3::ZERO);
    let settings = RenderSettings {
        width: 30,
        height: 30,
        transfer_function: colorful(),
        light_direction: Some(DVec3::new(1.0, 1.0, 1.0)),
        ..RenderSettings::default()
    };
    let used = Renderer::new(&volume).unwrap();
    used.render(FrameRequest::new(&RenderSettings {
        shadows: true,
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
    assert_eq!(after.pixels(), fresh.pixels());
}

#[test]
fn shadows_are_refused_where_nothing_is_lit_or_several_volumes_meet() {
    let volume = blobs([12, 12, 12], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let shadows = RenderSettings {
        width: 8,
        height: 8,
        shadows: true,
        ..RenderSettings::default()
    };
    for settings in [
        RenderSettings {
            blend: Blend::Maximum,
            ..shadows.clone()
        },
        RenderSettings {
            shading: false,
            ..shadows.clone()
        },
    ] {
        match renderer
            .render(FrameRequest::new(&settings))
            .map(Rendered::image)
        {
            Err(RenderError::Setting(SettingError::Shadows(why))) => {
                assert!(
                    why.contains("projection") || why.contains("lighting"),
                    "{why}"
                )
            }
            other => panic!("{:?}: {other:?}", settings.blend),
        }
    }
    let other = blobs([12, 12, 12], DVec3::ONE, DVec3::ZERO);
    let layers = vec![
        Renderer::new(&volume).unwrap(),
        Renderer::new(&other).unwrap(),
    ];
    let scene = Scene::new(layers).unwrap();
    let request = SceneSettings {
        looks: vec![Look::of(&shadows); 2],
        settings: shadows,
        mix: Mix::Composite,
    };
    let error = scene.render(FrameRequest::new(&request)).unwrap_err();
    assert!(error.to_string().contains("shadows"), "{error}");
}
