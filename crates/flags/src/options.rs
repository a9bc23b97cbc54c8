//! The flags as volray-options' [`Options`]: what every front end checks
//! together and turns into volray-core's settings, so that `volray
//! render`'s flags and Python's keywords mean the same; and how the
//! command line names an option in an error ([`Flags`]).

use crate::{BlendMode, CameraArgs, LookArgs, SamplingArgs, ViewArgs};
use volray_options::{CameraOptions, LookOptions, Naming, Opt, Options, Tf};

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

/// The options the view arguments give, with the text of the `--tf`
/// file (`tf_text`; read by the caller, which alone knows where files
/// may be read from: `volray render` reads it, `volray view` hands over
/// the text its page edited). A `--tf` file whose text is not given keeps
/// an empty text, which the transfer-function parser refuses.
pub fn options(view: &ViewArgs, tf_text: Option<&str>) -> Options {
    let mut look = look(&view.look);
    if let (Some(text), Some(Tf::Json { text: slot, .. })) = (tf_text, &mut look.tf) {
        *slot = text.to_string();
    }
    Options {
        camera: camera(&view.camera),
        look,
        sampling: sampling(&view.sampling),
    }
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
/// only [`options()`] puts it into the options; what the look leaves to
/// the volume (volray-options' `from_volume`) asks only whether one is
/// given.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Cli, Command, RenderArgs};
    use clap::Parser;
    use volray_core::glam::DVec3;
    use volray_core::{Blend, ClipPlane, IsoSurface, Projection, RenderSettings};

    fn settings(view: &ViewArgs) -> RenderSettings {
        volray_options::settings(&options(view, None)).unwrap()
    }

    #[test]
    fn command_line_defaults_are_the_library_defaults() {
        // The defaults are written twice, for `--help` and in volray-core:
        // they must say the same.
        let cli = Cli::try_parse_from(["volray", "render", "-o", "x.png"]).unwrap();
        let Command::Render(args) = cli.command else {
            panic!("not a render command")
        };
        assert_eq!(settings(&args.view), RenderSettings::default());
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
        let s = settings(&args.view);
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
        assert_eq!(settings(&mip.view).blend, Blend::Minimum);
    }
}
