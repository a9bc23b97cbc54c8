//! The rendering options of stage 2, each checked for its real effect:
//! blend modes (maximum, minimum, average), post-classification, jitter,
//! the crop box and clip planes, perspective, and which path renders what.

mod common;

use common::{
    Cut, assert_uniform_medium, assert_within_a_level, blobs, both_paths, colorful, constant_tf,
    grey_unit_window, on_the_reference, render_on_threads, uniform_medium,
};
use volray_core::PiecewiseLinear;
use volray_core::camera::{Camera, Projection, View};
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{
    Blend, Classification, ClipPlane, Image, Method, RenderSettings, Renderer, TransferFunction,
    Volume,
};
use volray_core::{FrameRequest, Render};

/// A ball of radius `r` about `centre` with a soft edge one voxel wide.
fn ball(n: usize, r: f64, centre: DVec3) -> Volume {
    let h = 2.0 / (n - 1) as f64;
    Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
        (0.5 + (r - (p - centre).length()) / h).clamp(0.0, 1.0) as f32
    })
    .unwrap()
}

/// `f = (1 + x/10)/2 · h(y, z)` with `h = 0.2 + 0.1y + 0.04z` on the grid
/// [0, 10] × [0, 6] × [0, 4]: trilinear, so interpolation is exact, and
/// along x it rises linearly from h/2 to h.
fn ramp_volume() -> Volume {
    Volume::from_fn([11, 7, 5], DVec3::ONE, DVec3::ZERO, |p| ramp(p) as f32).unwrap()
}

fn ramp(p: DVec3) -> f64 {
    (1.0 + p.x / 10.0) / 2.0 * (0.2 + 0.1 * p.y + 0.04 * p.z)
}

fn max_diff(a: &Image, b: &Image) -> f32 {
    a.max_abs_diff(b).unwrap()
}

fn mean_diff(a: &Image, b: &Image) -> f64 {
    let sum: f64 = (a.pixels().iter().zip(b.pixels()))
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).abs() as f64).sum::<f64>())
        .sum();
    sum / (3 * a.pixels().len()) as f64
}

#[test]
fn projections_of_a_ramp_seen_along_it_are_its_maximum_minimum_and_mean() {
    // Seen along −x (the default view), the y-z face 6 × 4 fills 12 × 8
    // pixels of 0.5: pixel (c, r) looks along the line y = (c + 0.5)/2,
    // z = 4 − (r + 0.5)/2, where f runs from h/2 (x = 0) to h (x = 10).
    // The samples at x = 0, step, …, 10 are symmetric about x = 5, so their
    // mean is the ramp's mean, 3h/4. With the grey map of [0, 1] the grey
    // level is the value itself. Both paths.
    let volume = ramp_volume();
    let renderer = Renderer::new(&volume).unwrap();
    for (step, method) in [
        (1.0, Method::Fast),
        (0.5, Method::Fast),
        (1.0, Method::Reference),
        (0.5, Method::Reference),
    ] {
        for (blend, factor) in [
            (Blend::Maximum, 1.0),
            (Blend::Minimum, 0.5),
            (Blend::Average, 0.75),
        ] {
            let settings = RenderSettings {
                width: 12,
                height: 8,
                step,
                blend,
                transfer_function: grey_unit_window(),
                background: [0.2, 0.4, 0.6],
                method,
                ..RenderSettings::default()
            };
            let image = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            for row in 0..8 {
                for col in 0..12 {
                    let (y, z) = ((col as f64 + 0.5) / 2.0, 4.0 - (row as f64 + 0.5) / 2.0);
                    let want = factor * (0.2 + 0.1 * y + 0.04 * z);
                    let px = image.get(col, row);
                    for c in 0..3 {
                        assert!(
                            (px[c] as f64 - want).abs() < 1e-6,
                            "{blend:?} {method:?} step {step} ({col}, {row}): {px:?} vs {want}"
                        );
                    }
                    assert_eq!(px[3], 1.0, "projections are opaque");
                }
            }
        }
    }
}

/// The grey level of `f(p)` projected by `blend` over the samples a
/// pixel's ray takes by the documented rule: `t = k·step` inside the grid's
/// box (within a millionth of a step), `t ≥ 0` from a perspective eye.
fn brute_force_projection(
    view: &View,
    grid: &GridFrame,
    step: f64,
    blend: Blend,
    col: usize,
    row: usize,
) -> Option<f64> {
    let (o, d) = view.pixel_ray(col, row);
    let (mut t0, t1) = grid.span(o, d)?;
    if matches!(view, View::Perspective(_)) {
        t0 = t0.max(0.0);
    }
    let first = ((t0 - 1e-6 * step) / step).ceil() as i64;
    let last = ((t1 + 1e-6 * step) / step).floor() as i64;
    let (lo, hi) = (
        grid.origin,
        grid.origin + 10.0 * DVec3::X + 6.0 * DVec3::Y + 4.0 * DVec3::Z,
    );
    let values: Vec<f64> = (first..=last)
        .map(|k| ramp((o + k as f64 * step * d).clamp(lo, hi)))
        .collect();
    if values.is_empty() {
        return None;
    }
    Some(match blend {
        Blend::Maximum => values.iter().cloned().fold(f64::MIN, f64::max),
        Blend::Minimum => values.iter().cloned().fold(f64::MAX, f64::min),
        _ => values.iter().sum::<f64>() / values.len() as f64,
    })
}

#[test]
fn projections_equal_a_brute_force_pass_over_the_samples_of_oblique_and_perspective_rays() {
    let volume = ramp_volume();
    let renderer = Renderer::new(&volume).unwrap();
    let grid = GridFrame {
        dims: volume.dims(),
        origin: volume.origin(),
        spacing: volume.spacing(),
    };
    let cameras = [
        Camera {
            view_point: Some(DVec3::new(30.0, -20.0, 14.0)),
            ..Camera::default()
        },
        Camera {
            view_point: Some(DVec3::new(18.0, 9.0, 8.0)),
            projection: Projection::Perspective { fov_degrees: 50.0 },
            ..Camera::default()
        },
    ];
    for camera in cameras {
        for (blend, method) in [Blend::Maximum, Blend::Minimum, Blend::Average]
            .into_iter()
            .flat_map(|b| [(b, Method::Fast), (b, Method::Reference)])
        {
            let settings = RenderSettings {
                width: 24,
                height: 20,
                step: 0.7,
                camera,
                blend,
                transfer_function: grey_unit_window(),
                method,
                ..RenderSettings::default()
            };
            let image = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let view = View::frame(&camera, volume.bounds(), 24, 20).unwrap();
            let mut hits = 0;
            for row in 0..20 {
                for col in 0..24 {
                    let px = image.get(col, row);
                    match brute_force_projection(&view, &grid, 0.7, blend, col, row) {
                        Some(want) => {
                            hits += 1;
                            assert!(
                                (px[0] as f64 - want).abs() < 1e-5 && px[3] == 1.0,
                                "{blend:?} {method:?} ({col}, {row}): {px:?} vs {want}"
                            );
                        }
                        None => assert_eq!(px, [0.0; 4], "({col}, {row}) misses"),
                    }
                }
            }
            assert!(hits > 100, "{hits} rays hit the volume");
        }
    }
}

#[test]
fn fast_projections_match_the_reference_with_every_option() {
    // Blobs (smooth, with empty space around them, so that maximum
    // projection skips bricks) under a colour map, orthographic and
    // perspective, cropped, clipped and jittered: the fast projections are
    // within 1/255 of the reference, and the same for any thread count.
    let volume = blobs([40, 34, 46], DVec3::splat(0.5), DVec3::new(-3.0, 2.0, 1.0));
    let renderer = Renderer::new(&volume).unwrap();
    let centre = volume.centre();
    let cameras = [
        Camera {
            view_point: Some(DVec3::new(150.0, 150.0, 500.0)),
            ..Camera::default()
        },
        Camera {
            projection: Projection::Perspective { fov_degrees: 35.0 },
            azimuth: 30.0,
            elevation: 20.0,
            ..Camera::default()
        },
    ];
    let mut worst = 0.0f32;
    for camera in cameras {
        for blend in [Blend::Maximum, Blend::Minimum, Blend::Average] {
            for (jitter, cut) in [(false, false), (true, true)] {
                let settings = RenderSettings {
                    width: 48,
                    height: 40,
                    camera,
                    step: 0.6,
                    blend,
                    jitter,
                    crop: cut.then_some((centre - DVec3::splat(20.0), centre + DVec3::splat(6.0))),
                    clip_planes: if cut {
                        vec![ClipPlane {
                            point: centre,
                            normal: DVec3::new(0.3, -1.0, 0.5),
                        }]
                    } else {
                        vec![]
                    },
                    transfer_function: colorful(),
                    background: [0.1, 0.1, 0.3],
                    ..RenderSettings::default()
                };
                let in_pool = |threads| render_on_threads(&renderer, &settings, threads);
                let (fast, fast_2) = (in_pool(1), in_pool(2));
                assert!(fast == fast_2);
                let slow = renderer
                    .render(FrameRequest::new(&on_the_reference(&settings)))
                    .unwrap()
                    .image();
                let diff =
                    assert_within_a_level(&fast, &slow, &format!("{camera:?} {blend:?} {jitter}"));
                worst = worst.max(diff);
                let (hit, missed) = (
                    fast.pixels().iter().filter(|p| p[3] == 1.0).count(),
                    fast.pixels().iter().filter(|p| p[3] == 0.0).count(),
                );
                assert!(hit > 100 && hit + missed == fast.pixels().len());
            }
        }
    }
    println!(
        "largest fast-vs-reference projection difference: {:.3} of 1/255",
        worst * 255.0
    );
}

#[test]
fn maximum_projection_finds_single_voxels_behind_brighter_bricks() {
    // The near half (x > 20, the default view looks along −x) is bright
    // (0.5 to 0.6), the far half dim (0 to 0.3) but for three 2×2×2 spots
    // of 0.9, 0.7 and 0.65: the fast path skips the far bricks whose
    // largest value cannot beat what the ray has seen, and must still find
    // the spots in the bricks that hold them.
    let hash = |i: usize, j: usize, k: usize| ((i * 73 + j * 151 + k * 283) % 97) as f32 / 97.0;
    let spikes = [((5, 12, 30), 0.9), ((11, 30, 8), 0.7), ((2, 2, 2), 0.65)];
    let n = 41;
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let noise = hash(i, j, k);
                data.push(if i > 20 {
                    0.5 + 0.1 * noise
                } else {
                    0.3 * noise
                });
            }
        }
    }
    for ((i, j, k), v) in spikes {
        for corner in 0..8 {
            let (di, dj, dk) = (corner & 1, corner >> 1 & 1, corner >> 2);
            data[(i + di) + n * ((j + dj) + n * (k + dk))] = v;
        }
    }
    let volume = Volume::new([n, n, n], data).unwrap();
    let renderer = Renderer::new(&volume).unwrap();
    for camera in [
        Camera::default(),
        Camera {
            view_point: Some(DVec3::new(100.0, 30.0, 45.0)),
            ..Camera::default()
        },
    ] {
        let settings = RenderSettings {
            width: 80,
            height: 80,
            step: 0.5,
            blend: Blend::Maximum,
            transfer_function: grey_unit_window(),
            camera,
            ..RenderSettings::default()
        };
        let fast = renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        let slow = renderer
            .render(FrameRequest::new(&on_the_reference(&settings)))
            .unwrap()
            .image();
        // f32 against f64 interpolation.
        assert!(max_diff(&fast, &slow) < 1e-5);
        // Each spot shows at (nearly) its full height where its centre
        // projects, above the bright near half.
        let view = View::frame(&camera, volume.bounds(), 80, 80).unwrap();
        for ((i, j, k), v) in spikes {
            let centre = volume.world_position(i, j, k) + DVec3::splat(0.5);
            let (c, r) = view.project(centre).unwrap();
            let around = (c as usize - 1..=c as usize + 1)
                .flat_map(|c| (r as usize - 1..=r as usize + 1).map(move |r| (c, r)));
            let brightest = around.map(|(c, r)| fast.get(c, r)[0]).fold(0.0, f32::max);
            assert!(brightest > v - 0.02, "{camera:?} spot {v}: {brightest}");
        }
    }
}

#[test]
fn skipping_resumes_at_the_first_sample_past_a_skipped_brick() {
    // Seen along −x, the bricks x ∈ [32, 40] (bright, 0.5 to 0.6 from
    // x = 33 on) and [24, 32] (dim, at most 0.3) come first; the ray skips
    // the dim one and must take the very first sample past its face x = 24,
    // since a wall of 0.9 stands one voxel behind it, at x = 23. Minimum
    // projection, mirrored (1 − f), likewise. Oblique and jittered rays
    // cross the face at every fraction of a step.
    let n = 41;
    let f = |p: DVec3| {
        let (i, j, k) = (p.x as usize, p.y as usize, p.z as usize);
        let noise = ((i * 73 + j * 151 + k * 283) % 101) as f64 / 101.0;
        if i == 23 {
            0.9
        } else if i >= 33 {
            0.5 + 0.1 * noise
        } else {
            0.3 * noise
        }
    };
    for (blend, flip) in [(Blend::Maximum, false), (Blend::Minimum, true)] {
        let volume = Volume::from_fn([n, n, n], DVec3::ONE, DVec3::ZERO, |p| {
            (if flip { 1.0 - f(p) } else { f(p) }) as f32
        })
        .unwrap();
        let renderer = Renderer::new(&volume).unwrap();
        for camera in [
            Camera::default(),
            Camera {
                view_point: Some(DVec3::new(200.0, 45.0, 70.0)),
                ..Camera::default()
            },
        ] {
            let settings = RenderSettings {
                width: 64,
                height: 64,
                step: 0.8,
                blend,
                jitter: true,
                camera,
                transfer_function: grey_unit_window(),
                ..RenderSettings::default()
            };
            let fast = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let slow = renderer
                .render(FrameRequest::new(&on_the_reference(&settings)))
                .unwrap()
                .image();
            assert!(max_diff(&fast, &slow) < 1e-5, "{blend:?} {camera:?}");
            // The wall shows through everywhere it is seen.
            let wall = if flip { 0.1 } else { 0.9 };
            let hits = fast.pixels().iter().filter(|p| (p[0] - wall).abs() < 0.3);
            assert!(hits.count() > 64 * 64 / 2);
        }
    }
}

#[test]
fn a_crop_removes_what_lies_outside_it_and_keeps_the_rest_unchanged() {
    // Seen from +z (up +y), screen right is +x: cropping the ball to x ≤ 0
    // empties the right half of the picture and leaves the left half as
    // it was, on both paths.
    let volume = ball(33, 0.6, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let settings = RenderSettings {
        width: 32,
        height: 32,
        camera: Camera {
            view_point: Some(DVec3::new(0.0, 0.0, 10.0)),
            up: DVec3::Y,
            ..Camera::default()
        },
        background: [0.1, 0.2, 0.3],
        ..RenderSettings::default()
    };
    let cropped = RenderSettings {
        crop: Some((DVec3::splat(-5.0), DVec3::new(0.0, 5.0, 5.0))),
        ..settings.clone()
    };
    let (whole, whole_ref) = both_paths(&renderer, &settings);
    let (half, half_ref) = both_paths(&renderer, &cropped);
    for (whole, half) in [(&whole, &half), (&whole_ref, &half_ref)] {
        let mut removed = 0;
        for row in 0..32 {
            for col in 0..32 {
                if col < 16 {
                    assert_eq!(half.get(col, row), whole.get(col, row), "({col}, {row})");
                } else {
                    assert_eq!(half.get(col, row), [0.1, 0.2, 0.3, 0.0], "({col}, {row})");
                    removed += (whole.get(col, row)[3] > 0.5) as usize;
                }
            }
        }
        assert!(removed > 50, "the right half held {removed} opaque pixels");
    }
}

#[test]
fn a_clip_plane_equals_the_equivalent_crop() {
    // Keeping x ≤ 0.2 by a plane or by a crop box reaching past the volume
    // is the same cut; seen obliquely, rays cross it.
    let volume = blobs([24, 20, 28], DVec3::splat(1.0 / 12.0), DVec3::splat(-1.0));
    let renderer = Renderer::new(&volume).unwrap();
    let base = RenderSettings {
        width: 40,
        height: 36,
        camera: Camera {
            view_point: Some(DVec3::new(5.0, 3.0, 8.0)),
            ..Camera::default()
        },
        transfer_function: colorful(),
        ..RenderSettings::default()
    };
    let clipped = RenderSettings {
        clip_planes: vec![ClipPlane {
            point: DVec3::new(0.2, 0.0, 0.0),
            normal: DVec3::new(-3.0, 0.0, 0.0),
        }],
        ..base.clone()
    };
    let cropped = RenderSettings {
        crop: Some((DVec3::splat(-10.0), DVec3::new(0.2, 10.0, 10.0))),
        ..base.clone()
    };
    for method in [Method::Fast, Method::Reference] {
        let with = |s: &RenderSettings| {
            renderer
                .render(FrameRequest::new(&RenderSettings {
                    method,
                    ..s.clone()
                }))
                .unwrap()
                .image()
        };
        let (plane, crop, whole) = (with(&clipped), with(&cropped), with(&base));
        assert!(max_diff(&plane, &crop) < 1e-6, "{method:?}");
        assert!(max_diff(&plane, &whole) > 0.1, "{method:?}: the cut shows");
    }
}

#[test]
fn fast_path_matches_the_reference_with_crops_clip_planes_and_jitter() {
    let volume = blobs(
        [24, 20, 28],
        DVec3::new(1.0, 1.5, 0.75),
        DVec3::new(-2.0, 5.0, 1.0),
    );
    let renderer = Renderer::new(&volume).unwrap();
    let centre = volume.centre();
    let cameras = [
        Camera::default(),
        Camera {
            view_point: Some(DVec3::new(150.0, 150.0, 500.0)),
            ..Camera::default()
        },
        Camera {
            view_point: Some(DVec3::new(-40.0, 12.0, -9.0)),
            ..Camera::default()
        },
    ];
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
                    point: centre + DVec3::new(0.0, 6.0, 0.0),
                    normal: DVec3::new(0.1, -1.0, 0.2),
                },
            ],
        ),
        (
            Some((centre - DVec3::splat(7.0), centre + DVec3::splat(7.0))),
            vec![ClipPlane {
                point: centre,
                normal: DVec3::new(-0.3, 0.2, -1.0),
            }],
        ),
    ];
    let mut worst = 0.0f32;
    for camera in cameras {
        for (crop, planes) in &cuts {
            for (jitter, step) in [(false, 1.0), (true, 0.7)] {
                let settings = RenderSettings {
                    width: 40,
                    height: 32,
                    camera,
                    step,
                    opacity_ramp: (0.0, 0.8),
                    transfer_function: colorful(),
                    background: [0.1, 0.1, 0.3],
                    crop: *crop,
                    clip_planes: planes.clone(),
                    jitter,
                    ..RenderSettings::default()
                };
                let (fast, reference) = both_paths(&renderer, &settings);
                let what = format!("{camera:?} {crop:?} {planes:?} {jitter}");
                worst = worst.max(assert_within_a_level(&fast, &reference, &what));
                assert!(reference.pixels().iter().any(|p| p[3] > 0.3));
            }
        }
    }
    println!(
        "largest difference with cuts: {:.3} of 1/255",
        worst * 255.0
    );
}

#[test]
fn jitter_is_deterministic_and_stays_close_to_the_plain_image_of_a_smooth_volume() {
    let volume = blobs([40, 40, 40], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let plain = RenderSettings {
        width: 64,
        height: 64,
        camera: Camera {
            view_point: Some(DVec3::new(150.0, 150.0, 500.0)),
            ..Camera::default()
        },
        opacity_ramp: (0.0, 0.6),
        ..RenderSettings::default()
    };
    let jittered = RenderSettings {
        jitter: true,
        ..plain.clone()
    };
    for settings in [jittered.clone(), on_the_reference(&jittered)] {
        let in_pool = |threads| render_on_threads(&renderer, &settings, threads);
        let (one, two, again) = (in_pool(1), in_pool(2), in_pool(2));
        assert!(one == two && two == again, "{:?}", settings.method);
        let unjittered = renderer
            .render(FrameRequest::new(&RenderSettings {
                jitter: false,
                ..settings.clone()
            }))
            .unwrap()
            .image();
        // Moving every sample by less than a step changes the picture, but
        // only a little: the volume is smooth at the scale of a voxel.
        let (max, mean) = (max_diff(&one, &unjittered), mean_diff(&one, &unjittered));
        println!(
            "{:?}: jitter changes pixels by {max:.4} at most, {mean:.5} on average",
            settings.method
        );
        assert!(max > 1e-3, "jitter moved the samples");
        assert!(max < 0.05 && mean < 0.002, "{max} {mean}");
    }
}

#[test]
fn post_classification_of_a_uniform_medium_has_the_closed_form_colour() {
    // As for pre-classification (tests/render.rs): K = 10/step + 1 samples
    // of colour c and opacity α_s = 1 − (1 − α)^step along each ray give
    // c(1 − (1 − α_s)^K) + bg(1 − α_s)^K. Lit, the uniform medium has no
    // gradient, so only the ambient term lights it.
    let volume = uniform_medium();
    let renderer = Renderer::new(&volume).unwrap();
    let (alpha, c, bg) = (0.3f64, [0.9, 0.5, 0.2], [0.1, 0.2, 1.0]);
    for (step, k) in [(1.0, 11), (0.5, 21), (0.25, 41)] {
        for (shading, method) in [false, true]
            .into_iter()
            .flat_map(|s| [(s, Method::Fast), (s, Method::Reference)])
        {
            let settings = RenderSettings {
                width: 14,
                height: 10,
                step,
                shading,
                classification: Classification::Post,
                transfer_function: constant_tf(alpha as f32, c),
                background: bg,
                method,
                ..RenderSettings::default()
            };
            let keep = (1.0 - alpha).powf(step * k as f64);
            let light = if shading { 0.1 } else { 1.0 };
            let image = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            assert_uniform_medium(&image, light, c, bg, keep, 1e-5, &format!("step {step}"));
        }
    }
}

#[test]
fn post_and_pre_classification_agree_on_a_smooth_volume() {
    let volume = blobs([40, 36, 44], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let camera = Camera {
        view_point: Some(DVec3::new(-40.0, 12.0, -9.0)),
        ..Camera::default()
    };
    // Unlit with the opacity ramp and no colour, classification is linear
    // in the value: it commutes with interpolation, so both orders give the
    // same samples.
    let linear = RenderSettings {
        width: 48,
        height: 48,
        camera,
        shading: false,
        opacity_ramp: (0.0, 0.7),
        method: Method::Reference,
        ..RenderSettings::default()
    };
    let post = |s: &RenderSettings| {
        renderer
            .render(FrameRequest::new(&RenderSettings {
                classification: Classification::Post,
                ..s.clone()
            }))
            .unwrap()
            .image()
    };
    let pre = renderer.render(FrameRequest::new(&linear)).unwrap().image();
    assert!(max_diff(&pre, &post(&linear)) < 1e-5);
    // Lit, with a non-linear transfer function, the orders differ but not
    // by much on data this smooth.
    let lit = RenderSettings {
        shading: true,
        transfer_function: colorful(),
        ..linear
    };
    let (pre, post) = (
        renderer.render(FrameRequest::new(&lit)).unwrap().image(),
        post(&lit),
    );
    let (max, mean) = (max_diff(&pre, &post), mean_diff(&pre, &post));
    println!("post vs pre: {max:.4} at most, {mean:.5} on average");
    assert!(
        max > 1e-4,
        "the orders differ under a non-linear transfer function"
    );
    assert!(max < 0.1 && mean < 0.01, "{max} {mean}");
}

#[test]
fn perspective_shows_a_near_ball_larger_than_the_same_ball_far_away() {
    // A ball of radius R = 0.3 (as a signed distance, made opaque inside
    // by a sharp step of the opacity, classified per sample so that the
    // silhouette is not blurred over a cell) seen from distance D with a
    // 40° field of view: a pixel is covered exactly when its ray passes
    // within R of the centre. From D = 1.5 the ball covers about four
    // times the pixels it covers from D = 3.
    let radius = 0.3;
    let h = 2.0 / 40.0;
    let volume = Volume::from_fn([41, 41, 41], DVec3::splat(h), DVec3::splat(-1.0), |p| {
        (radius - p.length()) as f32
    })
    .unwrap();
    let renderer = Renderer::new(&volume).unwrap();
    let covered = |distance: f64| {
        let camera = Camera {
            view_point: Some(DVec3::new(distance, 0.0, 0.0)),
            look_at: Some(DVec3::ZERO),
            projection: Projection::Perspective { fov_degrees: 40.0 },
            ..Camera::default()
        };
        let settings = RenderSettings {
            width: 64,
            height: 64,
            camera,
            classification: Classification::Post,
            transfer_function: TransferFunction {
                domain: Some((-1.0, 1.0)),
                opacity: Some(
                    PiecewiseLinear::new("opacity", vec![(0.4999, [0.0]), (0.5001, [1.0])])
                        .unwrap(),
                ),
                color: None,
            },
            ..RenderSettings::default()
        };
        // Both paths (post-classified compositing has its fast path,
        // tests/post_fast.rs).
        let view = View::frame(&camera, volume.bounds(), 64, 64).unwrap();
        let mut counts = Vec::new();
        for settings in [settings.clone(), on_the_reference(&settings)] {
            let image = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let mut count = 0;
            for row in 0..64 {
                for col in 0..64 {
                    let (o, d) = view.pixel_ray(col, row);
                    let miss_distance = o.cross(d).length();
                    let hit = image.get(col, row)[3] > 0.5;
                    count += hit as usize;
                    // Rays grazing the ball within a fifth of a voxel may go
                    // either way.
                    if (miss_distance - radius).abs() > 0.2 * h {
                        assert_eq!(hit, miss_distance < radius, "D {distance} ({col}, {row})");
                    }
                }
            }
            counts.push(count);
        }
        counts[0]
    };
    let (near, far) = (covered(1.5), covered(3.0));
    println!("the ball covers {near} pixels from 1.5, {far} from 3");
    assert!(near > 3 * far + far / 2, "{near} vs {far}");
}

#[test]
fn bad_crops_and_clip_planes_are_refused_by_name() {
    let volume = ball(5, 0.5, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let plane = |point: DVec3, normal: DVec3| RenderSettings {
        clip_planes: vec![ClipPlane { point, normal }],
        ..RenderSettings::default()
    };
    let crop = |lo: DVec3, hi: DVec3| RenderSettings {
        crop: Some((lo, hi)),
        ..RenderSettings::default()
    };
    let cases = [
        (plane(DVec3::ZERO, DVec3::ZERO), "clip plane normal"),
        (
            plane(DVec3::ZERO, DVec3::new(f64::NAN, 1.0, 0.0)),
            "clip plane normal",
        ),
        (
            plane(DVec3::new(0.0, f64::INFINITY, 0.0), DVec3::X),
            "clip plane point",
        ),
        (crop(DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0)), "crop box"),
        (crop(DVec3::ONE, DVec3::ZERO), "crop box"),
        (
            crop(DVec3::ZERO, DVec3::new(1.0, f64::NAN, 1.0)),
            "crop box",
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
