//! Volumes keep their samples' type (`u8`, `i8`, `u16`, `i16`, `f32`), and
//! every path reads a sample as the `f32` it converts to exactly: a volume
//! of any type renders exactly as its `f32` conversion, bit for bit, on
//! every path and option.

mod common;

use common::colorful;
use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::{
    Blend, Classification, IsoSurface, Method, NonFinite, RenderSettings, Renderer, SampleType,
    Samples, Volume,
};
use volray_core::{FrameRequest, Render};

/// A smooth field with structure at every scale, as `T` values over
/// `[lo, hi]` (rounded to whole numbers).
fn field<T>(dims: [usize; 3], lo: f64, hi: f64, convert: impl Fn(f64) -> T) -> Vec<T> {
    let [nx, ny, nz] = dims;
    let mut out = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let u = [i, j, k].map(|c| c as f64 / 12.0);
                let blob = (-((u[0] - 1.2).powi(2) + (u[1] - 1.0).powi(2) + (u[2] - 0.9).powi(2))
                    / 0.3)
                    .exp();
                let ripple = 0.15 * (3.0 * u[0]).sin() * (2.0 * u[1]).cos();
                let t = (blob + ripple).clamp(0.0, 1.0);
                out.push(convert((lo + t * (hi - lo)).round()));
            }
        }
    }
    out
}

fn settings_to_try() -> Vec<(&'static str, RenderSettings)> {
    let base = RenderSettings {
        width: 40,
        height: 36,
        transfer_function: colorful(),
        ..RenderSettings::default()
    };
    let oblique = Camera {
        azimuth: 30.0,
        elevation: 20.0,
        ..Camera::default()
    };
    vec![
        ("fast, pre-classified", base.clone()),
        (
            "fast, oblique perspective",
            RenderSettings {
                camera: Camera {
                    projection: Projection::Perspective { fov_degrees: 40.0 },
                    ..oblique
                },
                ..base.clone()
            },
        ),
        (
            "fast, post-classified",
            RenderSettings {
                classification: Classification::Post,
                camera: oblique,
                ..base.clone()
            },
        ),
        (
            "fast, iso-surface",
            RenderSettings {
                iso: Some(IsoSurface {
                    value: 0.0,
                    thickness: 1.5,
                }),
                ..base.clone()
            },
        ),
        (
            "fast, gradient opacity",
            RenderSettings {
                gradient_opacity: Some((0.1, 0.6)),
                step: 0.5,
                ..base.clone()
            },
        ),
        (
            "fast, maximum",
            RenderSettings {
                blend: Blend::Maximum,
                ..base.clone()
            },
        ),
        (
            "fast, average",
            RenderSettings {
                blend: Blend::Average,
                camera: oblique,
                ..base.clone()
            },
        ),
        (
            "reference, pre-classified",
            RenderSettings {
                method: Method::Reference,
                ..base.clone()
            },
        ),
        (
            "reference, minimum",
            RenderSettings {
                method: Method::Reference,
                blend: Blend::Minimum,
                ..base
            },
        ),
    ]
}

/// Renders `typed` and its `f32` conversion with every setting; they must
/// be the same images, bit for bit.
fn assert_renders_as_f32(typed: Volume, what: &str) {
    let converted = typed.to_f32();
    assert_eq!(converted.sample_type(), SampleType::F32);
    assert_eq!(*converted.values(), *typed.values());
    let (a, b) = (
        Renderer::new(&typed).unwrap(),
        Renderer::new(&converted).unwrap(),
    );
    assert_eq!(a.value_range(), b.value_range());
    for (name, settings) in settings_to_try() {
        // The iso-surface half way up the value range.
        let (lo, hi) = a.value_range();
        let settings = RenderSettings {
            iso: settings.iso.map(|iso| IsoSurface {
                value: 0.5 * (lo + hi),
                ..iso
            }),
            ..settings
        };
        let (x, y) = (
            a.render(FrameRequest::new(&settings)).unwrap().image(),
            b.render(FrameRequest::new(&settings)).unwrap().image(),
        );
        assert!(x == y, "{what}, {name}: differs from its f32 conversion");
        assert!(
            x.pixels().iter().any(|p| p[3] > 0.3),
            "{what}, {name}: empty"
        );
    }
}

#[test]
fn every_sample_type_renders_exactly_as_its_f32_conversion() {
    let dims = [26, 23, 21];
    let spacing = DVec3::new(1.0, 0.8, 1.2);
    let volumes: Vec<(&str, Samples, (f64, f64))> = vec![
        (
            "u8",
            field(dims, 0.0, 255.0, |v| v as u8).into(),
            (0.0, 255.0),
        ),
        (
            "i8",
            field(dims, -128.0, 127.0, |v| v as i8).into(),
            (-128.0, 127.0),
        ),
        (
            "u16",
            field(dims, 100.0, 65000.0, |v| v as u16).into(),
            (100.0, 65000.0),
        ),
        (
            "i16",
            field(dims, -1024.0, 3071.0, |v| v as i16).into(),
            (-1024.0, 3071.0),
        ),
        (
            "f32",
            field(dims, -2.5, 7.0, |v| v as f32).into(),
            (-2.5, 7.0),
        ),
    ];
    for (what, samples, (lo, hi)) in volumes {
        let volume = Volume::from_samples(dims, samples)
            .unwrap()
            .with_spacing(spacing)
            .unwrap();
        assert_eq!(volume.sample_type().name(), what);
        // Read back as the values the field was made of.
        assert_eq!(
            *volume.values(),
            field(dims, lo, hi, |v| v as f32),
            "{what}"
        );
        assert_renders_as_f32(volume, what);
    }
}

#[test]
fn a_sixteen_bit_volume_takes_two_bytes_a_voxel_and_has_no_non_finite_values() {
    let dims = [30, 20, 10];
    let volume = Volume::from_samples(dims, field(dims, 0.0, 4000.0, |v| v as u16)).unwrap();
    assert_eq!(volume.sample_type().bytes(), 2);
    assert_eq!(volume.count_non_finite(), 0);
    // Nothing to clean: the renderer uses the volume as it is.
    let renderer = Renderer::with_non_finite(&volume, NonFinite::Transparent).unwrap();
    assert!(renderer.non_finite().is_none());
    assert_eq!(renderer.volume().sample_type(), SampleType::U16);
    assert_eq!(volume.get(29, 19, 9), volume.values()[volume.len() - 1]);
}
