//! The surface renderer against closed forms: a sphere's silhouette and
//! shading, the nearest of two lobes of |Y_10|², the disc of |Y_00|², the
//! camera's screen axes, supersampling as a box filter, and bad settings.

use std::f64::consts::PI;

use volray_core::LightGeometry;
use volray_data::hydrogen::SphericalHarmonic;
use volray_surface::glam::{DVec3, Vec3};
use volray_surface::{
    Camera, Image, Phong, PolarSurface, SurfaceError, SurfaceSettings, render, render_with_depth,
};

/// The paper's oblique view point (Figure 1b, 1c).
const OBLIQUE: DVec3 = DVec3::new(150.0, 150.0, 500.0);

fn oblique() -> Camera {
    Camera {
        view_point: Some(OBLIQUE),
        ..Camera::default()
    }
}

fn sphere(radius: f64) -> PolarSurface {
    PolarSurface::new(move |_, _| radius, 64, 128).unwrap()
}

/// Checks that the covered pixels (alpha 1; alpha 0 elsewhere) form a disc
/// of radius `radius` pixels about the image centre: every row's and every
/// column's run of covered pixels is the chord of that circle within one
/// pixel, and the run is centred.
fn assert_disc(image: &Image, radius: f64) {
    let (w, h) = (image.width(), image.height());
    let (cx, cy) = (0.5 * w as f64, 0.5 * h as f64);
    assert!(
        image.pixels().iter().all(|p| p[3] == 0.0 || p[3] == 1.0),
        "one sample per pixel covers all or nothing"
    );
    let covered = |c: usize, r: usize| image.get(c, r)[3] == 1.0;
    for (lines, length, centre, along) in [(h, w, cy, cx), (w, h, cx, cy)] {
        for line in 0..lines {
            let offset = line as f64 + 0.5 - centre;
            let chord = 2.0 * (radius * radius - offset * offset).max(0.0).sqrt();
            let hits: Vec<usize> = (0..length)
                .filter(|&k| {
                    if lines == h {
                        covered(k, line)
                    } else {
                        covered(line, k)
                    }
                })
                .collect();
            assert!(
                (hits.len() as f64 - chord).abs() < 1.1,
                "line {line}: {} pixels covered, chord {chord:.2}",
                hits.len()
            );
            if let (Some(&first), Some(&last)) = (hits.first(), hits.last()) {
                assert_eq!(last + 1 - first, hits.len(), "line {line}: one run");
                let middle = 0.5 * (first + last + 1) as f64;
                assert!(
                    (middle - along).abs() <= 1.0,
                    "line {line}: run centred at {middle}"
                );
            }
        }
    }
}

#[test]
fn a_sphere_is_a_disc_of_its_radius_over_the_pixel_size() {
    let radius = 1.7;
    let surface = sphere(radius);
    for (size, half_window) in [(101, Some(1.3 * radius)), (96, None)] {
        let settings = SurfaceSettings {
            width: size,
            height: size,
            camera: oblique(),
            half_window,
            ..SurfaceSettings::default()
        };
        let image = render(&surface, &settings).unwrap();
        let pixel_size = 2.0 * half_window.unwrap_or(radius) / size as f64;
        assert_disc(&image, radius / pixel_size);
    }
}

#[test]
fn a_sphere_is_lit_by_the_closed_form_of_phong() {
    let radius = 0.8;
    let phong = Phong {
        ambient: [0.15, 0.1, 0.05],
        diffuse: [0.5, 0.6, 0.3],
        specular: [0.3, 0.2, 0.4],
        shininess: 12.0,
        light_color: [1.0, 0.8, 0.6],
    };
    let color = [0.9, 0.5, 0.25];
    let settings = SurfaceSettings {
        width: 65,
        height: 65,
        camera: oblique(),
        phong,
        color,
        half_window: Some(1.1 * radius),
        ..SurfaceSettings::default()
    };
    let (image, depth) = render_with_depth(&sphere(radius), &settings).unwrap();
    let pixel_size = 2.0 * 1.1 * radius / 65.0;
    // Headlight: L = V = H, so with the exact normal at angle α to V,
    // C = C_s·(k_a + k_d cos α + k_s cos^n α) times the material colour.
    let expect = |cos: f32| -> [f32; 3] {
        std::array::from_fn(|c| {
            phong.light_color[c]
                * (phong.ambient[c] + phong.diffuse[c] * cos + phong.specular[c] * cos.powf(12.0))
                * color[c]
        })
    };
    // The centre pixel's ray meets the sphere head on: N = L = V.
    let centre = image.get(32, 32);
    let head_on = expect(1.0);
    for c in 0..3 {
        assert!(
            (centre[c] - head_on[c]).abs() < 1e-4,
            "{centre:?} vs {head_on:?}"
        );
    }
    // Its depth is the sphere's nearest point, −R, up to the mesh's sag
    // R (1 − cos(Δ/2)) for cells of Δ = π/64.
    assert!(
        (depth[32 + 65 * 32] + radius).abs() < radius * 1.3e-3,
        "{}",
        depth[32 + 65 * 32]
    );
    // Everywhere inside 0.9 R the shading follows cos α = √(1 − ρ²/R²).
    let mut worst = 0.0f32;
    for row in 0..65 {
        for col in 0..65 {
            let (u, v) = (col as f64 - 32.0, row as f64 - 32.0);
            let rho = (u * u + v * v).sqrt() * pixel_size / radius;
            if rho > 0.9 {
                continue;
            }
            let want = expect((1.0 - rho * rho).sqrt() as f32);
            let got = image.get(col, row);
            for c in 0..3 {
                worst = worst.max((got[c] - want[c]).abs());
            }
            let nearest = -radius * (1.0 - rho * rho).sqrt();
            assert!((depth[col + 65 * row] - nearest).abs() < 2e-3 * radius);
        }
    }
    assert!(worst < 2e-3, "largest shading error {worst}");
}

#[test]
fn phong_shading_keeps_the_highlight_of_a_coarse_mesh() {
    // A sphere of only 6 × 12 cells: no vertex normal faces the oblique
    // viewer (the nearest is about 13° off), so interpolating colours
    // (Gouraud) would miss the highlight; interpolating normals finds it.
    let phong = Phong {
        shininess: 60.0,
        ..Phong::default()
    };
    let surface = PolarSurface::new(|_, _| 1.0, 6, 12).unwrap();
    let v = OBLIQUE.normalize();
    let best_vertex = surface
        .normals()
        .iter()
        .map(|n| n.dot(v))
        .fold(f64::MIN, f64::max);
    let gouraud_peak = 0.1 + 0.7 * best_vertex + 0.2 * best_vertex.powi(60);
    let settings = SurfaceSettings {
        width: 64,
        height: 64,
        camera: oblique(),
        phong,
        ..SurfaceSettings::default()
    };
    let image = render(&surface, &settings).unwrap();
    let peak = image.pixels().iter().map(|p| p[0]).fold(0.0f32, f32::max);
    assert!(gouraud_peak < 0.9, "{gouraud_peak}");
    assert!(peak > 0.99, "peak {peak}");
}

/// The nearest point of the polar surface |Y_10|² = c cos²θ along a ray
/// parallel to the z axis at distance `rho` from it, on the side of the lobe
/// facing the viewer: its distance `c cos³θ` from the plane z = 0 and its
/// polar angle θ from the lobe's axis, with `c cos²θ sin θ = rho` solved by
/// bisection on the near branch `tan θ < 1/√2`.
fn y10_nearest(c: f64, rho: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (0.0, (0.5f64).sqrt().atan());
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if c * mid.cos().powi(2) * mid.sin() < rho {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let theta = 0.5 * (lo + hi);
    (c * theta.cos().powi(3), theta)
}

#[test]
fn the_z_buffer_shows_the_nearer_lobe_of_y10() {
    // Seen along the z axis, the two lobes of |Y_10|² cover the same
    // pixels; from either side only the lobe facing the viewer may show,
    // with its own depth and its own (oblique, light-dependent) shading.
    let harmonic = SphericalHarmonic::new(1, 0).unwrap();
    let c = 3.0 / (4.0 * PI);
    let surface = PolarSurface::new(|t, _| harmonic.norm_sqr(t), 64, 128).unwrap();
    assert!((surface.max_radius() - c).abs() < 1e-12);
    let (size, half) = (64, 0.1);
    let pixel_size = 2.0 * half / size as f64;
    for side in [1.0, -1.0] {
        let light = DVec3::new(1.0, 0.3, side);
        let settings = SurfaceSettings {
            width: size,
            height: size,
            camera: Camera {
                view_point: Some(DVec3::new(0.0, 0.0, 500.0 * side)),
                up: DVec3::Y,
                ..Camera::default()
            },
            light_direction: Some(light),
            half_window: Some(half),
            ..SurfaceSettings::default()
        };
        let (image, depth) = render_with_depth(&surface, &settings).unwrap();
        // d = ∓z, up = +y: right = d × up = ±x.
        let geometry = LightGeometry::new(
            light.normalize().as_vec3(),
            Vec3::new(0.0, 0.0, side as f32),
        );
        let mut checked = 0;
        for row in 0..size {
            for col in 0..size {
                let x = side * (col as f64 + 0.5 - 0.5 * size as f64) * pixel_size;
                let y = -(row as f64 + 0.5 - 0.5 * size as f64) * pixel_size;
                let rho = x.hypot(y);
                // The lobe's widest ring is at ρ = c·2/(3√3) ≈ 0.092; keep
                // away from its silhouette.
                if rho > 0.08 {
                    continue;
                }
                let (height, theta) = y10_nearest(c, rho);
                let d = depth[col + size * row];
                assert!(
                    (d + height).abs() < 1e-3,
                    "pixel {col},{row}: depth {d}, expected {}",
                    -height
                );
                // Outward normal of the lobe at (θ, φ) on the viewer's side:
                // r u − r_θ e_θ with r = c cos²θ, r_θ = −2c cos θ sin θ,
                // mirrored through z = 0 for the lower lobe.
                let phi = y.atan2(x);
                let (st, ct) = theta.sin_cos();
                let u = DVec3::new(st * phi.cos(), st * phi.sin(), ct);
                let e_theta = DVec3::new(ct * phi.cos(), ct * phi.sin(), -st);
                let n = c * ct * ct * u + 2.0 * c * ct * st * e_theta;
                let n = DVec3::new(n.x, n.y, side * n.z);
                let want = Phong::default().shade(n.as_vec3(), &geometry);
                let got = image.get(col, row);
                for k in 0..3 {
                    assert!(
                        (got[k] - want[k]).abs() < 5e-3,
                        "pixel {col},{row}: {got:?} vs {want:?}"
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 1500, "{checked}");
    }
}

#[test]
fn y00_renders_as_a_disc_of_radius_one_over_four_pi() {
    let harmonic = SphericalHarmonic::new(0, 0).unwrap();
    let surface = PolarSurface::new(|t, _| harmonic.norm_sqr(t), 32, 64).unwrap();
    let radius = 1.0 / (4.0 * PI);
    assert!((surface.max_radius() - radius).abs() < 1e-15);
    for camera in [Camera::default(), oblique()] {
        let settings = SurfaceSettings {
            width: 64,
            height: 64,
            camera,
            half_window: Some(0.1),
            ..SurfaceSettings::default()
        };
        let image = render(&surface, &settings).unwrap();
        assert_disc(&image, radius / (0.2 / 64.0));
    }
}

#[test]
fn screen_axes_follow_the_volume_cameras() {
    // A sphere with a spike along +y (r up to 1.6) and a smaller one
    // along +z (r up to 1.3). From the default view point on +x with z up,
    // screen right is d × up = (−x) × z = +y and screen up is +z.
    let spikes = |t: f64, p: f64| {
        let u = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
        1.0 + 0.6 * u.y.max(0.0).powi(8) + 0.3 * u.z.max(0.0).powi(8)
    };
    let surface = PolarSurface::new(spikes, 48, 96).unwrap();
    let settings = SurfaceSettings {
        width: 80,
        height: 80,
        half_window: Some(2.0),
        ..SurfaceSettings::default()
    };
    let image = render(&surface, &settings).unwrap();
    let covered: Vec<(usize, usize)> = (0..80)
        .flat_map(|r| (0..80).map(move |c| (c, r)))
        .filter(|&(c, r)| image.get(c, r)[3] == 1.0)
        .collect();
    let pixel = 4.0 / 80.0;
    let extent =
        |f: &dyn Fn(&(usize, usize)) -> f64| covered.iter().map(f).fold(f64::MIN, f64::max);
    let right = extent(&|&(c, _)| (c as f64 + 0.5 - 40.0) * pixel);
    let left = extent(&|&(c, _)| (40.0 - c as f64 - 0.5) * pixel);
    let top = extent(&|&(_, r)| (40.0 - r as f64 - 0.5) * pixel);
    let bottom = extent(&|&(_, r)| (r as f64 + 0.5 - 40.0) * pixel);
    for (got, want) in [(right, 1.6), (left, 1.0), (top, 1.3), (bottom, 1.0)] {
        assert!(
            (got - want).abs() < 1.5 * pixel,
            "{right} {left} {top} {bottom}"
        );
    }
}

#[test]
fn the_fitted_window_holds_the_projection() {
    // An ellipsoid with semi-axes 1, 0.5, 0.3 along x, y, z, seen from +x
    // (screen right +y, up +z): its outline is the ellipse of semi-axes
    // 0.5 × 0.3, so a 60 × 40 image needs a half window of
    // max(0.5 · 40/60, 0.3) = 1/3 (up to the mesh's sag), not the sphere's 1.
    let (a, b, c) = (1.0, 0.5, 0.3);
    let ellipsoid = move |t: f64, p: f64| {
        let (st, ct) = t.sin_cos();
        let (sp, cp) = p.sin_cos();
        1.0 / ((st * cp / a).powi(2) + (st * sp / b).powi(2) + (ct / c).powi(2)).sqrt()
    };
    let surface = PolarSurface::new(ellipsoid, 64, 128).unwrap();
    let settings = SurfaceSettings {
        width: 60,
        height: 40,
        ..SurfaceSettings::default()
    };
    let half = volray_surface::fitted_half_window(&surface, &settings).unwrap();
    assert!((half - 1.0 / 3.0).abs() < 1e-4, "{half}");
    // Rendered with it, the outline reaches the left and right edges.
    let image = render(
        &surface,
        &SurfaceSettings {
            half_window: Some(half),
            ..settings
        },
    )
    .unwrap();
    assert!(image.get(0, 20)[3] == 1.0 && image.get(59, 20)[3] == 1.0);
    assert!(image.get(30, 0)[3] == 0.0 && image.get(30, 39)[3] == 0.0);
    assert!(image.get(30, 5)[3] == 1.0 && image.get(30, 34)[3] == 1.0);
}

#[test]
fn supersampling_is_a_box_filter_of_the_finer_image() {
    let surface = PolarSurface::new(|t, p| 0.5 + 0.4 * (t.sin() * p.cos()).abs(), 24, 48).unwrap();
    let settings = SurfaceSettings {
        width: 40,
        height: 30,
        camera: oblique(),
        background: [0.2, 0.4, 0.6],
        half_window: Some(1.0),
        ..SurfaceSettings::default()
    };
    let (coarse, coarse_depth) = render_with_depth(
        &surface,
        &SurfaceSettings {
            supersampling: 2,
            ..settings
        },
    )
    .unwrap();
    let (fine, fine_depth) = render_with_depth(
        &surface,
        &SurfaceSettings {
            width: 80,
            height: 60,
            ..settings
        },
    )
    .unwrap();
    let mut partial = 0;
    for row in 0..30 {
        for col in 0..40 {
            let block =
                [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| (2 * col + dx, 2 * row + dy));
            let got = coarse.get(col, row);
            for (k, value) in got.iter().enumerate() {
                let mean = block.iter().map(|&(c, r)| fine.get(c, r)[k]).sum::<f32>() / 4.0;
                assert!((value - mean).abs() < 1e-6, "pixel {col},{row}");
            }
            let nearest = block
                .iter()
                .map(|&(c, r)| fine_depth[c + 80 * r])
                .fold(f64::INFINITY, f64::min);
            assert_eq!(coarse_depth[col + 40 * row], nearest);
            if got[3] > 0.0 && got[3] < 1.0 {
                partial += 1;
            }
        }
    }
    assert!(
        partial > 20,
        "the silhouette has partly covered pixels: {partial}"
    );
}

#[test]
fn the_picture_does_not_depend_on_the_thread_count() {
    let surface =
        PolarSurface::new(|t, p| 0.3 + (t.cos() * (2.0 * p).sin()).powi(2), 32, 64).unwrap();
    let settings = SurfaceSettings {
        width: 96,
        height: 96,
        camera: oblique(),
        supersampling: 2,
        ..SurfaceSettings::default()
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render_with_depth(&surface, &settings).unwrap())
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn bad_settings_are_refused_with_one_line_errors() {
    let surface = sphere(1.0);
    let base = SurfaceSettings::default();
    let cases: Vec<(SurfaceSettings, &str)> = vec![
        (SurfaceSettings { width: 0, ..base }, "image size 0 × 120"),
        (
            SurfaceSettings {
                width: 1 << 14,
                height: 1 << 14,
                ..base
            },
            "the samples at most",
        ),
        (
            SurfaceSettings {
                supersampling: 0,
                ..base
            },
            "supersampling 0",
        ),
        (
            SurfaceSettings {
                supersampling: 9,
                ..base
            },
            "supersampling 9",
        ),
        (
            SurfaceSettings {
                half_window: Some(f64::NAN),
                ..base
            },
            "half window NaN",
        ),
        (
            SurfaceSettings {
                half_window: Some(-1.0),
                ..base
            },
            "half window -1",
        ),
        (
            SurfaceSettings {
                light_direction: Some(DVec3::ZERO),
                ..base
            },
            "light direction",
        ),
        (
            SurfaceSettings {
                light_direction: Some(DVec3::new(f64::INFINITY, 0.0, 0.0)),
                ..base
            },
            "light direction",
        ),
        (
            SurfaceSettings {
                camera: Camera {
                    view_point: Some(DVec3::ZERO),
                    ..Camera::default()
                },
                ..base
            },
            "camera: view point",
        ),
        (
            SurfaceSettings {
                camera: Camera {
                    view_point: Some(DVec3::new(0.0, 0.0, 5.0)),
                    ..Camera::default()
                },
                ..base
            },
            "parallel",
        ),
    ];
    for (settings, expect) in cases {
        let err = render(&surface, &settings).unwrap_err();
        let text = err.to_string();
        assert!(text.contains(expect), "{text:?} lacks {expect:?}");
        assert!(!text.contains('\n'), "{text:?}");
    }
    assert!(matches!(
        render(
            &surface,
            &SurfaceSettings {
                supersampling: 0,
                ..base
            }
        ),
        Err(SurfaceError::Supersampling(0))
    ));
}
