//! What the tests of pieces share: a volume of three blobs on an
//! anisotropic, offset grid, and the frames they render it with (every
//! projection, blend mode, classification, crop, clip plane and the
//! gradient-scaled transfer functions).

#![allow(dead_code)]

use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::{
    Blend, Classification, ClipPlane, IsoSurface, RenderSettings, TransferFunction, Volume,
};

/// Three Gaussian blobs on an anisotropic, offset grid.
pub fn volume() -> Volume {
    let centres = [
        (DVec3::new(8.0, 10.0, 7.0), 4.0),
        (DVec3::new(20.0, 14.0, 12.0), 5.0),
        (DVec3::new(14.0, 22.0, 16.0), 3.5),
    ];
    Volume::from_fn(
        [29, 27, 23],
        DVec3::new(1.0, 1.1, 0.9),
        DVec3::new(-2.0, 1.0, 0.5),
        |p| {
            (centres.iter())
                .map(|(c, r)| (-(p - *c).length_squared() / (2.0 * r * r)).exp() as f32)
                .sum()
        },
    )
    .unwrap()
}

pub fn colorful() -> TransferFunction {
    TransferFunction::from_json(
        r#"{"opacity": [[0, 0], [0.1, 0], [0.6, 0.4], [1, 0.9]],
            "color": [[0, 0.23, 0.299, 0.754], [0.5, 0.865, 0.865, 0.865], [1, 0.706, 0.016, 0.15]]}"#,
    )
    .unwrap()
}

pub fn cases() -> Vec<(String, RenderSettings)> {
    let base = RenderSettings {
        width: 64,
        height: 56,
        transfer_function: colorful(),
        background: [0.1, 0.1, 0.2],
        ..RenderSettings::default()
    };
    let cameras = [
        (
            "orthographic",
            Camera {
                azimuth: 30.0,
                elevation: 25.0,
                ..Camera::default()
            },
        ),
        (
            "perspective",
            Camera {
                projection: Projection::Perspective { fov_degrees: 40.0 },
                azimuth: -50.0,
                elevation: -15.0,
                ..Camera::default()
            },
        ),
        (
            "perspective from inside",
            Camera {
                projection: Projection::Perspective { fov_degrees: 75.0 },
                view_point: Some(DVec3::new(12.5, 14.0, 10.0)),
                look_at: Some(DVec3::new(25.0, 20.0, 14.0)),
                ..Camera::default()
            },
        ),
    ];
    let mut out = Vec::new();
    for (name, camera) in cameras {
        let s = RenderSettings {
            camera,
            ..base.clone()
        };
        out.push((format!("{name}, composite"), s.clone()));
        out.push((
            format!("{name}, post-classified"),
            RenderSettings {
                classification: Classification::Post,
                ..s.clone()
            },
        ));
        for blend in [Blend::Maximum, Blend::Minimum, Blend::Average] {
            out.push((
                format!("{name}, {blend:?}"),
                RenderSettings { blend, ..s.clone() },
            ));
        }
    }
    let s = RenderSettings {
        camera: Camera {
            azimuth: 110.0,
            elevation: 40.0,
            ..Camera::default()
        },
        ..base.clone()
    };
    out.push((
        "cropped, clipped, unshaded, half steps".into(),
        RenderSettings {
            crop: Some((DVec3::new(0.0, 3.0, 2.0), DVec3::new(22.0, 30.0, 18.0))),
            clip_planes: vec![ClipPlane {
                point: DVec3::new(12.0, 14.0, 10.0),
                normal: DVec3::new(1.0, -0.4, 0.3),
            }],
            shading: false,
            step: 0.5,
            ..s.clone()
        },
    ));
    out.push((
        "iso-surface and gradient opacity, jittered".into(),
        RenderSettings {
            iso: Some(IsoSurface {
                value: 0.5,
                thickness: 1.5,
            }),
            gradient_opacity: Some((0.0, 0.5)),
            jitter: true,
            ..s
        },
    ));
    out
}
