//! Classification options through the whole renderer: Levoy's isovalue
//! contours and gradient-magnitude opacity, on both paths (the fast path
//! held to the reference within 1/255), and their settings.

mod common;

use common::{assert_within_a_level, both_paths, tf};
use volray_core::camera::Camera;
use volray_core::glam::DVec3;
use volray_core::{FrameRequest, Render, Rendered};
use volray_core::{Image, IsoSurface, RenderError, RenderSettings, Renderer, SettingError, Volume};

/// The fast and the reference image of one frame, which must agree within
/// 1/255 per channel.
fn agreeing_paths(renderer: &Renderer, settings: &RenderSettings, what: &str) -> (Image, Image) {
    let (fast, reference) = both_paths(renderer, settings);
    assert_within_a_level(&fast, &reference, what);
    (fast, reference)
}

/// The distance from the centre of [−1, 1]³ on `n`³ voxels.
fn distance_field(n: usize) -> Volume {
    let h = 2.0 / (n - 1) as f64;
    Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
        p.length() as f32
    })
    .unwrap()
}

#[test]
fn an_iso_surface_of_a_distance_field_is_a_hollow_shell() {
    // The sphere |p| = 0.6, r = 1.5 voxels of 1/16: opacity only within
    // 0.094 of the sphere. Looking along −x (screen right +y, up +z) on 41²
    // pixels of 2/41, pixel (20, 20) looks through the centre, pixel
    // (32, 20) passes 0.585 from it, grazing the shell, and (37, 20) passes
    // 0.83 from it, outside the shell.
    let volume = distance_field(33);
    let renderer = Renderer::new(&volume).unwrap();
    let settings = RenderSettings {
        width: 41,
        height: 41,
        transfer_function: tf(r#"{"opacity": [[0, 0.2]]}"#),
        iso: Some(IsoSurface {
            value: 0.6,
            thickness: 1.5,
        }),
        background: [0.0, 0.0, 0.2],
        ..RenderSettings::default()
    };
    let (_, image) = agreeing_paths(&renderer, &settings, "default view");
    let alpha = |col, row| image.get(col, row)[3];
    // Through the centre the ray crosses the shell twice, and sees nothing
    // of the inside (a value threshold at 0.6 would fill the ball).
    assert!(
        alpha(20, 20) > 0.2 && alpha(20, 20) < 0.8,
        "{}",
        alpha(20, 20)
    );
    // A ray grazing the shell runs through more of it: limb brightening,
    // the mark of a shell.
    for (col, row) in [(32, 20), (8, 20), (20, 32), (20, 8)] {
        assert!(alpha(col, row) > alpha(20, 20) + 0.1, "{col},{row}");
    }
    // Outside the shell: exactly the background.
    for (col, row) in [(37, 20), (20, 3), (0, 0), (40, 40)] {
        assert_eq!(image.get(col, row), [0.0, 0.0, 0.2, 0.0], "{col},{row}");
    }
    // A filled ball under the same opacity, for contrast: its centre ray
    // meets 1.2 units of material instead of two thin crossings.
    let ball = RenderSettings {
        transfer_function: tf(r#"{"opacity": [[0.34, 0.2], [0.35, 0]]}"#),
        iso: None,
        ..settings.clone()
    };
    let filled = renderer.render(FrameRequest::new(&ball)).unwrap().image();
    assert!(filled.get(20, 20)[3] > alpha(20, 20) + 0.2);

    // Other views and steps, and an anisotropic grid, on both paths.
    let views = [
        Camera {
            view_point: Some(DVec3::new(3.0, 4.0, 5.0)),
            ..Camera::default()
        },
        Camera {
            view_point: Some(DVec3::new(0.2, -6.0, 0.3)),
            up: DVec3::new(1.0, 0.0, 0.2),
            ..Camera::default()
        },
    ];
    for camera in views {
        for step in [1.0, 0.5] {
            let s = RenderSettings {
                width: 37,
                height: 29,
                camera,
                step,
                ..settings.clone()
            };
            agreeing_paths(&renderer, &s, &format!("{camera:?} step {step}"));
        }
    }
    let stretched = Volume::from_fn(
        [33, 17, 40],
        DVec3::new(1.0 / 16.0, 1.0 / 8.0, 0.05),
        DVec3::new(-1.0, -1.0, -1.0),
        |p| p.length() as f32,
    )
    .unwrap();
    let renderer = Renderer::new(&stretched).unwrap();
    let (_, image) = agreeing_paths(&renderer, &settings, "anisotropic");
    assert!(image.pixels().iter().any(|p| p[3] > 0.2));
}

#[test]
fn changing_the_iso_surface_reclassifies() {
    // The fast path keeps its classified bricks between frames: a new
    // isovalue must not reuse them.
    let volume = distance_field(25);
    let shared = Renderer::new(&volume).unwrap();
    let at = |value| RenderSettings {
        width: 30,
        height: 30,
        iso: Some(IsoSurface {
            value,
            thickness: 1.0,
        }),
        ..RenderSettings::default()
    };
    let first = shared.render(FrameRequest::new(&at(0.4))).unwrap().image();
    let second = shared.render(FrameRequest::new(&at(0.8))).unwrap().image();
    let fresh = Renderer::new(&volume)
        .unwrap()
        .render(FrameRequest::new(&at(0.8)))
        .unwrap()
        .image();
    assert_eq!(second, fresh);
    assert_ne!(first, second);
}

/// Zero for `y < 7.5`, one beyond: two uniform regions and an edge
/// between them, on 9 × 17 × 9 unit voxels.
fn step_along_y() -> Volume {
    Volume::from_fn([9, 17, 9], DVec3::ONE, DVec3::ZERO, |p| {
        if p.y < 7.5 { 0.0 } else { 1.0 }
    })
    .unwrap()
}

#[test]
fn gradient_opacity_hides_uniform_regions_and_keeps_the_edge() {
    // Both values are half opaque; along −x a ray crosses 8 voxels of
    // either. The largest gradient, 0.5, is at y = 7 and y = 8 (central
    // differences across the step); elsewhere it is zero. On 32 × 16
    // pixels of 0.5, column c looks along y = (c + 0.5)/2: columns 12 to
    // 17 see the voxels y = 7, 8, the others only zero gradients.
    let volume = step_along_y();
    let renderer = Renderer::new(&volume).unwrap();
    let plain = RenderSettings {
        width: 32,
        height: 16,
        transfer_function: tf(r#"{"opacity": [[0, 0.5]]}"#),
        ..RenderSettings::default()
    };
    let (_, without) = agreeing_paths(&renderer, &plain, "no gradient opacity");
    assert!(without.pixels().iter().all(|p| p[3] > 0.99));
    let settings = RenderSettings {
        gradient_opacity: Some((0.1, 0.5)),
        ..plain.clone()
    };
    let (_, image) = agreeing_paths(&renderer, &settings, "gradient opacity");
    for row in 0..16 {
        for col in (0..12).chain(18..32) {
            assert_eq!(image.get(col, row), [0.0; 4], "{col},{row}");
        }
        // Midway between y = 7 and y = 8 the edge is as opaque as before.
        for col in [14, 15] {
            let (a, b) = (image.get(col, row)[3], without.get(col, row)[3]);
            assert!((a - b).abs() < 1e-3, "{col},{row}: {a} vs {b}");
        }
    }
    assert!((renderer.max_gradient() - 0.5).abs() < 1e-7);
}

#[test]
fn classification_settings_are_validated() {
    let volume = distance_field(9);
    let renderer = Renderer::new(&volume).unwrap();
    let bad = [
        RenderSettings {
            iso: Some(IsoSurface {
                value: 0.5,
                thickness: 0.0,
            }),
            ..RenderSettings::default()
        },
        RenderSettings {
            iso: Some(IsoSurface {
                value: f32::NAN,
                thickness: 1.0,
            }),
            ..RenderSettings::default()
        },
        RenderSettings {
            gradient_opacity: Some((0.6, 0.2)),
            ..RenderSettings::default()
        },
        RenderSettings {
            gradient_opacity: Some((0.0, 1.5)),
            ..RenderSettings::default()
        },
    ];
    let want = [
        SettingError::IsoThickness(0.0),
        SettingError::IsoValue(f32::NAN),
        SettingError::GradientOpacity { lo: 0.6, hi: 0.2 },
        SettingError::GradientOpacity { lo: 0.0, hi: 1.5 },
    ];
    for (settings, want) in bad.iter().zip(want) {
        match renderer
            .render(FrameRequest::new(settings))
            .map(Rendered::image)
        {
            // NaN != NaN: compare the messages.
            Err(RenderError::Setting(got)) => assert_eq!(got.to_string(), want.to_string()),
            other => panic!("{settings:?}: {other:?}"),
        }
    }
}
