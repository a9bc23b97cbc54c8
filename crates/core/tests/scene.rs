//! Several volumes in one picture (`volray_core::scene`): the fast path
//! against the reference for two and three volumes, both mixes, every
//! blend mode, overlays on other grids and spacings; occlusion between
//! volumes from both sides; a scene of one volume bit-identical to its
//! renderer; label overlays in their table colours; the same image on any
//! number of threads; what is refused.

mod common;

use common::{colorful, on_the_reference, sparse_tf, tf};
use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::scene::{Look, Mix, Scene, SceneSettings};
use volray_core::transfer::labels::{LabelStyle, PALETTE, transfer_function};
use volray_core::{
    Blend, Classification, Image, Method, PartialImage, Piece, PiecewiseLinear, RenderError,
    RenderSettings, Renderer, SceneError, TransferFunction, Volume,
};
use volray_core::{FrameRequest, Render};

/// A ball of density `1 − r/radius` about `centre` (world units) on
/// `dims` points of `spacing` from `origin`.
fn ball(dims: [usize; 3], spacing: f64, origin: DVec3, centre: DVec3, radius: f64) -> Volume {
    Volume::from_fn(dims, DVec3::splat(spacing), origin, move |p| {
        (1.0 - (p - centre).length() / radius).max(0.0) as f32
    })
    .unwrap()
}

/// Smooth values with structure everywhere on one grid, from a phase.
fn waves(dims: [usize; 3], spacing: DVec3, origin: DVec3, phase: f64) -> Volume {
    Volume::from_fn(dims, spacing, origin, move |p| {
        let q = p * 0.37 + phase;
        (0.5 + 0.25 * (q.x.sin() * q.y.cos() + (q.z * 1.3 + phase).sin())) as f32
    })
    .unwrap()
}

/// A look of `transfer_function` in `settings`.
fn look(settings: &RenderSettings, transfer_function: TransferFunction) -> Look {
    Look {
        transfer_function,
        ..Look::of(settings)
    }
}

/// A constant colour with the paper's ramp over the volume's range.
fn coloured(settings: &RenderSettings, rgb: [f32; 3]) -> Look {
    look(
        settings,
        TransferFunction {
            color: Some(PiecewiseLinear::constant(rgb)),
            ..TransferFunction::default()
        },
    )
}

fn render(scene: &Scene, request: &SceneSettings) -> Image {
    scene.render(FrameRequest::new(request)).unwrap().image()
}

/// The fast image of `request` against the reference's: within 1/255 per
/// channel, and the reference shows something.
fn assert_fast_matches(scene: &Scene, request: &SceneSettings, what: &str) -> f32 {
    assert_eq!(request.settings.method, Method::Fast);
    let fast = render(scene, request);
    let reference = render(
        scene,
        &SceneSettings {
            settings: on_the_reference(&request.settings),
            ..request.clone()
        },
    );
    let diff = fast.max_abs_diff(&reference).unwrap();
    assert!(diff <= 1.0 / 255.0, "{what}: fast vs reference {diff}");
    let shown = reference.pixels().iter().filter(|p| p[3] > 0.2).count();
    assert!(shown > 100, "{what}: nearly empty ({shown} pixels shown)");
    diff
}

fn small(width: usize) -> RenderSettings {
    RenderSettings {
        width,
        height: width,
        camera: Camera {
            view_point: Some(DVec3::new(3.0, -2.0, 1.5)),
            ..Camera::default()
        },
        ..RenderSettings::default()
    }
}

#[test]
fn two_and_three_volumes_match_the_reference_in_both_mixes_and_classifications() {
    // Three channels of one grid, each with structure everywhere.
    let (dims, spacing, origin) = ([30, 26, 22], DVec3::new(1.0, 1.2, 0.9), DVec3::ZERO);
    let volumes: Vec<Volume> = (0..3)
        .map(|c| waves(dims, spacing, origin, c as f64 * 1.7))
        .collect();
    let renderers = || volumes.iter().map(|v| Renderer::new(v).unwrap()).collect();
    let scene = Scene::new(renderers()).unwrap();
    let scene2 = Scene::new(renderers().into_iter().take(2).collect()).unwrap();
    let settings = RenderSettings {
        opacity_ramp: (0.0, 0.15),
        ..small(48)
    };
    let looks = vec![
        coloured(&settings, [1.0, 0.0, 1.0]),
        look(&settings, colorful()),
        coloured(&settings, [0.0, 1.0, 1.0]),
    ];
    for classification in [Classification::Pre, Classification::Post] {
        for mix in [Mix::Composite, Mix::Additive] {
            let settings = RenderSettings {
                classification,
                ..settings.clone()
            };
            let three = SceneSettings {
                settings: settings.clone(),
                looks: looks.clone(),
                mix,
            };
            assert_fast_matches(
                &scene,
                &three,
                &format!("3 volumes {mix:?} {classification:?}"),
            );
            let two = SceneSettings {
                looks: looks[..2].to_vec(),
                ..three
            };
            assert_fast_matches(
                &scene2,
                &two,
                &format!("2 volumes {mix:?} {classification:?}"),
            );
        }
    }
}

#[test]
fn an_overlay_on_another_grid_and_spacing_matches_the_reference_in_both_projections() {
    // A coarse, large volume and a fine one over part of it, offset by
    // a fraction of a voxel.
    let base = waves([24, 20, 18], DVec3::splat(1.0), DVec3::ZERO, 0.3);
    let fine = ball(
        [33, 29, 25],
        0.5,
        DVec3::new(4.3, 3.1, 2.2),
        DVec3::new(12.0, 10.0, 8.0),
        7.0,
    );
    let scene = Scene::new(vec![
        Renderer::new(&base).unwrap(),
        Renderer::new(&fine).unwrap(),
    ])
    .unwrap();
    for projection in [
        Projection::Orthographic,
        Projection::Perspective { fov_degrees: 40.0 },
    ] {
        let mut settings = RenderSettings {
            opacity_ramp: (0.0, 0.1),
            ..small(56)
        };
        settings.camera.projection = projection;
        settings.camera.view_point = Some(DVec3::new(40.0, -30.0, 25.0));
        for classification in [Classification::Pre, Classification::Post] {
            let settings = RenderSettings {
                classification,
                ..settings.clone()
            };
            let request = SceneSettings {
                looks: vec![
                    look(&settings, sparse_tf()),
                    look(
                        &settings,
                        tf(
                            r#"{"opacity": [[0, 0], [0.2, 0], [1, 0.8]], "color": [[0, 1, 0.8, 0]]}"#,
                        ),
                    ),
                ],
                settings,
                mix: Mix::Composite,
            };
            assert_fast_matches(
                &scene,
                &request,
                &format!("overlay {projection:?} {classification:?}"),
            );
        }
    }
}

#[test]
fn every_blend_mode_and_a_crop_match_the_reference() {
    let a = waves([20, 22, 18], DVec3::ONE, DVec3::ZERO, 0.0);
    let b = ball(
        [20, 22, 18],
        1.0,
        DVec3::ZERO,
        DVec3::new(9.0, 11.0, 9.0),
        8.0,
    );
    let scene = Scene::new(vec![Renderer::new(&a).unwrap(), Renderer::new(&b).unwrap()]).unwrap();
    for blend in [
        Blend::Composite,
        Blend::Maximum,
        Blend::Minimum,
        Blend::Average,
    ] {
        let settings = RenderSettings {
            blend,
            crop: Some((DVec3::new(2.0, 3.0, 1.0), DVec3::new(17.0, 19.5, 14.0))),
            jitter: true,
            ..small(40)
        };
        let request = SceneSettings {
            looks: vec![
                look(&settings, colorful()),
                coloured(&settings, [0.0, 1.0, 0.0]),
            ],
            settings,
            mix: Mix::Composite,
        };
        assert_fast_matches(&scene, &request, &format!("{blend:?}"));
    }
}

/// Two opaque balls in two volumes of one grid, one behind the other
/// along x: seen from +x and from −x.
fn two_balls() -> (Volume, Volume) {
    let dims = [40, 24, 24];
    let a = ball(dims, 1.0, DVec3::ZERO, DVec3::new(28.0, 11.5, 11.5), 7.0);
    let b = ball(dims, 1.0, DVec3::ZERO, DVec3::new(11.0, 11.5, 11.5), 10.0);
    (a, b)
}

#[test]
fn the_ball_in_front_hides_the_other_volumes_ball_from_either_side() {
    // Volume A's ball is nearer +x, volume B's (larger) nearer −x. Drawn
    // one after the other, one volume would cover the other from both
    // sides; in one march each is hidden from the side the other faces.
    let (a, b) = two_balls();
    let scene = Scene::new(vec![Renderer::new(&a).unwrap(), Renderer::new(&b).unwrap()]).unwrap();
    let opaque = |rgb: [f32; 3]| TransferFunction {
        domain: Some((0.0, 1.0)),
        opacity: Some(PiecewiseLinear::new("opacity", vec![(0.0, [0.0]), (0.05, [1.0])]).unwrap()),
        color: Some(PiecewiseLinear::constant(rgb)),
    };
    for method in [Method::Fast, Method::Reference] {
        for (view_point, front) in [(DVec3::X, [1.0, 0.0, 1.0]), (-DVec3::X, [0.0, 1.0, 0.0])] {
            let settings = RenderSettings {
                width: 48,
                height: 48,
                camera: Camera {
                    view_point: Some(DVec3::new(20.0, 11.5, 11.5) + 100.0 * view_point),
                    ..Camera::default()
                },
                shading: false,
                method,
                ..RenderSettings::default()
            };
            let request = SceneSettings {
                looks: vec![
                    look(&settings, opaque([1.0, 0.0, 1.0])),
                    look(&settings, opaque([0.0, 1.0, 0.0])),
                ],
                settings,
                mix: Mix::Composite,
            };
            let image = render(&scene, &request);
            // The centre: both balls on the ray; the nearer one's colour.
            let centre = image.get(24, 24);
            for c in 0..3 {
                assert!(
                    (centre[c] - front[c]).abs() < 0.01,
                    "{method:?} from {view_point}: centre {centre:?}, want {front:?}"
                );
            }
            // B's ball is the larger: seen from +x, its rim shows around
            // A's; seen from −x it hides A's ball whole.
            let green = |p: &[f32; 4]| p[1] > 0.9 && p[0] < 0.01;
            let magenta = |p: &[f32; 4]| p[0] > 0.01;
            let pixels = image.pixels();
            if front == [1.0, 0.0, 1.0] {
                assert!(
                    pixels.iter().filter(|p| green(p)).count() > 50,
                    "{method:?}"
                );
            } else {
                assert_eq!(
                    pixels.iter().filter(|p| magenta(p)).count(),
                    0,
                    "{method:?}"
                );
            }
        }
    }
}

#[test]
fn a_scene_of_one_volume_renders_exactly_as_its_renderer() {
    let v = waves(
        [21, 17, 19],
        DVec3::new(1.0, 0.8, 1.1),
        DVec3::new(-3.0, 2.0, 0.5),
        0.4,
    );
    let renderer = Renderer::new(&v).unwrap();
    for blend in [Blend::Composite, Blend::Maximum] {
        for classification in [Classification::Pre, Classification::Post] {
            let settings = RenderSettings {
                transfer_function: colorful(),
                blend,
                classification,
                ..small(40)
            };
            let alone = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let scene = Scene::new(vec![Renderer::new(&v).unwrap()]).unwrap();
            let request = SceneSettings {
                looks: vec![Look::of(&settings)],
                settings,
                mix: Mix::Composite,
            };
            assert_eq!(
                render(&scene, &request),
                alone,
                "{blend:?} {classification:?}"
            );
        }
    }
}

#[test]
fn a_transparent_or_hidden_second_channel_leaves_the_first_as_it_renders_alone() {
    // Channels of one grid: the scene's samples are the first volume's,
    // so with nothing from the second the picture is the first's alone
    // (within the fast path's rounding of the mix, and exactly when the
    // second is hidden: then the first renders by itself).
    let a = waves([24, 20, 22], DVec3::ONE, DVec3::ZERO, 0.2);
    let b = waves([24, 20, 22], DVec3::ONE, DVec3::ZERO, 1.1);
    let settings = RenderSettings {
        transfer_function: colorful(),
        ..small(40)
    };
    let alone = Renderer::new(&a)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    let scene = Scene::new(vec![Renderer::new(&a).unwrap(), Renderer::new(&b).unwrap()]).unwrap();
    let nothing = TransferFunction {
        opacity: Some(PiecewiseLinear::constant([0.0])),
        ..TransferFunction::default()
    };
    let mut request = SceneSettings {
        looks: vec![Look::of(&settings), look(&settings, nothing)],
        settings,
        mix: Mix::Composite,
    };
    let diff = render(&scene, &request).max_abs_diff(&alone).unwrap();
    assert!(diff <= 1.0 / 255.0, "{diff}");
    request.looks[1] = Look {
        visible: false,
        ..Look::of(&request.settings)
    };
    assert_eq!(render(&scene, &request), alone);
}

#[test]
fn the_additive_mix_sums_the_channels_colours() {
    // Two channels composited apart: red and green over black add up.
    let (a, b) = two_balls();
    let settings = RenderSettings {
        width: 40,
        height: 40,
        shading: false,
        ..RenderSettings::default()
    };
    let red = coloured(&settings, [1.0, 0.0, 0.0]);
    let green = coloured(&settings, [0.0, 1.0, 0.0]);
    let alone = |v: &Volume, l: &Look| {
        let s = RenderSettings {
            transfer_function: l.transfer_function.clone(),
            camera: Camera {
                bounds: Some(a.bounds()),
                ..settings.camera
            },
            ..settings.clone()
        };
        Renderer::new(v)
            .unwrap()
            .render(FrameRequest::new(&s))
            .unwrap()
            .image()
    };
    let (ra, gb) = (alone(&a, &red), alone(&b, &green));
    let scene = Scene::new(vec![Renderer::new(&a).unwrap(), Renderer::new(&b).unwrap()]).unwrap();
    let image = render(
        &scene,
        &SceneSettings {
            looks: vec![red, green],
            settings,
            mix: Mix::Additive,
        },
    );
    let mut both = 0;
    for (i, p) in image.pixels().iter().enumerate() {
        let (r, g) = (ra.pixels()[i], gb.pixels()[i]);
        assert!(
            (p[0] - r[0]).abs() < 1e-6 && (p[1] - g[1]).abs() < 1e-6,
            "{p:?}"
        );
        assert!((p[3] - (1.0 - (1.0 - r[3]) * (1.0 - g[3]))).abs() < 1e-6);
        both += (r[0] > 0.2 && g[1] > 0.2) as usize;
    }
    assert!(both > 50, "{both} pixels of both channels");
}

#[test]
fn channels_marched_together_in_the_additive_mix_sum_as_each_alone() {
    // Five channels of one grid (one march of four, then one of one, their
    // colours summed), shaded, in perspective, jittered, cropped: each
    // channel's colour is what it renders alone, over black.
    let dims = [34, 30, 26];
    let volumes: Vec<Volume> = (0..5)
        .map(|c| waves(dims, DVec3::ONE, DVec3::ZERO, c as f64 * 1.3))
        .collect();
    let settings = RenderSettings {
        opacity_ramp: (0.0, 0.1),
        jitter: true,
        background: [0.0; 3],
        camera: Camera {
            projection: Projection::Perspective { fov_degrees: 35.0 },
            ..small(40).camera
        },
        crop: Some((DVec3::new(2.0, 0.0, 1.0), DVec3::new(30.0, 29.0, 22.0))),
        ..small(40)
    };
    let colours = [
        [1.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 1.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let looks: Vec<Look> = colours.iter().map(|&c| coloured(&settings, c)).collect();
    for k in [2, 3, 5] {
        let scene = Scene::new(
            (volumes[..k].iter())
                .map(|v| Renderer::new(v).unwrap())
                .collect(),
        )
        .unwrap();
        let request = SceneSettings {
            settings: settings.clone(),
            looks: looks[..k].to_vec(),
            mix: Mix::Additive,
        };
        let image = render(&scene, &request);
        let alone: Vec<Image> = (0..k)
            .map(|c| {
                let one = Scene::new(vec![Renderer::new(&volumes[c]).unwrap()]).unwrap();
                let request = SceneSettings {
                    looks: vec![looks[c].clone()],
                    ..request.clone()
                };
                render(&one, &request)
            })
            .collect();
        for (i, p) in image.pixels().iter().enumerate() {
            let (mut sum, mut keep) = ([0.0f32; 3], 1.0f32);
            for a in &alone {
                let q = a.pixels()[i];
                (0..3).for_each(|c| sum[c] += q[c]);
                keep *= 1.0 - q[3];
            }
            for c in 0..3 {
                assert!((p[c] - sum[c].min(1.0)).abs() < 1e-5, "{k}: {p:?} {sum:?}");
            }
            assert!((p[3] - (1.0 - keep)).abs() < 1e-5, "{k}: {p:?} {keep}");
        }
        assert_fast_matches(&scene, &request, &format!("{k} channels additive"));
    }
}

#[test]
fn a_label_overlay_shows_each_label_in_its_table_colour_over_a_translucent_scan() {
    // A faint scan, and labels 3 and 7 (two opaque blocks) with 0 elsewhere.
    let dims = [32, 32, 32];
    let scan = waves(dims, DVec3::ONE, DVec3::ZERO, 0.0);
    let labels = Volume::from_fn(dims, DVec3::ONE, DVec3::ZERO, |p| {
        let inside = |lo: f64, hi: f64| p.y >= lo && p.y <= hi && p.z >= 10.0 && p.z <= 21.0;
        if p.x > 8.0 && p.x < 24.0 && inside(4.0, 13.0) {
            3.0
        } else if p.x > 8.0 && p.x < 24.0 && inside(18.0, 27.0) {
            7.0
        } else {
            0.0
        }
    })
    .unwrap()
    .as_labels();
    let settings = RenderSettings {
        width: 64,
        height: 64,
        shading: false,
        opacity_ramp: (0.0, 0.004),
        ..RenderSettings::default()
    };
    let table = transfer_function(&[0, 3, 7], &LabelStyle::default()).unwrap();
    let scene = Scene::new(vec![
        Renderer::new(&scan).unwrap(),
        Renderer::new(&labels).unwrap(),
    ])
    .unwrap();
    for method in [Method::Fast, Method::Reference] {
        let settings = RenderSettings {
            method,
            ..settings.clone()
        };
        let request = SceneSettings {
            looks: vec![
                coloured(&settings, [1.0, 1.0, 1.0]),
                look(&settings, table.clone()),
            ],
            settings,
            mix: Mix::Composite,
        };
        let image = render(&scene, &request);
        // Seen along −x: +y to the right, so label 3 (low y) on the left.
        // The scan in front tints them by its few percent of white.
        for (col, label) in [(20, 3), (43, 7)] {
            let p = image.get(col, 32);
            let want = PALETTE[label];
            for c in 0..3 {
                assert!(
                    (p[c] - want[c]).abs() < 0.03,
                    "{method:?}: label {label} at column {col}: {p:?}, want {want:?}"
                );
            }
        }
        // Between the blocks and above them, label 0: the grey scan only.
        for (col, row) in [(32, 32), (20, 8)] {
            let p = image.get(col, row);
            assert!(
                (p[0] - p[1]).abs() < 1e-3 && (p[1] - p[2]).abs() < 1e-3 && p[3] < 0.9,
                "{method:?}: ({col}, {row}) {p:?}"
            );
        }
    }
}

#[test]
fn the_image_is_the_same_on_one_and_on_several_threads() {
    let (a, b) = two_balls();
    let c = waves([40, 24, 24], DVec3::ONE, DVec3::ZERO, 0.9);
    let scene = Scene::new(
        [&a, &b, &c]
            .iter()
            .map(|v| Renderer::new(v).unwrap())
            .collect(),
    )
    .unwrap();
    let cases = [Classification::Pre, Classification::Post]
        .into_iter()
        .flat_map(|c| [(c, Mix::Composite), (c, Mix::Additive)]);
    for (classification, mix) in cases {
        let settings = RenderSettings {
            classification,
            jitter: true,
            ..small(44)
        };
        let request = SceneSettings {
            looks: vec![
                coloured(&settings, [1.0, 0.0, 1.0]),
                coloured(&settings, [0.0, 1.0, 0.0]),
                look(&settings, colorful()),
            ],
            settings,
            mix,
        };
        let on = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render(&scene, &request))
        };
        let one = on(1);
        assert_eq!(one, on(2), "{classification:?} {mix:?}");
        assert_eq!(one, on(5), "{classification:?} {mix:?}");
    }
}

#[test]
fn refused_scenes_name_the_volume_and_the_problem() {
    let a = ball([10, 10, 10], 1.0, DVec3::ZERO, DVec3::splat(4.5), 3.0);
    let far = ball(
        [10, 10, 10],
        1.0,
        DVec3::splat(50.0),
        DVec3::splat(54.5),
        3.0,
    );
    let err = Scene::new(vec![
        Renderer::new(&a).unwrap(),
        Renderer::new(&far).unwrap(),
    ])
    .err()
    .unwrap();
    assert!(
        matches!(err, SceneError::Disjoint { layer: 1, .. }),
        "{err}"
    );
    assert!(
        err.to_string().contains("does not meet the first volume"),
        "{err}"
    );
    assert_eq!(Scene::new(vec![]).err(), Some(SceneError::Empty));

    let scene = Scene::new(vec![Renderer::new(&a).unwrap(), Renderer::new(&a).unwrap()]).unwrap();
    let settings = small(16);
    let request = SceneSettings {
        looks: vec![Look::of(&settings)],
        settings: settings.clone(),
        mix: Mix::Composite,
    };
    assert_eq!(
        scene.render(FrameRequest::new(&request)).err(),
        Some(RenderError::Scene(SceneError::Looks {
            layers: 2,
            looks: 1
        }))
    );
    let request = SceneSettings {
        looks: vec![
            Look::of(&settings),
            Look {
                opacity: 1.5,
                ..Look::of(&settings)
            },
        ],
        settings: settings.clone(),
        mix: Mix::Composite,
    };
    let err = scene.render(FrameRequest::new(&request)).unwrap_err();
    assert_eq!(err.to_string(), "volume 1: opacity 1.5 must be in [0, 1]");
    let request = SceneSettings {
        looks: vec![
            Look::of(&settings),
            Look {
                opacity_ramp: (0.5, 0.2),
                ..Look::of(&settings)
            },
        ],
        settings,
        mix: Mix::Composite,
    };
    let err = scene.render(FrameRequest::new(&request)).unwrap_err();
    assert!(
        err.to_string().starts_with("volume 1: opacity ramp"),
        "{err}"
    );
}

/// The piece of `volume` owning voxels `owned`, held with its ghosts.
fn piece_of(volume: &Volume, owned: ([usize; 3], [usize; 3])) -> (Volume, Piece) {
    let (lo, hi) = Piece::held(owned, volume.dims());
    let renderer = Renderer::new(volume).unwrap();
    let piece = Piece {
        whole: GridFrame::of(volume),
        offset: lo,
        owned,
        value_range: renderer.value_range(),
        max_gradient: renderer.max_gradient(),
    };
    (volume.sub_box(lo, hi), piece)
}

#[test]
fn pieces_of_a_scene_composited_front_to_back_give_the_whole_scenes_frame() {
    // Two channels of one grid, cut into three slabs along x as the ranks
    // of a distributed frame hold them; each slab a scene of its two
    // pieces.
    let (dims, spacing, origin) = (
        [33, 27, 25],
        DVec3::new(1.0, 1.1, 0.9),
        DVec3::new(-2.0, 1.0, 0.5),
    );
    let channels = [
        waves(dims, spacing, origin, 0.0),
        waves(dims, spacing, origin, 1.9),
    ];
    let whole = Scene::new(channels.iter().map(|v| Renderer::new(v).unwrap()).collect()).unwrap();
    let cuts = [(0, 12), (12, 21), (21, dims[0])];
    let slabs: Vec<Vec<(Volume, Piece)>> = (cuts.iter())
        .map(|&(a, b)| {
            (channels.iter())
                .map(|v| piece_of(v, ([a, 0, 0], [b, dims[1], dims[2]])))
                .collect()
        })
        .collect();
    let scenes: Vec<Scene> = (slabs.iter())
        .map(|pieces| {
            Scene::new(
                pieces
                    .iter()
                    .map(|(v, _)| Renderer::new(v).unwrap())
                    .collect(),
            )
            .unwrap()
        })
        .collect();
    let cameras = [
        Camera::default(),
        Camera {
            azimuth: 30.0,
            elevation: -25.0,
            ..Camera::default()
        },
        Camera {
            projection: Projection::Perspective { fov_degrees: 35.0 },
            azimuth: -25.0,
            elevation: 10.0,
            ..Camera::default()
        },
    ];
    for camera in cameras {
        for classification in [Classification::Pre, Classification::Post] {
            for method in [Method::Fast, Method::Reference] {
                let settings = RenderSettings {
                    width: 48,
                    height: 40,
                    camera,
                    classification,
                    method,
                    opacity_ramp: (0.0, 0.2),
                    background: [0.1, 0.2, 0.3],
                    ..RenderSettings::default()
                };
                let looks = vec![
                    coloured(&settings, [1.0, 0.0, 1.0]),
                    look(&settings, colorful()),
                ];
                let request = SceneSettings {
                    settings: settings.clone(),
                    looks: looks.clone(),
                    mix: Mix::Composite,
                };
                let frame = render(&whole, &request);
                // Each slab's partial image; the eye is on the +x side.
                let mut parts: Vec<PartialImage> = (scenes.iter().zip(&slabs))
                    .map(|(scene, pieces)| {
                        let looks = (looks.iter().zip(pieces))
                            .map(|(l, (_, piece))| Look {
                                piece: Some(piece.clone()),
                                ..l.clone()
                            })
                            .collect();
                        let request = SceneSettings {
                            looks,
                            ..request.clone()
                        };
                        scene
                            .render(FrameRequest::new(&request).partial())
                            .unwrap()
                            .partial()
                    })
                    .collect();
                let mut front = parts.pop().unwrap();
                while let Some(behind) = parts.pop() {
                    front.combine(&behind);
                }
                let combined = front.finish(settings.background, |_| unreachable!());
                let diff = combined.max_abs_diff(&frame).unwrap();
                let bound = if method == Method::Reference {
                    1e-5
                } else {
                    2.0 / 1024.0
                };
                let what = format!("{camera:?} {classification:?} {method:?}");
                assert!(diff <= bound, "{what}: {diff}");
                assert!(
                    frame.pixels().iter().filter(|p| p[3] > 0.5).count() > 100,
                    "{what}"
                );
            }
        }
    }
    // What does not combine front to back is refused.
    let settings = RenderSettings::default();
    let (_, piece) = &slabs[0][0];
    let with_piece = Look {
        piece: Some(piece.clone()),
        ..Look::of(&settings)
    };
    let request = SceneSettings {
        looks: vec![with_piece.clone(), with_piece.clone()],
        settings,
        mix: Mix::Additive,
    };
    let err = scenes[0].render(FrameRequest::new(&request)).unwrap_err();
    assert!(
        err.to_string().contains("only in the composite mix"),
        "{err}"
    );
    let request = SceneSettings {
        looks: vec![with_piece, Look::of(&request.settings)],
        mix: Mix::Composite,
        ..request
    };
    let err = scenes[0].render(FrameRequest::new(&request)).unwrap_err();
    assert!(
        err.to_string().contains("every volume is a piece, or none"),
        "{err}"
    );
}
