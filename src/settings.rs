//! The render settings the flags describe: the flags read into
//! volray-options' [`Options`] (the `--tf` file's text with them), which
//! checks them together and builds volray-core's settings, as it does for
//! Python and the viewer; its errors worded with the flags ([`Flags`]).

use crate::error::CliError;
use crate::flags::{BlendMode, CameraArgs, LookArgs, RenderArgs, SamplingArgs, ViewArgs};
use std::path::Path;
use volray_core::{RenderSettings, TransferFunction, Volume};
use volray_options::{CameraOptions, LookOptions, Naming, Opt, OptionError, Options, Tf};

/// How the command line writes an option: `--look-at`, `--no-shading`,
/// `--blend mip`.
pub struct Flags;

impl Naming for Flags {
    fn option(&self, opt: Opt) -> String {
        format!("--{}", opt.name())
    }

    fn with_value(&self, opt: Opt, value: &str) -> String {
        format!("--{} {value}", opt.name())
    }
}

/// An option error as one line naming the flags: bad input, exit 1.
pub fn refused(e: OptionError) -> CliError {
    CliError::input(e.message(&Flags))
}

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
    volray_options::settings(&options(view, tf_text)?).map_err(refused)
}

/// The options the view arguments give, in volray-options' terms, with
/// the text of the `--tf` file.
pub fn options(view: &ViewArgs, tf_text: Option<&str>) -> Result<Options, CliError> {
    let mut look = look(&view.look);
    if let (Some(path), Some(Tf::Json { text, .. })) = (view.look.tf_file(), &mut look.tf) {
        *text = tf_text
            .ok_or_else(|| CliError::io(format!("--tf {}: the file was not read", path.display())))?
            .to_string();
    }
    Ok(Options {
        camera: camera(&view.camera),
        look,
        sampling: sampling(&view.sampling),
    })
}

/// The camera flags as options.
pub fn camera(cam: &CameraArgs) -> CameraOptions {
    CameraOptions {
        size: cam.size(),
        view: cam.view,
        look_at: cam.look_at,
        up: cam.up,
        perspective: cam.perspective,
        zoom: cam.zoom,
        azimuth: cam.azimuth,
        elevation: cam.elevation,
        clip: cam.clip.clone(),
        crop: cam.crop,
    }
}

/// The sampling flags as options.
pub fn sampling(sampling: &SamplingArgs) -> volray_options::SamplingOptions {
    volray_options::SamplingOptions {
        step: sampling.step,
        reference: sampling.reference,
        jitter: sampling.jitter,
        nonfinite: sampling.nonfinite.into(),
    }
}

/// The look flags as options. A `--tf` file's text is left empty here:
/// only [`options`] reads it into the settings; what follows the volume
/// ([`from_volume`]) asks only whether one is given.
pub fn look(look: &LookArgs) -> LookOptions {
    LookOptions {
        opacity: look.opacity,
        tf: look.tf.as_ref().map(|path| match look.tf_file() {
            None => Tf::Auto,
            Some(_) => Tf::Json {
                source: path.display().to_string(),
                text: String::new(),
            },
        }),
        preset: look.preset.clone(),
        colormap: look.colormap.clone(),
        labels: look.labels,
        label_opacity: look.label_opacity.clone().map(|l| l.0),
        show_labels: look.show_labels.clone().map(|l| l.0),
        label_colours: Vec::new(),
        range: look.range,
        ambient: look.ambient,
        diffuse: look.diffuse,
        specular: look.specular,
        shininess: look.shininess,
        light: look.light,
        light_color: look.light_color,
        shadows: look.shadows,
        ambient_occlusion: look.ambient_occlusion,
        shading: !look.no_shading,
        background: look.background,
        blend: match look.blend {
            BlendMode::Composite => volray_options::BlendMode::Composite,
            BlendMode::Mip => volray_options::BlendMode::Mip,
            BlendMode::Minip => volray_options::BlendMode::Minip,
            BlendMode::Average => volray_options::BlendMode::Average,
            BlendMode::Iso => volray_options::BlendMode::Iso,
        },
        iso: look.iso,
        iso_thickness: look.iso_thickness,
        log: look.log,
        linear: look.linear,
        gradient_opacity: look.gradient_opacity,
        post_classification: look.post_classification,
    }
}

/// The transfer function of `--tf` (its file's text `tf_text`) or
/// `--preset` (else the default), with `--colormap`'s colours and
/// `--range`'s window (volray-options' `named_transfer_function`).
pub fn named_transfer_function(
    look_args: &LookArgs,
    tf_text: Option<&str>,
) -> Result<TransferFunction, CliError> {
    let mut look = look(look_args);
    if let Some(Tf::Json { text, .. }) = &mut look.tf {
        *text = tf_text.unwrap_or_default().to_string();
    }
    volray_options::named_transfer_function(&look).map_err(refused)
}

/// What the flags leave to the volume `name`: `--labels`, or the transfer
/// function chosen from its histogram (volray-options' `from_volume`).
pub fn from_volume(
    look_args: &LookArgs,
    transfer_function: &mut TransferFunction,
    volume: &mut Volume,
    name: &str,
) -> Result<(), CliError> {
    volray_options::from_volume(&look(look_args), transfer_function, volume, name).map_err(refused)
}

/// `settings` with what the flags leave to `input`'s volume (volray-app's
/// `look`): the file's display window as the default `--range`, then
/// `--labels` or the transfer function chosen from it (`--tf auto`), the
/// volume marked as labels.
pub fn from_input(
    args: &RenderArgs,
    settings: &RenderSettings,
    input: &mut volray_app::input::Input,
) -> Result<RenderSettings, CliError> {
    let mut settings = settings.clone();
    let tf = &mut settings.transfer_function;
    volray_app::look::leave_to_volume(&look(&args.view.look), tf, input).map_err(refused)?;
    Ok(settings)
}

/// Reads a `--tf` file (volray-app's `look`: a regular file of UTF-8
/// text, bounded).
pub fn read_tf_file(path: &Path) -> Result<String, CliError> {
    volray_app::look::read_tf_file(path).map_err(|e| {
        let message = format!("--tf {}: {e}", path.display());
        match e.is_io_failure() {
            true => CliError::io(message),
            false => CliError::input(message),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flags::{Cli, Command, RenderArgs};
    use clap::Parser;
    use volray_core::glam::DVec3;
    use volray_core::{Blend, ClipPlane, IsoSurface, Projection};

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
