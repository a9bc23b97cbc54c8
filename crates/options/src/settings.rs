//! [`Options`] to volray-core's [`RenderSettings`]: the transfer function
//! put together from the transfer function, preset, colour map, window and
//! log options, the camera, the blend mode checked against the options
//! only compositing uses, Levoy's isovalue contour, and the rest as they
//! are; then checked by volray-core, so that a bad combination is refused
//! before any work. What depends on the volume itself (labels, the
//! automatic transfer function) is [`crate::volume`]'s.

use crate::error::OptionError;
use crate::option::Opt;
use crate::options::{BlendMode, CameraOptions, LookOptions, Options, Tf};
use volray_core::glam::DVec3;
use volray_core::transfer::{colormap, presets};
use volray_core::{
    Blend, Camera, Classification, ClipPlane, IsoSurface, Method, Phong, Projection,
    RenderSettings, TransferFunction,
};

/// The render settings `options` describe, checked.
pub fn settings(options: &Options) -> Result<RenderSettings, OptionError> {
    let Options {
        camera: cam,
        look,
        sampling,
    } = options;
    for (given, opt) in [
        (look.label_opacity.is_some(), Opt::LabelOpacity),
        (look.show_labels.is_some(), Opt::ShowLabels),
    ] {
        if given && !look.labels {
            return Err(OptionError::LabelsOnly(opt));
        }
    }
    let transfer_function = in_log_units(look, named_transfer_function(look)?)?;
    let settings = RenderSettings {
        width: cam.size.0,
        height: cam.size.1,
        camera: camera(cam),
        step: sampling.step,
        opacity_ramp: look
            .opacity
            .unwrap_or(RenderSettings::default().opacity_ramp),
        transfer_function,
        phong: Phong {
            ambient: look.ambient,
            diffuse: look.diffuse,
            specular: look.specular,
            shininess: look.shininess,
            light_color: look.light_color,
        },
        shading: look.shading,
        light_direction: look.light.map(DVec3::from),
        background: look.background,
        method: if sampling.reference {
            Method::Reference
        } else {
            Method::Fast
        },
        blend: blend(look)?,
        classification: if look.post_classification {
            Classification::Post
        } else {
            Classification::Pre
        },
        jitter: sampling.jitter,
        clip_planes: (cam.clip.iter())
            .map(|&(point, normal)| ClipPlane {
                point: DVec3::from(point),
                normal: DVec3::from(normal),
            })
            .collect(),
        crop: (cam.crop).map(|(lo, hi)| (DVec3::from(lo), DVec3::from(hi))),
        iso: iso(look)?,
        gradient_opacity: look.gradient_opacity,
        gradient_opacity_max: None,
        piece: None,
        shadows: look.shadows,
        ambient_occlusion: look.ambient_occlusion,
    };
    (settings.validate()).map_err(|e| OptionError::Invalid(e.into()))?;
    (settings.camera.validate()).map_err(|e| OptionError::Invalid(e.into()))?;
    Ok(settings)
}

/// The transfer function given ([`Tf::Json`] or [`Tf::Function`]) or the
/// preset (else the default), with the colour map's colours and the
/// window, each refused where it would replace what the transfer function
/// or a CT preset fixes; the window in the data's units, as given.
pub fn named_transfer_function(look: &LookOptions) -> Result<TransferFunction, OptionError> {
    let transfer_function = match &look.tf {
        Some(Tf::Json { source, text }) => {
            TransferFunction::from_json(text).map_err(|e| OptionError::TfJson {
                source: source.clone(),
                error: e.to_string(),
            })?
        }
        Some(Tf::Function(f)) => f.clone(),
        Some(Tf::Auto) | None => TransferFunction::default(),
    };
    let from = tf_source(look);
    let mut transfer_function = match &look.preset {
        Some(_) if look.tf.is_some() => return Err(OptionError::Conflict(Opt::Preset, Opt::Tf)),
        Some(name) => presets::preset(name).ok_or_else(|| OptionError::Unknown {
            opt: Opt::Preset,
            what: "preset",
            name: name.clone(),
            expected: &presets::NAMES,
        })?,
        None => transfer_function,
    };
    if look.opacity.is_some() && transfer_function.opacity.is_some() {
        return Err(OptionError::OpacityConflict { from });
    }
    if let Some(name) = &look.colormap {
        if look.tf_given() && transfer_function.color.is_some() {
            return Err(OptionError::ColormapConflict);
        }
        transfer_function.color =
            Some(
                colormap::colormap(name).ok_or_else(|| OptionError::Unknown {
                    opt: Opt::Colormap,
                    what: "colour map",
                    name: name.clone(),
                    expected: &colormap::NAMES,
                })?,
            );
    }
    if let Some(range) = look.range {
        if transfer_function.domain.is_some() {
            return Err(OptionError::RangeConflict { from });
        }
        transfer_function.domain = Some(range);
    }
    Ok(transfer_function)
}

/// The option a transfer function came from, for messages.
fn tf_source(look: &LookOptions) -> Opt {
    if look.tf.is_some() {
        Opt::Tf
    } else {
        Opt::Preset
    }
}

/// With the log option, the window of `transfer_function` converted from
/// the data's units to the log10 the renderer sees.
fn in_log_units(
    look: &LookOptions,
    mut transfer_function: TransferFunction,
) -> Result<TransferFunction, OptionError> {
    if look.log
        && let Some((lo, hi)) = transfer_function.domain
    {
        if lo <= 0.0 {
            let from = if look.range.is_some() {
                Opt::Range
            } else {
                tf_source(look)
            };
            return Err(OptionError::LogWindow { from, lo });
        }
        transfer_function.domain = Some((lo.log10(), hi.log10()));
    }
    Ok(transfer_function)
}

/// The camera of the camera options (their image size aside).
fn camera(cam: &CameraOptions) -> Camera {
    Camera {
        view_point: cam.view.map(DVec3::from),
        look_at: cam.look_at.map(DVec3::from),
        up: DVec3::from(cam.up),
        projection: match cam.perspective {
            Some(fov_degrees) => Projection::Perspective { fov_degrees },
            None => Projection::Orthographic,
        },
        zoom: cam.zoom,
        azimuth: cam.azimuth,
        elevation: cam.elevation,
        ..Camera::default()
    }
}

/// The blend mode, checked against the options that only compositing
/// uses: a projection shows the interpolated scalar, with no opacity to
/// shape and no lighting.
fn blend(look: &LookOptions) -> Result<Blend, OptionError> {
    let name = look.blend.name();
    let blend = match look.blend {
        BlendMode::Composite => Blend::Composite,
        BlendMode::Iso if look.iso.is_none() => return Err(OptionError::IsoNeedsValue),
        BlendMode::Iso => Blend::Composite,
        BlendMode::Mip => Blend::Maximum,
        BlendMode::Minip => Blend::Minimum,
        BlendMode::Average => Blend::Average,
    };
    if blend.is_projection() {
        for (given, opt) in [
            (look.iso.is_some(), Opt::Iso),
            (look.gradient_opacity.is_some(), Opt::GradientOpacity),
            (look.post_classification, Opt::PostClassification),
            (look.opacity.is_some(), Opt::Opacity),
        ] {
            if given {
                return Err(OptionError::NoOpacityInProjection { opt, blend: name });
            }
        }
    }
    let unlit = if blend.is_projection() {
        Some(Some(name))
    } else if !look.shading {
        Some(None)
    } else {
        None
    };
    if let (Some(projection), Some(opt)) = (unlit, lighting_option(look)) {
        return Err(OptionError::Unlit { opt, projection });
    }
    // Ambient occlusion dims the ambient light, which an unlit composite
    // has too (its colour); a projection has none.
    if blend.is_projection() && look.ambient_occlusion.is_some() {
        return Err(OptionError::Unlit {
            opt: Opt::AmbientOcclusion,
            projection: Some(name),
        });
    }
    Ok(blend)
}

/// The first lighting option given a value other than its default (the
/// library's), if any.
fn lighting_option(look: &LookOptions) -> Option<Opt> {
    let lit = Phong::default();
    [
        (look.ambient != lit.ambient, Opt::Ambient),
        (look.diffuse != lit.diffuse, Opt::Diffuse),
        (look.specular != lit.specular, Opt::Specular),
        (look.shininess != lit.shininess, Opt::Shininess),
        (look.light_color != lit.light_color, Opt::LightColor),
        (look.light.is_some(), Opt::Light),
        (look.shadows, Opt::Shadows),
    ]
    .into_iter()
    .find_map(|(given, opt)| given.then_some(opt))
}

/// The isovalue contour and its thickness; with the log option the value
/// is in the data's units, like the window.
fn iso(look: &LookOptions) -> Result<Option<IsoSurface>, OptionError> {
    let Some(value) = look.iso else {
        return match look.iso_thickness {
            Some(_) => Err(OptionError::IsoThicknessAlone),
            None => Ok(None),
        };
    };
    let value = if look.log {
        if value <= 0.0 {
            return Err(OptionError::IsoLog { value });
        }
        (value as f64).log10() as f32
    } else {
        value
    };
    Ok(Some(IsoSurface {
        value,
        thickness: look.iso_thickness.unwrap_or(1.0),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_options_give_the_library_defaults() {
        assert_eq!(
            settings(&Options::default()).unwrap(),
            RenderSettings::default()
        );
    }

    #[test]
    fn the_log_of_the_data_moves_the_window_and_the_isovalue() {
        let mut options = Options::default();
        options.look.log = true;
        options.look.range = Some((1.0, 1000.0));
        options.look.iso = Some(100.0);
        let s = settings(&options).unwrap();
        assert_eq!(s.transfer_function.domain, Some((0.0, 3.0)));
        assert_eq!(s.iso.map(|i| i.value), Some(2.0));
        options.look.range = Some((0.0, 1.0));
        assert_eq!(
            settings(&options),
            Err(OptionError::LogWindow {
                from: Opt::Range,
                lo: 0.0
            })
        );
    }

    #[test]
    fn projections_refuse_opacity_and_lighting_options() {
        let mut options = Options::default();
        options.look.blend = BlendMode::Mip;
        options.look.opacity = Some((0.0, 1.0));
        assert_eq!(
            settings(&options),
            Err(OptionError::NoOpacityInProjection {
                opt: Opt::Opacity,
                blend: "mip"
            })
        );
        options.look.opacity = None;
        options.look.shininess = 20.0;
        assert_eq!(
            settings(&options),
            Err(OptionError::Unlit {
                opt: Opt::Shininess,
                projection: Some("mip")
            })
        );
    }

    #[test]
    fn a_preset_and_a_transfer_function_conflict() {
        let mut options = Options::default();
        options.look.preset = Some("ct-bone".into());
        options.look.tf = Some(Tf::Auto);
        assert_eq!(
            settings(&options),
            Err(OptionError::Conflict(Opt::Preset, Opt::Tf))
        );
        options.look.tf = None;
        options.look.range = Some((0.0, 1.0));
        assert_eq!(
            settings(&options),
            Err(OptionError::RangeConflict { from: Opt::Preset })
        );
    }
}
