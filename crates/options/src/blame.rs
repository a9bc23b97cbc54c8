//! Which option a render error is about: volray-core's errors say which
//! setting or camera quantity, by variant, and the options say whether
//! the user gave it (a default point of the camera is the volume's
//! bounds' fault, not an option's).

use crate::option::Opt;
use crate::options::CameraOptions;
use volray_core::camera::CameraError;
use volray_core::{CameraPoint, Orbit, Reflection, RenderError, SettingError as S};

/// The option whose value caused `e`, if one did; `camera` tells which
/// camera options were given.
pub fn option_of(e: &RenderError, camera: &CameraOptions) -> Option<Opt> {
    let opt = match e {
        RenderError::NonFinite { .. } => Opt::NonFinite,
        RenderError::SamplesChanged(_) | RenderError::Stopped => return None,
        // A scene's volume: its own error's option.
        RenderError::Scene(volray_core::SceneError::Layer { error, .. }) => {
            return option_of(error, camera);
        }
        RenderError::Scene(_) => return None,
        RenderError::Camera(c) => match c {
            CameraError::NoDirection(_) if camera.view.is_some() => Opt::View,
            CameraError::NoDirection(_) => Opt::LookAt,
            CameraError::UpParallel { .. } => Opt::Up,
            CameraError::NotFinite(CameraPoint::ViewPoint, _) if camera.view.is_some() => Opt::View,
            CameraError::NotFinite(CameraPoint::ViewReference, _) if camera.look_at.is_some() => {
                Opt::LookAt
            }
            CameraError::NotFinite(CameraPoint::Up, _) => Opt::Up,
            // A default point beyond f64: the volume's bounds are to blame.
            CameraError::NotFinite(..) => return None,
            CameraError::FieldOfView(_) => Opt::Perspective,
            CameraError::Zoom(_) => Opt::Zoom,
            CameraError::Angle(Orbit::Azimuth, _) => Opt::Azimuth,
            CameraError::Angle(Orbit::Elevation, _) => Opt::Elevation,
            CameraError::EmptyImage { .. } => Opt::Size,
            CameraError::Bounds { .. } | CameraError::WrongProjection { .. } => return None,
        },
        RenderError::Setting(s) => match s {
            S::ImageSide { .. } | S::ImagePixels { .. } => Opt::Size,
            S::Step(_) | S::StepTooSmall { .. } => Opt::Step,
            S::OpacityRamp { .. } => Opt::Opacity,
            S::Reflection { term, .. } => match term {
                Reflection::Ambient => Opt::Ambient,
                Reflection::Diffuse => Opt::Diffuse,
                Reflection::Specular => Opt::Specular,
                Reflection::LightColor => Opt::LightColor,
            },
            S::Shininess(_) => Opt::Shininess,
            S::Background(_) => Opt::Background,
            S::LightDirection(_) => Opt::Light,
            S::Shadows(_) => Opt::Shadows,
            S::AmbientOcclusion(_) | S::AmbientOcclusionRadius(_) => Opt::AmbientOcclusion,
            S::Crop { .. } => Opt::Crop,
            S::ClipPoint(_) | S::ClipNormal(_) => Opt::Clip,
            S::IsoValue(_) => Opt::Iso,
            S::IsoThickness(_) => Opt::IsoThickness,
            S::GradientOpacity { .. } => Opt::GradientOpacity,
            // Set by a series from its volumes, not by an option.
            S::GradientOpacityMax(_) => return None,
            // Set by a distributed render for each rank, not by an option.
            S::Piece(_) => return None,
        },
    };
    Some(opt)
}
