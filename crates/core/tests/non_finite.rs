//! Non-finite voxel values (NaN, ±∞): refused by default, or rendered as
//! empty space ([`NonFinite::Transparent`], see `volray_core::non_finite`),
//! checked against closed forms, against the same data with those voxels
//! cut away, and the fast paths against the reference.

mod common;

use common::{
    assert_uniform_medium, assert_within_a_level, colorful, constant_tf, grey_unit_window,
    on_the_reference, uniform_medium,
};
use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::{
    Blend, Classification, ClipPlane, Image, IsoSurface, Method, NonFinite, RenderError,
    RenderSettings, Renderer, TransferFunction, Volume,
};
use volray_core::{FrameRequest, Render};

fn transparent(volume: &Volume) -> Renderer<'_> {
    Renderer::with_non_finite(volume, NonFinite::Transparent).unwrap()
}

/// `common::blobs` on `dims` unit voxels from the world origin.
fn blobs(dims: [usize; 3]) -> Volume {
    common::blobs(dims, DVec3::ONE, DVec3::ZERO)
}

/// `volume` with the voxels `hole(i, j, k)` names set to its value.
fn with_holes(volume: &Volume, hole: impl Fn(usize, usize, usize) -> Option<f32>) -> Volume {
    let [nx, ny, nz] = volume.dims();
    let mut data = volume.values().to_vec();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                if let Some(v) = hole(i, j, k) {
                    data[volume.index(i, j, k)] = v;
                }
            }
        }
    }
    Volume::new(volume.dims(), data)
        .unwrap()
        .with_spacing(volume.spacing())
        .unwrap()
        .with_origin(volume.origin())
        .unwrap()
}

/// NaN, +∞ and −∞ in turn, by position: every kind in every region.
fn non_finite(i: usize, j: usize, k: usize) -> f32 {
    [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][(i + 2 * j + k) % 3]
}

#[test]
fn non_finite_values_are_refused_by_default_with_their_count() {
    let volume = with_holes(&blobs([9, 8, 7]), |i, j, k| {
        (i == 3 && j < 4 && k == 2).then(|| non_finite(i, j, k))
    });
    let err = Renderer::new(&volume).err().unwrap();
    assert_eq!(
        err,
        RenderError::NonFinite {
            count: 4,
            total: 504
        }
    );
    assert_eq!(
        err.to_string(),
        "4 of 504 values are not finite (NaN or infinite)"
    );
    let refused = Renderer::with_non_finite(&volume, NonFinite::Refuse).err();
    assert_eq!(refused, Some(err));
    // Transparent: the window is the finite values'.
    let renderer = transparent(&volume);
    assert_eq!(renderer.value_range(), volume.value_range().unwrap());
    assert_eq!(renderer.non_finite().unwrap().count(), 4);
    assert!(renderer.volume().values().iter().all(|v| v.is_finite()));
    // A finite volume is rendered as it is, whatever the mode.
    let finite = blobs([9, 8, 7]);
    let renderer = transparent(&finite);
    assert!(renderer.non_finite().is_none());
    assert!(std::ptr::eq(renderer.volume(), &finite));
    let settings = RenderSettings {
        width: 16,
        height: 16,
        ..RenderSettings::default()
    };
    let plain = Renderer::new(&finite)
        .unwrap()
        .render(FrameRequest::new(&settings))
        .unwrap()
        .image();
    assert!(
        renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image()
            == plain
    );
}

#[test]
fn a_non_finite_slab_in_a_uniform_medium_leaves_the_shorter_medium() {
    // 11 points along x, the default view along −x, so every ray's samples
    // lie at x = 0, step, …, 10 (tests/render.rs). The planes x = 4, 5, 6
    // hold NaN and ±∞. At step 1 every sample is on a plane: 8 of them in
    // the medium (colour c, opacity α_s), 3 in the slab (no opacity), so
    // the pixel is c(1 − (1 − α_s)^8) + bg(1 − α_s)^8. At step 0.5:
    // - pre-classified, the opacities are interpolated: the samples at
    //   x = 3.5 and 6.5 get α_s/2 (the fade over the slab's faces' cells)
    //   and the five in [4, 6] none, so the transmittance is
    //   (1 − α_s)^14 (1 − α_s/2)^2 (the masked voxels' colour is the
    //   medium's: they hold the fill value, the medium's, and, like the
    //   medium, have no gradient);
    // - post-classified (and in any mode a non-finite voxel weighs in a
    //   sample), those two are skipped: (1 − α_s)^14.
    // Lit, the medium has no gradient: ambient light only, 0.1 c.
    let medium = uniform_medium();
    let volume = with_holes(&medium, |i, j, k| {
        (4..=6).contains(&i).then(|| non_finite(i, j, k))
    });
    let renderer = transparent(&volume);
    let (alpha, c, bg) = (0.3f64, [0.9, 0.5, 0.2], [0.1, 0.2, 1.0]);
    let mut checked = 0;
    for classification in [Classification::Pre, Classification::Post] {
        for step in [1.0, 0.5] {
            let a = 1.0 - (1.0 - alpha).powf(step);
            let keep = match (step == 1.0, classification) {
                (true, _) => (1.0 - a).powi(8),
                (false, Classification::Pre) => (1.0 - a).powi(14) * (1.0 - a / 2.0).powi(2),
                (false, Classification::Post) => (1.0 - a).powi(14),
            };
            for shading in [false, true] {
                for method in [Method::Fast, Method::Reference] {
                    let settings = RenderSettings {
                        width: 14,
                        height: 10,
                        step,
                        shading,
                        classification,
                        transfer_function: constant_tf(alpha as f32, c),
                        background: bg,
                        method,
                        ..RenderSettings::default()
                    };
                    let light = if shading { 0.1 } else { 1.0 };
                    let tol = match method {
                        Method::Reference => 1e-5,
                        Method::Fast => 1.0 / 255.0,
                    };
                    let image = renderer
                        .render(FrameRequest::new(&settings))
                        .unwrap()
                        .image();
                    let what = format!("{classification:?} step {step} {method:?}");
                    assert_uniform_medium(&image, light, c, bg, keep, tol, &what);
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 16);
}

/// Blobs with non-finite regions: a slab across a blob, a ball inside
/// another, a brick-face plane patch, a rod along a brick edge and single
/// voxels at brick corners (bricks are 8 cells wide).
fn holed_blobs() -> Volume {
    let volume = blobs([34, 30, 38]);
    with_holes(&volume, |i, j, k| {
        let (x, y, z) = (i as f64, j as f64, k as f64);
        let slab = (9..=11).contains(&i) && j >= 6 && k <= 28;
        let ball = (x - 23.0).powi(2) + (y - 18.0).powi(2) + (z - 11.0).powi(2) < 12.0;
        let face = k == 16 && (3..=20).contains(&i) && (2..=12).contains(&j);
        let rod = j == 8 && k == 24 && i >= 14;
        let corner = [(8, 8, 8), (16, 16, 8), (24, 8, 32)].contains(&(i, j, k));
        (slab || ball || face || rod || corner).then(|| non_finite(i, j, k))
    })
}

#[test]
fn fast_paths_match_the_reference_with_non_finite_regions_in_every_mode() {
    let volume = holed_blobs();
    let renderer = transparent(&volume);
    let count = renderer.non_finite().unwrap().count();
    assert!(count > 400, "{count}");
    // The cleaned copy rendered as if its fill values were data: the mask
    // must change every mode's picture, or the comparison shows nothing.
    let unmasked = Renderer::new(renderer.volume()).unwrap();
    let cameras = [
        Camera {
            view_point: Some(DVec3::new(150.0, 110.0, 400.0)),
            ..Camera::default()
        },
        Camera {
            view_point: Some(DVec3::new(-60.0, 40.0, -25.0)),
            ..Camera::default()
        },
        Camera {
            projection: Projection::Perspective { fov_degrees: 40.0 },
            azimuth: 35.0,
            elevation: -25.0,
            ..Camera::default()
        },
    ];
    let base = RenderSettings {
        width: 44,
        height: 40,
        transfer_function: colorful(),
        background: [0.1, 0.1, 0.3],
        ..RenderSettings::default()
    };
    let opaque_low = RenderSettings {
        transfer_function: TransferFunction {
            opacity: None,
            ..colorful()
        },
        opacity_ramp: (0.15, 0.6),
        ..base.clone()
    };
    let iso = Some(IsoSurface {
        value: 0.45,
        thickness: 1.5,
    });
    // Each mode, and whether masking changes its picture from that of the
    // cleaned copy taken as data: not where the fill value (the bottom of
    // the range) is transparent anyway and pre-classification gives the
    // masked voxels the same zero opacity; elsewhere it must.
    let modes: Vec<(&str, RenderSettings)> = vec![
        ("pre", base.clone()),
        ("pre, opaque at the fill value", opaque_low.clone()),
        (
            "post",
            RenderSettings {
                classification: Classification::Post,
                ..opaque_low.clone()
            },
        ),
        (
            "post, step 0.7, jitter",
            RenderSettings {
                classification: Classification::Post,
                step: 0.7,
                jitter: true,
                ..base.clone()
            },
        ),
        (
            "pre, iso",
            RenderSettings {
                iso,
                ..base.clone()
            },
        ),
        (
            "post, iso",
            RenderSettings {
                iso,
                classification: Classification::Post,
                ..base.clone()
            },
        ),
        (
            "pre, gradient opacity, clipped",
            RenderSettings {
                gradient_opacity: Some((0.05, 0.5)),
                clip_planes: vec![ClipPlane {
                    point: volume.centre(),
                    normal: DVec3::new(0.2, -1.0, 0.4),
                }],
                ..opaque_low.clone()
            },
        ),
        (
            "maximum",
            RenderSettings {
                blend: Blend::Maximum,
                ..base.clone()
            },
        ),
        (
            "minimum, step 0.6",
            RenderSettings {
                blend: Blend::Minimum,
                step: 0.6,
                ..base.clone()
            },
        ),
        (
            "average, jitter",
            RenderSettings {
                blend: Blend::Average,
                jitter: true,
                ..base.clone()
            },
        ),
    ];
    let mut worst = 0.0f32;
    for (name, settings) in &modes {
        let mut changed = 0.0f32;
        for camera in cameras {
            let settings = RenderSettings {
                camera,
                ..settings.clone()
            };
            let fast = renderer
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let slow = renderer
                .render(FrameRequest::new(&on_the_reference(&settings)))
                .unwrap()
                .image();
            let diff = assert_within_a_level(&fast, &slow, &format!("{name}, {camera:?}"));
            worst = worst.max(diff);
            assert!(
                slow.pixels().iter().any(|p| p[3] > 0.2),
                "{name}: the image is empty"
            );
            let plain = unmasked
                .render(FrameRequest::new(&on_the_reference(&settings)))
                .unwrap()
                .image();
            changed = changed.max(plain.max_abs_diff(&slow).unwrap());
        }
        println!("{name}: masking changed the picture by {changed}");
        if *name == "pre" {
            assert_eq!(changed, 0.0, "{name}");
        } else if !name.contains("iso") {
            assert!(
                changed > 0.05,
                "{name}: the mask changed nothing ({changed})"
            );
        }
    }
    println!(
        "largest fast-vs-reference difference with non-finite voxels: {:.3} of 1/255",
        worst * 255.0
    );
}

#[test]
fn projections_with_infinite_voxels_equal_those_of_the_data_cut_before_them() {
    // +∞ fills the planes x ≥ 22 of the blobs (in index space; the grid has
    // spacing 0.5 and an offset origin). A sample counts when no +∞ voxel
    // weighs in it: exactly when x ≤ 21, where the crop box of the world
    // planes up to x = 21 cuts. So the maximum, minimum and mean of the
    // masked volume are those of the volume cropped there, its +∞ voxels
    // replaced by 2.0, brighter than any blob value (so any sample that
    // weighed them would show), in every view, on both paths.
    let blobs = blobs([30, 26, 28]);
    let place = |v: Volume| {
        v.with_spacing(DVec3::splat(0.5))
            .unwrap()
            .with_origin(DVec3::new(-4.0, 1.0, 2.5))
            .unwrap()
    };
    let infinite = place(with_holes(&blobs, |i, _, _| {
        (i >= 22).then_some(f32::INFINITY)
    }));
    let bright = place(with_holes(&blobs, |i, _, _| (i >= 22).then_some(2.0)));
    let (lo, hi) = bright.bounds();
    let cut_x = bright.world_position(21, 0, 0).x;
    let crop = Some((lo - DVec3::ONE, DVec3::new(cut_x, hi.y + 1.0, hi.z + 1.0)));
    let (masked, cropped) = (transparent(&infinite), Renderer::new(&bright).unwrap());
    let cameras = [
        Camera::default(),
        Camera {
            view_point: Some(DVec3::new(40.0, -35.0, 20.0)),
            ..Camera::default()
        },
        Camera {
            projection: Projection::Perspective { fov_degrees: 30.0 },
            azimuth: -40.0,
            elevation: 15.0,
            ..Camera::default()
        },
    ];
    for blend in [Blend::Maximum, Blend::Minimum, Blend::Average] {
        for camera in cameras {
            for method in [Method::Fast, Method::Reference] {
                let settings = RenderSettings {
                    width: 40,
                    height: 36,
                    camera,
                    step: 0.7,
                    blend,
                    method,
                    transfer_function: grey_unit_window(),
                    ..RenderSettings::default()
                };
                let got = masked.render(FrameRequest::new(&settings)).unwrap().image();
                let want = cropped
                    .render(FrameRequest::new(&RenderSettings {
                        crop,
                        ..settings.clone()
                    }))
                    .unwrap()
                    .image();
                let diff = got.max_abs_diff(&want).unwrap();
                assert!(diff < 1e-6, "{blend:?} {camera:?} {method:?}: {diff}");
                assert!(got.pixels().iter().filter(|p| p[3] == 1.0).count() > 200);
                // Uncropped, the bright planes show: the cut is not vacuous.
                let whole = cropped
                    .render(FrameRequest::new(&settings))
                    .unwrap()
                    .image();
                if blend == Blend::Maximum {
                    assert!(whole.max_abs_diff(&got).unwrap() > 0.1);
                }
            }
        }
    }
}

#[test]
fn a_blob_in_a_sea_of_nan_renders_as_the_blob() {
    // Every voxel NaN but a ball of radius 6 voxels about the centre of a
    // 25³ grid, where f = 1 − r²/64. Seen along −x, every sample lies on an
    // x plane of the grid, where trilinear interpolation is bilinear in y
    // and z, and the bilinear interpolation of y² in the cell [a, a + 1] is
    // y² + (y − a)(a + 1 − y). So a counted sample on the plane x has the
    // value 1 − ((x − 12)² + (y − 12)² + e(y) + (z − 12)² + e(z))/64, and
    // the largest is on the plane x = 12, counted when the four voxels of
    // its cell are in the ball (within 6 of the centre), as they are when
    // the ray passes within 4.5 of it: that is the maximum projection. A
    // ray passing further than 6 from the centre has no sample in the
    // ball's convex hull of finite voxels, so every sample has a NaN voxel
    // of non-zero weight: it shows the background. Composited, the ball's
    // disc shows and the NaN sea does not.
    let n = 25;
    let c = 12.0;
    let volume = Volume::from_fn([n, n, n], DVec3::ONE, DVec3::ZERO, |p| {
        let r2 = (p - DVec3::splat(c)).length_squared();
        if r2 <= 36.0 {
            (1.0 - r2 / 64.0) as f32
        } else {
            f32::NAN
        }
    })
    .unwrap();
    let renderer = transparent(&volume);
    assert!(renderer.non_finite().unwrap().count() > n * n * n - 1000);
    let bg = [0.2, 0.3, 0.4];
    // 25 pixels across the 24-unit face: pixel (col, row) looks along the
    // line y = 24·(col + 0.5)/25, z = 24 − 24·(row + 0.5)/25.
    let line = |col: usize, row: usize| {
        let h = 24.0 / 25.0;
        (h * (col as f64 + 0.5), 24.0 - h * (row as f64 + 0.5))
    };
    for method in [Method::Fast, Method::Reference] {
        let settings = RenderSettings {
            width: 25,
            height: 25,
            blend: Blend::Maximum,
            transfer_function: grey_unit_window(),
            background: bg,
            method,
            ..RenderSettings::default()
        };
        let image = renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        assert!((image.get(12, 12)[0] - 1.0).abs() < 1e-6, "{method:?}");
        for row in 0..25 {
            for col in 0..25 {
                let (y, z) = line(col, row);
                let d = ((y - c).powi(2) + (z - c).powi(2)).sqrt();
                let px = image.get(col, row);
                if d > 6.0 {
                    assert_eq!(px, [bg[0], bg[1], bg[2], 0.0], "{col} {row}");
                } else if d < 4.5 {
                    let e = |u: f64| (u - u.floor()) * (u.floor() + 1.0 - u);
                    let want = 1.0 - (d * d + e(y) + e(z)) / 64.0;
                    assert!(
                        (px[0] as f64 - want).abs() < 1e-5,
                        "{col} {row}: {px:?} vs {want}"
                    );
                }
            }
        }
        // Composited, with an opacity table opaque at every value: the
        // ball's disc is lit and the rest is background (pre-classified,
        // a sample's voxels are within √2 of it on its x plane: rays
        // further than 6 + √2 from the centre take no opacity).
        let settings = RenderSettings {
            blend: Blend::Composite,
            transfer_function: constant_tf(0.4, [1.0, 0.5, 0.0]),
            ..settings
        };
        for classification in [Classification::Pre, Classification::Post] {
            let image = renderer
                .render(FrameRequest::new(&RenderSettings {
                    classification,
                    ..settings.clone()
                }))
                .unwrap()
                .image();
            for row in 0..25 {
                for col in 0..25 {
                    let (y, z) = line(col, row);
                    let d = ((y - c).powi(2) + (z - c).powi(2)).sqrt();
                    let alpha = image.get(col, row)[3];
                    if d > 7.5 {
                        assert_eq!(alpha, 0.0, "{classification:?} {col} {row}");
                    } else if d < 4.5 {
                        assert!(alpha > 0.9, "{classification:?} {col} {row}: {alpha}");
                    }
                }
            }
        }
    }
}

#[test]
fn a_volume_of_nothing_but_non_finite_values_renders_the_background() {
    let volume = Volume::new([9, 10, 11], vec![f32::NAN; 990]).unwrap();
    let renderer = transparent(&volume);
    assert_eq!(renderer.value_range(), (0.0, 0.0));
    let bg = [0.3, 0.6, 0.9];
    for blend in [Blend::Composite, Blend::Maximum, Blend::Average] {
        for classification in [Classification::Pre, Classification::Post] {
            for method in [Method::Fast, Method::Reference] {
                let settings = RenderSettings {
                    width: 12,
                    height: 12,
                    blend,
                    classification,
                    method,
                    opacity_ramp: (0.5, 0.9),
                    background: bg,
                    ..RenderSettings::default()
                };
                let image = renderer
                    .render(FrameRequest::new(&settings))
                    .unwrap()
                    .image();
                let want = Image::new(12, 12, [bg[0], bg[1], bg[2], 0.0]);
                assert!(image == want, "{blend:?} {classification:?} {method:?}");
            }
        }
    }
}
