//! `volray render`: INPUT → Volume → Renderer → Image → PNG or OpenEXR;
//! with `--turntable` or several inputs, an animation (`animate.rs`).

use crate::animate;
use crate::cli::{BlendMode, RenderArgs, ViewArgs};
use crate::error::CliError;
use crate::input;
use crate::session::{load, progress_bar, render_failure, renderer_for, thread_pool};
use std::path::{Path, PathBuf};
use volray_core::glam::DVec3;
use volray_core::transfer::{colormap, presets};
use volray_core::{
    Blend, Camera, Classification, ClipPlane, IsoSurface, Method, Phong, Projection,
    RenderSettings, TransferFunction,
};
use volray_io::{Animation, AnimationKind, BitDepth};

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    let specs = specs(args);
    let animation = animation_reason(args)?;
    let kind = output_kind(&args.output, args.bit_depth, animation)?;
    if args.fps.is_some() && animation.is_none() {
        return Err(CliError::input(
            "--fps applies to animations: give --turntable FRAMES or several inputs",
        ));
    }
    let settings = settings(&args.view)?;
    check_output(&args.output)?;
    crate::overwrite::refuse_overwriting_inputs(
        &output_files(args, kind, specs.len()),
        &specs,
        &args.view.tf.iter().map(|p| p.as_path()).collect::<Vec<_>>(),
    )?;
    let pool = thread_pool(args.view.threads)?;
    match (kind, args.turntable) {
        (OutputKind::Animation, Some(frames)) => {
            animate::turntable(args, &settings, &pool, frames as usize)
        }
        (OutputKind::Animation, None) => animate::series(args, &specs, &settings, &pool),
        (kind, _) => still(args, &settings, &pool, kind),
    }
}

/// One frame of one volume, to an image file.
fn still(
    args: &RenderArgs,
    settings: &RenderSettings,
    pool: &rayon::ThreadPool,
    kind: OutputKind,
) -> Result<(), CliError> {
    let input = load(&args.input, args.view.log)?;
    let renderer = renderer_for(&args.view, settings, &input)?;
    let bar = progress_bar((settings.width * settings.height) as u64);
    let image = pool
        .install(|| renderer.render_with_progress(settings, &|n| bar.inc(n as u64)))
        .map_err(|e| render_failure(&args.view, &input.name, e))?;
    bar.finish_and_clear();

    match kind {
        OutputKind::Png(depth) => volray_io::write_png(&args.output, &image, depth)?,
        OutputKind::Exr => volray_io::write_exr(&args.output, &image)?,
        OutputKind::Gif => {
            let mut gif = Animation::create(
                &args.output,
                image.width(),
                image.height(),
                1,
                animate::DEFAULT_FPS,
            )?;
            gif.push(&image)?;
            gif.finish()?;
        }
        OutputKind::Animation => unreachable!("animations are rendered by animate.rs"),
    }
    Ok(())
}

/// The inputs in order: INPUT (or the demo volume), then MORE.
fn specs(args: &RenderArgs) -> Vec<String> {
    let first = args.input.input.as_deref().unwrap_or(input::DEMO);
    std::iter::once(first.to_string())
        .chain(args.series.iter().cloned())
        .collect()
}

/// Why the output is an animation (the flag that asks for one), or
/// `None` for a single frame. A turntable of a series is refused: which
/// frame would turn how far is not obvious.
fn animation_reason(args: &RenderArgs) -> Result<Option<&'static str>, CliError> {
    match (args.turntable, args.series.is_empty()) {
        (Some(_), false) => Err(CliError::input(
            "--turntable renders one volume: give one input, or several inputs without --turntable",
        )),
        (Some(_), true) => Ok(Some("--turntable")),
        (None, false) => Ok(Some("several inputs")),
        (None, true) => Ok(None),
    }
}

/// What an output file name asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum OutputKind {
    Png(BitDepth),
    /// OpenEXR: the f32 frame buffer, unquantised.
    Exr,
    /// A one-frame GIF.
    Gif,
    /// Frames through [`Animation`]: APNG, GIF or a PNG sequence.
    Animation,
}

/// The output format from the file name: `.exr` is OpenEXR, `.gif` a GIF,
/// anything else PNG (at `--bit-depth`). An animation (`animation` says
/// which flag asks for one) is an animated PNG, a GIF or a PNG sequence,
/// at 8 bits. `--bit-depth 16` is refused where the format cannot hold it.
fn output_kind(
    output: &Path,
    bit_depth: u8,
    animation: Option<&str>,
) -> Result<OutputKind, CliError> {
    let name = output.display();
    let ext = output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if let Some(why) = animation {
        if ext.as_deref() == Some("exr") {
            return Err(CliError::input(format!(
                "{name}: {why} makes an animation, which OpenEXR cannot hold: write .png (animated PNG), .gif or numbered PNGs (e.g. turn_%03d.png)"
            )));
        }
        if AnimationKind::from_path(output).is_none() {
            return Err(CliError::input(format!(
                "{name}: {why} makes an animation: write .png (animated PNG), .gif or numbered PNGs (e.g. turn_%03d.png)"
            )));
        }
        if bit_depth != 8 {
            return Err(CliError::input(format!(
                "{name}: --bit-depth {bit_depth}: animations are written at 8 bits per channel"
            )));
        }
        return Ok(OutputKind::Animation);
    }
    match ext.as_deref() {
        Some("exr") if bit_depth != 8 => Err(CliError::input(format!(
            "{name}: --bit-depth applies to PNG output; OpenEXR holds 32-bit floats"
        ))),
        Some("exr") => Ok(OutputKind::Exr),
        Some("gif") if bit_depth != 8 => Err(CliError::input(format!(
            "{name}: --bit-depth applies to PNG output; GIF holds 8 bits per channel"
        ))),
        Some("gif") => Ok(OutputKind::Gif),
        _ => Ok(OutputKind::Png(if bit_depth == 16 {
            BitDepth::Sixteen
        } else {
            BitDepth::Eight
        })),
    }
}

/// The files the run will write: OUTPUT, or each frame's file of a PNG
/// sequence.
fn output_files(args: &RenderArgs, kind: OutputKind, inputs: usize) -> Vec<PathBuf> {
    let frames = args.turntable.map_or(inputs, |n| n as usize);
    match AnimationKind::from_path(&args.output) {
        Some(AnimationKind::PngSequence) if kind == OutputKind::Animation => (0..frames)
            .filter_map(|i| volray_io::sequence_path(&args.output, i))
            .collect(),
        _ => vec![args.output.clone()],
    }
}

/// Refuses, before any work, an output that cannot be written where it is
/// asked for (overwriting an input is refused by `overwrite.rs`).
fn check_output(output: &Path) -> Result<(), CliError> {
    let dir = match output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(CliError::io(format!(
            "{}: directory {} does not exist",
            output.display(),
            dir.display()
        )));
    }
    if output.is_dir() {
        return Err(CliError::io(format!(
            "{}: is a directory",
            output.display()
        )));
    }
    Ok(())
}

/// The largest `--tf` file read: a transfer function is a few hundred
/// points; this bounds what a wrong path (a device, a huge file) costs.
const TF_MAX_BYTES: u64 = 16 << 20;

/// Reads a `--tf` file: a regular file of at most [`TF_MAX_BYTES`].
fn read_tf_file(path: &Path) -> Result<String, CliError> {
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

/// The render settings the view arguments describe.
pub fn settings(view: &ViewArgs) -> Result<RenderSettings, CliError> {
    let transfer_function = match &view.tf {
        Some(path) => {
            let text = read_tf_file(path)?;
            TransferFunction::from_json(&text)
                .map_err(|e| CliError::input(format!("--tf {}: {e}", path.display())))?
        }
        None => TransferFunction::default(),
    };
    let from = if view.tf.is_some() {
        "--tf"
    } else {
        "--preset"
    };
    let mut transfer_function = match &view.preset {
        Some(_) if view.tf.is_some() => {
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
    if view.opacity.is_some() && transfer_function.opacity.is_some() {
        return Err(CliError::input(format!(
            "--opacity conflicts with the opacity function in {from}: give one of them"
        )));
    }
    if let Some(name) = &view.colormap {
        if view.tf.is_some() && transfer_function.color.is_some() {
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
    if let Some(range) = view.range {
        if transfer_function.domain.is_some() {
            return Err(CliError::input(format!(
                "--range conflicts with the value domain fixed by {from}: give one of them"
            )));
        }
        transfer_function.domain = Some(range);
    }
    if view.log
        && let Some((lo, hi)) = transfer_function.domain
    {
        // The window is given in the data's units; the renderer sees log10.
        let from = if view.range.is_some() {
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
    let settings = RenderSettings {
        width: view.size.0,
        height: view.size.1,
        camera: camera(view),
        step: view.step,
        opacity_ramp: view
            .opacity
            .unwrap_or(RenderSettings::default().opacity_ramp),
        transfer_function,
        phong: Phong {
            ambient: view.ambient,
            diffuse: view.diffuse,
            specular: view.specular,
            shininess: view.shininess,
            light_color: view.light_color,
        },
        shading: !view.no_shading,
        light_direction: view.light.map(DVec3::from),
        background: view.background,
        method: if view.reference {
            Method::Reference
        } else {
            Method::Fast
        },
        blend: blend(view)?,
        classification: if view.post_classification {
            Classification::Post
        } else {
            Classification::Pre
        },
        jitter: view.jitter,
        clip_planes: (view.clip.iter())
            .map(|&(point, normal)| ClipPlane {
                point: DVec3::from(point),
                normal: DVec3::from(normal),
            })
            .collect(),
        crop: view.crop.map(|(lo, hi)| (DVec3::from(lo), DVec3::from(hi))),
        iso: iso(view)?,
        gradient_opacity: view.gradient_opacity,
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

/// The camera of the view options.
fn camera(view: &ViewArgs) -> Camera {
    Camera {
        view_point: view.view.map(DVec3::from),
        look_at: view.look_at.map(DVec3::from),
        up: DVec3::from(view.up),
        projection: match view.perspective {
            Some(fov_degrees) => Projection::Perspective { fov_degrees },
            None => Projection::Orthographic,
        },
        zoom: view.zoom,
        azimuth: view.azimuth,
        elevation: view.elevation,
        ..Camera::default()
    }
}

/// `--blend`, checked against the options that only compositing uses:
/// a projection shows the interpolated scalar, with no opacity to shape
/// and no lighting.
fn blend(view: &ViewArgs) -> Result<Blend, CliError> {
    let (blend, name) = match view.blend {
        BlendMode::Composite => (Blend::Composite, "composite"),
        BlendMode::Iso if view.iso.is_none() => {
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
            (view.iso.is_some(), "--iso"),
            (view.gradient_opacity.is_some(), "--gradient-opacity"),
            (view.post_classification, "--post-classification"),
            (view.opacity.is_some(), "--opacity"),
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
    } else if view.no_shading {
        Some("--no-shading turns the lighting off".to_string())
    } else {
        None
    };
    if let (Some(why), Some(flag)) = (unlit, lighting_flag(view)) {
        return Err(CliError::input(format!(
            "{flag} sets the lighting, but {why}: leave {flag} out"
        )));
    }
    Ok(blend)
}

/// The first lighting option given a value other than its default (the
/// library's, which `--help` shows), if any.
fn lighting_flag(view: &ViewArgs) -> Option<&'static str> {
    let lit = Phong::default();
    [
        (view.ambient != lit.ambient, "--ambient"),
        (view.diffuse != lit.diffuse, "--diffuse"),
        (view.specular != lit.specular, "--specular"),
        (view.shininess != lit.shininess, "--shininess"),
        (view.light_color != lit.light_color, "--light-color"),
        (view.light.is_some(), "--light"),
    ]
    .into_iter()
    .find_map(|(given, flag)| given.then_some(flag))
}

/// `--iso VALUE --iso-thickness R`; with `--log` the value is in the data's
/// units, like `--range`.
fn iso(view: &ViewArgs) -> Result<Option<IsoSurface>, CliError> {
    let Some(value) = view.iso else {
        return match view.iso_thickness {
            Some(_) => Err(CliError::input(
                "--iso-thickness is the half-width of the --iso shell: give --iso VALUE too",
            )),
            None => Ok(None),
        };
    };
    let value = if view.log {
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
        thickness: view.iso_thickness.unwrap_or(1.0),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{Cli, Command};
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

    #[test]
    fn output_names_pick_the_format() {
        let kind = |name: &str, depth: u8, animation: Option<&str>| {
            output_kind(Path::new(name), depth, animation).map_err(|e| e.message)
        };
        assert_eq!(
            kind("a.png", 16, None),
            Ok(OutputKind::Png(BitDepth::Sixteen))
        );
        assert_eq!(kind("a.EXR", 8, None), Ok(OutputKind::Exr));
        assert_eq!(kind("a.gif", 8, None), Ok(OutputKind::Gif));
        assert!(kind("a.gif", 16, None).is_err());
        for name in ["a.png", "a.gif", "a_%03d.png"] {
            assert_eq!(
                kind(name, 8, Some("--turntable")),
                Ok(OutputKind::Animation)
            );
        }
        assert!(
            kind("a.exr", 8, Some("--turntable"))
                .unwrap_err()
                .contains("OpenEXR")
        );
        assert!(kind("a.mp4", 8, Some("several inputs")).is_err());
        assert!(
            kind("a.png", 16, Some("--turntable"))
                .unwrap_err()
                .contains("8 bits")
        );
    }
}
