//! `volray render`: INPUT → Volume → Renderer → Image → PNG.

use crate::cli::{RenderArgs, ViewArgs};
use crate::error::CliError;
use crate::input::{self, Input};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::Path;
use volray_core::glam::DVec3;
use volray_core::{
    Camera, Method, Phong, RenderSettings, Renderer, TransferFunction, colormap, presets,
};
use volray_io::BitDepth;

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    let input = input::load(&args.input)?;
    check_output(&args.output, &input)?;
    output_kind(&args.output, args.bit_depth)?;
    let settings = settings(&args.view)?;
    let pool = thread_pool(args.view.threads)?;
    let renderer = Renderer::new(&input.volume)
        .map_err(|e| CliError::input(format!("{}: {e}", input.name)))?;

    let pixels = (settings.width * settings.height) as u64;
    let bar = if std::io::stderr().is_terminal() && pixels >= 256 * 256 {
        let bar = ProgressBar::new(pixels);
        bar.set_style(
            ProgressStyle::with_template("{spinner} rendering [{bar:40}] {percent}% ({eta} left)")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let image = pool
        .install(|| renderer.render_with_progress(&settings, &|n| bar.inc(n as u64)))
        .map_err(|e| CliError::input(format!("{}: {e}", input.name)))?;
    bar.finish_and_clear();

    match output_kind(&args.output, args.bit_depth)? {
        OutputKind::Png(depth) => volray_io::write_png(&args.output, &image, depth)?,
        OutputKind::Exr => volray_io::write_exr(&args.output, &image)?,
    }
    Ok(())
}

/// What an output file name asks for.
enum OutputKind {
    Png(BitDepth),
    /// OpenEXR: the f32 frame buffer, unquantised.
    Exr,
}

/// The output format from the file name: `.exr` is OpenEXR, anything else
/// PNG (at `--bit-depth`). `--bit-depth 16` with `.exr` is refused: EXR
/// holds 32-bit floats.
fn output_kind(output: &Path, bit_depth: u8) -> Result<OutputKind, CliError> {
    let ext = output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") if bit_depth != 8 => Err(CliError::input(format!(
            "{}: --bit-depth applies to PNG output; OpenEXR holds 32-bit floats",
            output.display()
        ))),
        Some("exr") => Ok(OutputKind::Exr),
        _ => Ok(OutputKind::Png(if bit_depth == 16 {
            BitDepth::Sixteen
        } else {
            BitDepth::Eight
        })),
    }
}

/// Refuses, before any work, an output that would overwrite the input or
/// that cannot be written where it is asked for.
fn check_output(output: &Path, input: &Input) -> Result<(), CliError> {
    if let Some(path) = &input.path
        && let (Ok(a), Ok(b)) = (path.canonicalize(), output.canonicalize())
        && a == b
    {
        return Err(CliError::input(format!(
            "{}: the output is the input file; refusing to overwrite it",
            output.display()
        )));
    }
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

/// The render settings the view arguments describe.
pub fn settings(view: &ViewArgs) -> Result<RenderSettings, CliError> {
    let transfer_function = match &view.tf {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| CliError::io(format!("{}: cannot read: {e}", path.display())))?;
            TransferFunction::from_json(&text)
                .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?
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
    let settings = RenderSettings {
        width: view.size.0,
        height: view.size.1,
        camera: Camera {
            view_point: view.view.map(DVec3::from),
            look_at: view.look_at.map(DVec3::from),
            up: DVec3::from(view.up),
        },
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
    };
    settings
        .validate()
        .map_err(|e| CliError::input(e.to_string()))?;
    Ok(settings)
}

/// A pool of `threads` workers (default: one per core).
pub fn thread_pool(threads: Option<u16>) -> Result<rayon::ThreadPool, CliError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n as usize);
    }
    builder
        .build()
        .map_err(|e| CliError::io(format!("cannot start worker threads: {e}")))
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
}
