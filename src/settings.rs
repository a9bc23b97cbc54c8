//! The render settings the flags describe: the transfer function put
//! together from `--tf`, `--preset`, `--colormap`, `--range` and `--log`,
//! the camera, `--blend` checked against the options only compositing
//! uses, Levoy's `--iso` contour, and the rest as they are; then checked
//! by volray-core, so that a bad combination is refused before any work.

use crate::error::CliError;
use crate::flags::{BlendMode, CameraArgs, LookArgs, ViewArgs};
use std::path::Path;
use volray_core::glam::DVec3;
use volray_core::transfer::{auto, colormap, labels, presets};
use volray_core::{
    Blend, Camera, Classification, ClipPlane, Histogram, IsoSurface, Method, Phong, Projection,
    RenderSettings, TransferFunction, Volume,
};

/// The render settings the view arguments describe (reading `--tf`).
pub fn settings(view: &ViewArgs) -> Result<RenderSettings, CliError> {
    let tf_text = view.look.tf_file().map(read_tf_file).transpose()?;
    settings_with_tf_text(view, tf_text.as_deref())
}

/// The render settings the view arguments describe, with the text of the
/// `--tf` file given rather than read: [`settings`] reads it, `volray
/// view` writes the file its Command box names. `tf_text` is used only
/// when `--tf` is given.
pub fn settings_with_tf_text(
    view: &ViewArgs,
    tf_text: Option<&str>,
) -> Result<RenderSettings, CliError> {
    let ViewArgs {
        camera: cam,
        look,
        sampling,
        threads: _,
    } = view;
    for (given, flag) in [
        (look.label_opacity.is_some(), "--label-opacity"),
        (look.show_labels.is_some(), "--show-labels"),
    ] {
        if given && !look.labels {
            return Err(CliError::input(format!(
                "{flag} applies to label volumes: give --labels"
            )));
        }
    }
    let transfer_function = in_log_units(look, named_transfer_function(look, tf_text)?)?;
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
        shading: !look.no_shading,
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
    };
    settings
        .validate()
        .map_err(|e| CliError::input(e.to_string()))?;
    settings
        .camera
        .validate()
        .map_err(|e| CliError::input(e.to_string()))?;
    Ok(settings)
}

/// The transfer function of `--tf` (its file's text `tf_text`) or
/// `--preset` (else the default), with `--colormap`'s colours and
/// `--range`'s window, each refused where it would replace what `--tf` or
/// a CT preset fixes; the window in the data's units, as the flags give it.
pub fn named_transfer_function(
    look: &LookArgs,
    tf_text: Option<&str>,
) -> Result<TransferFunction, CliError> {
    let transfer_function = match (look.tf_file(), tf_text) {
        (Some(path), Some(text)) => TransferFunction::from_json(text)
            .map_err(|e| CliError::input(format!("--tf {}: {e}", path.display())))?,
        (Some(path), None) => {
            return Err(CliError::io(format!(
                "--tf {}: the file was not read",
                path.display()
            )));
        }
        (None, _) => TransferFunction::default(),
    };
    let from = tf_source(look);
    let mut transfer_function = match &look.preset {
        Some(_) if look.tf.is_some() => {
            return Err(CliError::input(
                "--preset conflicts with --tf: give one of them",
            ));
        }
        Some(name) => presets::preset(name).ok_or_else(|| {
            CliError::input(format!(
                "--preset: unknown preset '{name}': expected one of {}",
                presets::NAMES.join(", ")
            ))
        })?,
        None => transfer_function,
    };
    if look.opacity.is_some() && transfer_function.opacity.is_some() {
        return Err(CliError::input(format!(
            "--opacity conflicts with the opacity function in {from}: give one of them"
        )));
    }
    if let Some(name) = &look.colormap {
        if look.tf_file().is_some() && transfer_function.color.is_some() {
            return Err(CliError::input(
                "--colormap conflicts with the colour function in --tf: give one of them",
            ));
        }
        transfer_function.color = Some(colormap::colormap(name).ok_or_else(|| {
            CliError::input(format!(
                "--colormap: unknown colour map '{name}': expected one of {}",
                colormap::NAMES.join(", ")
            ))
        })?);
    }
    if let Some(range) = look.range {
        if transfer_function.domain.is_some() {
            return Err(CliError::input(format!(
                "--range conflicts with the value domain fixed by {from}: give one of them"
            )));
        }
        transfer_function.domain = Some(range);
    }
    Ok(transfer_function)
}

/// What the flags leave to the volume `name`: with `--labels`, the volume
/// marked as labels (volray-core's [`labels`]) and, unless `--tf` names a
/// file, the labels' transfer function; else, where
/// [`LookArgs::auto_tf`] says so, the transfer function chosen from its
/// histogram ([`choose_auto`]).
pub fn from_volume(
    look: &LookArgs,
    transfer_function: &mut TransferFunction,
    volume: &mut Volume,
    name: &str,
) -> Result<(), CliError> {
    if !look.labels {
        choose_auto(look, transfer_function, volume);
        return Ok(());
    }
    let found = volume_labels(volume, name)?;
    volume.set_labels(true);
    label_transfer_function(look, transfer_function, &found, name)
}

/// The labels of `volume` (`name`), refused as `--labels` would be.
pub fn volume_labels(volume: &Volume, name: &str) -> Result<Vec<i64>, CliError> {
    labels::labels_of(volume, labels::MAX_LABELS)
        .map_err(|e| CliError::input(format!("{name}: --labels: {e}")))?
        .ok_or_else(|| {
            CliError::input(format!(
                "{name}: --labels: more than {} distinct values: not a label volume",
                labels::MAX_LABELS
            ))
        })
}

/// With `--labels`, the transfer function of `found` (the labels of the
/// volume or volumes `name`) as `--label-opacity` and `--show-labels` say,
/// unless `--tf` names a file, which then gives it.
pub fn label_transfer_function(
    look: &LookArgs,
    transfer_function: &mut TransferFunction,
    found: &[i64],
    name: &str,
) -> Result<(), CliError> {
    let styled = look.label_opacity.is_some() || look.show_labels.is_some();
    match look.tf.as_deref() {
        Some(_) if look.tf_file().is_none() => Err(CliError::input(
            "--tf auto conflicts with --labels, which gives each label its colour: give one of them",
        )),
        Some(_) if styled => Err(CliError::input(
            "--label-opacity and --show-labels shape the colours --labels gives; --tf replaces them: give one of them",
        )),
        Some(_) => Ok(()),
        None if look.range.is_some() => Err(CliError::input(
            "--range conflicts with --labels, whose window spans the labels: give one of them",
        )),
        None => {
            let style = labels::LabelStyle {
                opacity: look.label_opacity.clone().map(|l| l.0).unwrap_or_default(),
                shown: look.show_labels.clone().map(|l| l.0),
            };
            *transfer_function = labels::transfer_function(found, &style).map_err(|e| {
                let flag = match e {
                    labels::LabelError::Absent(..) => "--label-opacity / --show-labels",
                    _ => "--labels",
                };
                CliError::input(format!("{name}: {flag}: {e}"))
            })?;
            Ok(())
        }
    }
}

/// Where [`LookArgs::auto_tf`] says so, the transfer function chosen from
/// `volume`'s histogram (volray-core's [`auto`]) over `transfer_function`'s
/// window: its opacity unless `--opacity` gives the paper's ramp, its
/// colours unless `--colormap` names them. `volume` is what the renderer
/// sees (with `--log`, the log10 of the data), and the window is in its
/// units, as [`settings`] leaves it.
pub fn choose_auto(look: &LookArgs, transfer_function: &mut TransferFunction, volume: &Volume) {
    if !look.auto_tf() {
        return;
    }
    // A volume with no finite value is refused later, by the renderer.
    if let Some(histogram) = Histogram::of(volume, auto::BINS) {
        apply_auto(look, transfer_function, &histogram);
    }
}

/// The transfer function chosen from values whose statistics are
/// `histogram`, put into `transfer_function` as [`choose_auto`] says (a
/// series chooses from its first volume's histogram).
pub fn apply_auto(
    look: &LookArgs,
    transfer_function: &mut TransferFunction,
    histogram: &Histogram,
) {
    let chosen = auto::transfer_function(histogram, transfer_function.domain);
    if look.opacity.is_none() {
        transfer_function.opacity = chosen.opacity;
    }
    if transfer_function.color.is_none() {
        transfer_function.color = chosen.color;
    }
}

/// The flag a transfer function came from, for messages.
fn tf_source(look: &LookArgs) -> &'static str {
    if look.tf.is_some() {
        "--tf"
    } else {
        "--preset"
    }
}

/// With `--log`, the window of `transfer_function` converted from the
/// data's units to the log10 the renderer sees.
fn in_log_units(
    look: &LookArgs,
    mut transfer_function: TransferFunction,
) -> Result<TransferFunction, CliError> {
    let from = tf_source(look);
    if look.log
        && let Some((lo, hi)) = transfer_function.domain
    {
        // The window is given in the data's units; the renderer sees log10.
        let from = if look.range.is_some() {
            "--range"
        } else {
            from
        };
        if lo <= 0.0 {
            return Err(CliError::input(format!(
                "{from}: with --log the value window is in the data's own units and must be positive, but LO is {lo}"
            )));
        }
        transfer_function.domain = Some((lo.log10(), hi.log10()));
    }
    Ok(transfer_function)
}

/// The largest `--tf` file read: a transfer function is a few hundred
/// points; this bounds what a wrong path (a device, a huge file) costs.
const TF_MAX_BYTES: u64 = 16 << 20;

/// Reads a `--tf` file: a regular file of at most [`TF_MAX_BYTES`].
pub fn read_tf_file(path: &Path) -> Result<String, CliError> {
    use std::io::Read;
    let name = path.display();
    let meta = std::fs::metadata(path)
        .map_err(|e| CliError::io(format!("--tf {name}: cannot read: {e}")))?;
    if !meta.is_file() {
        return Err(CliError::input(format!("--tf {name}: not a regular file")));
    }
    if meta.len() > TF_MAX_BYTES {
        return Err(CliError::input(format!(
            "--tf {name}: {} bytes is too large for a transfer function (at most {TF_MAX_BYTES})",
            meta.len()
        )));
    }
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(TF_MAX_BYTES).read_to_string(&mut text))
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::InvalidData => CliError::input(format!(
                "--tf {name}: not UTF-8 text (a JSON file is expected)"
            )),
            _ => CliError::io(format!("--tf {name}: cannot read: {e}")),
        })?;
    Ok(text)
}

/// The camera of the camera options (their image size aside).
fn camera(cam: &CameraArgs) -> Camera {
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

/// `--blend`, checked against the options that only compositing uses:
/// a projection shows the interpolated scalar, with no opacity to shape
/// and no lighting.
fn blend(look: &LookArgs) -> Result<Blend, CliError> {
    let (blend, name) = match look.blend {
        BlendMode::Composite => (Blend::Composite, "composite"),
        BlendMode::Iso if look.iso.is_none() => {
            return Err(CliError::input(
                "--blend iso needs the isovalue: give --iso VALUE",
            ));
        }
        BlendMode::Iso => (Blend::Composite, "iso"),
        BlendMode::Mip => (Blend::Maximum, "mip"),
        BlendMode::Minip => (Blend::Minimum, "minip"),
        BlendMode::Average => (Blend::Average, "average"),
    };
    if blend.is_projection() {
        for (given, flag) in [
            (look.iso.is_some(), "--iso"),
            (look.gradient_opacity.is_some(), "--gradient-opacity"),
            (look.post_classification, "--post-classification"),
            (look.opacity.is_some(), "--opacity"),
        ] {
            if given {
                return Err(CliError::input(format!(
                    "{flag} shapes the opacity of --blend composite; --blend {name} projects the interpolated value and has none"
                )));
            }
        }
    }
    let unlit = if blend.is_projection() {
        Some(format!("--blend {name} is unshaded"))
    } else if look.no_shading {
        Some("--no-shading turns the lighting off".to_string())
    } else {
        None
    };
    if let (Some(why), Some(flag)) = (unlit, lighting_flag(look)) {
        return Err(CliError::input(format!(
            "{flag} sets the lighting, but {why}: leave {flag} out"
        )));
    }
    Ok(blend)
}

/// The first lighting option given a value other than its default (the
/// library's, which `--help` shows), if any.
fn lighting_flag(look: &LookArgs) -> Option<&'static str> {
    let lit = Phong::default();
    [
        (look.ambient != lit.ambient, "--ambient"),
        (look.diffuse != lit.diffuse, "--diffuse"),
        (look.specular != lit.specular, "--specular"),
        (look.shininess != lit.shininess, "--shininess"),
        (look.light_color != lit.light_color, "--light-color"),
        (look.light.is_some(), "--light"),
    ]
    .into_iter()
    .find_map(|(given, flag)| given.then_some(flag))
}

/// `--iso VALUE --iso-thickness R`; with `--log` the value is in the data's
/// units, like `--range`.
fn iso(look: &LookArgs) -> Result<Option<IsoSurface>, CliError> {
    let Some(value) = look.iso else {
        return match look.iso_thickness {
            Some(_) => Err(CliError::input(
                "--iso-thickness is the half-width of the --iso shell: give --iso VALUE too",
            )),
            None => Ok(None),
        };
    };
    let value = if look.log {
        if value <= 0.0 {
            return Err(CliError::input(format!(
                "--iso: with --log the isovalue is in the data's own units and must be positive, but it is {value}"
            )));
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
    use crate::flags::{Cli, Command, RenderArgs};
    use clap::Parser;

    #[test]
    fn command_line_defaults_are_the_library_defaults() {
        // The defaults are written twice, for `--help` and in volray-core:
        // they must say the same.
        let cli = Cli::try_parse_from(["volray", "render", "-o", "x.png"]).unwrap();
        let Command::Render(args) = cli.command else {
            panic!("not a render command")
        };
        assert_eq!(settings(&args.view).unwrap(), RenderSettings::default());
    }

    fn parse(args: &[&str]) -> RenderArgs {
        let all = [&["volray", "render", "-o", "x.png"][..], args].concat();
        match Cli::try_parse_from(all).unwrap().command {
            Command::Render(args) => args,
            _ => panic!("not a render command"),
        }
    }

    #[test]
    fn options_reach_the_settings() {
        let args = parse(&[
            "--perspective",
            "40",
            "--zoom",
            "2",
            "--azimuth",
            "-30",
            "--elevation",
            "15",
            "--clip",
            "1,2,3,0,0,-2",
            "--crop",
            "-1,1,-2,2,-3,3",
            "--jitter",
            "--iso",
            "100",
            "--iso-thickness",
            "2",
            "--log",
            "--range",
            "1,1000",
            "--gradient-opacity",
            "0.1,0.9",
        ]);
        let s = settings(&args.view).unwrap();
        assert_eq!(
            s.camera.projection,
            Projection::Perspective { fov_degrees: 40.0 }
        );
        assert_eq!(
            (s.camera.zoom, s.camera.azimuth, s.camera.elevation),
            (2.0, -30.0, 15.0)
        );
        assert_eq!(
            s.clip_planes,
            [ClipPlane {
                point: DVec3::new(1.0, 2.0, 3.0),
                normal: DVec3::new(0.0, 0.0, -2.0)
            }]
        );
        assert_eq!(
            s.crop,
            Some((DVec3::new(-1.0, -2.0, -3.0), DVec3::new(1.0, 2.0, 3.0)))
        );
        assert!(s.jitter);
        // --log: the window and the isovalue were given in the data's units.
        assert_eq!(s.transfer_function.domain, Some((0.0, 3.0)));
        assert_eq!(
            s.iso,
            Some(IsoSurface {
                value: 2.0,
                thickness: 2.0
            })
        );
        assert_eq!(s.gradient_opacity, Some((0.1, 0.9)));
        assert_eq!(s.blend, Blend::Composite);
        let mip = parse(&["--blend", "minimum"]);
        assert_eq!(settings(&mip.view).unwrap().blend, Blend::Minimum);
    }
}
