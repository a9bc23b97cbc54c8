//! `volray render`: INPUT → Volume → Renderer → Image → PNG or OpenEXR;
//! with `--turntable`, `--frames` or several inputs, an animation
//! (`animate.rs`); with `--channels` or `--overlay`, several volumes in
//! one picture (`scene.rs`).

use crate::animate;
use crate::error::CliError;
use crate::flags::RenderArgs;
use crate::input;
use crate::session::{load, progress_bar, render_failure, renderer_for, thread_pool};
use crate::settings::settings;
use crate::streamed::Plan;
use std::path::{Path, PathBuf};
use volray_core::{FrameRequest, Render, RenderSettings, Rendered};
use volray_io::{Animation, AnimationKind, BitDepth};

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    refuse_scene_flags_alone(args)?;
    if args.scene.is_scene() {
        return crate::scene::run(args);
    }
    let specs = specs(args);
    let animation = animation_reason(args)?;
    let kind = output_kind(&args.out.output, args.out.bit_depth, animation)?;
    if args.animation.fps.is_some() && animation.is_none() {
        return Err(CliError::input(
            "--fps applies to animations: give --turntable FRAMES, --frames or several inputs",
        ));
    }
    let settings = settings(&args.view)?;
    check_output(&args.out.output)?;
    crate::overwrite::refuse_overwriting_inputs(
        &output_files(args, kind, specs.len()),
        &specs,
        &args.view.look.tf_file().into_iter().collect::<Vec<_>>(),
    )?;
    let pool = thread_pool(args.view.threads)?;
    match (kind, args.animation.turntable) {
        (OutputKind::Animation, Some(frames)) => {
            animate::turntable(args, &settings, &pool, frames as usize)
        }
        (OutputKind::Animation, None) if args.scene.frames.is_some() => {
            animate::time_points(args, kind, &settings, &pool)
        }
        (OutputKind::Animation, None) => animate::series(args, &specs, &settings, &pool),
        (kind, _) => still(args, &settings, &pool, kind),
    }
}

/// `settings` with what the flags leave to `input`'s volume: `--labels`
/// or the transfer function chosen from it (`--tf auto`; see
/// [`crate::settings::from_volume`]), the volume marked as labels.
pub fn from_volume(
    args: &RenderArgs,
    settings: &RenderSettings,
    input: &mut crate::input::Input,
) -> Result<RenderSettings, CliError> {
    let mut settings = settings.clone();
    crate::settings::file_window(
        &args.view.look,
        &mut settings.transfer_function,
        input
            .file
            .as_ref()
            .and_then(|(_, info)| info.display_window()),
    );
    crate::settings::from_volume(
        &args.view.look,
        &mut settings.transfer_function,
        &mut input.volume,
        &input.name,
    )?;
    Ok(settings)
}

/// One frame of one volume, to an image file.
fn still(
    args: &RenderArgs,
    settings: &RenderSettings,
    pool: &rayon::ThreadPool,
    kind: OutputKind,
) -> Result<(), CliError> {
    let input_args = match crate::streamed::plan(&args.input, &args.view, settings)? {
        Plan::Streamed(mut streamed) => {
            crate::figure::refuse(&args.figure, "a volume rendered piece by piece")?;
            let settings = &streamed.settings_from_volume(&args.view, settings.clone())?;
            let bar = progress_bar((settings.width * settings.height) as u64);
            let (image, times) =
                pool.install(|| streamed.render(&args.view, settings, &|n| bar.inc(n as u64)))?;
            bar.finish_and_clear();
            write_still(args, kind, &image)?;
            eprintln!("{}", streamed.note(&times));
            return Ok(());
        }
        Plan::Whole { level } => crate::streamed::at_level(&args.input, level),
    };
    let mut input = load(&input_args, args.view.look.log)?;
    let settings = &from_volume(args, settings, &mut input)?;
    let renderer = renderer_for(&args.view, settings, &input)?;
    let bar = progress_bar((settings.width * settings.height) as u64);
    let mut image = pool
        .install(|| renderer.render(FrameRequest::new(settings).reporting(&|n| bar.inc(n as u64))))
        .map(Rendered::image)
        .map_err(|e| render_failure(&args.view, &input.name, e))?;
    bar.finish_and_clear();
    crate::figure::draw(args, kind, settings, &renderer, &input, &mut image)?;

    write_still(args, kind, &image)
}

/// Writes one frame to OUTPUT, as `kind` says (atomically: a failed write
/// leaves no file).
pub fn write_still(
    args: &RenderArgs,
    kind: OutputKind,
    image: &volray_core::Image,
) -> Result<(), CliError> {
    match kind {
        OutputKind::Png(depth) => volray_io::write_png(&args.out.output, image, depth)?,
        OutputKind::Exr => volray_io::write_exr(&args.out.output, image)?,
        OutputKind::Gif => {
            let mut gif = Animation::create(
                &args.out.output,
                image.width(),
                image.height(),
                1,
                animate::DEFAULT_FPS,
            )?;
            gif.push(image)?;
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
        .chain(args.animation.series.iter().cloned())
        .collect()
}

/// The flags of several volumes that mean nothing without `--channels`
/// or `--overlay`, and `--frames` with what it cannot take, refused.
fn refuse_scene_flags_alone(args: &RenderArgs) -> Result<(), CliError> {
    let scene = &args.scene;
    if !scene.is_scene() {
        if scene.channel_colors.is_some() {
            return Err(CliError::input(
                "--channel-colors colours the channels of --channels: give --channels",
            ));
        }
        if scene.mix.is_some() {
            return Err(CliError::input(
                "--mix mixes several volumes: give --channels or --overlay",
            ));
        }
    }
    if scene.frames.is_some() {
        if args.animation.turntable.is_some() {
            return Err(CliError::input(
                "--frames animates the time points of INPUT: give --frames or --turntable, not both",
            ));
        }
        if !args.animation.series.is_empty() {
            return Err(CliError::input(
                "--frames animates the time points of one input: give one input with it",
            ));
        }
    }
    Ok(())
}

/// Why the output is an animation (the flag that asks for one), or
/// `None` for a single frame. A turntable of a series is refused: which
/// frame would turn how far is not obvious.
fn animation_reason(args: &RenderArgs) -> Result<Option<&'static str>, CliError> {
    if args.scene.frames.is_some() {
        return Ok(Some("--frames"));
    }
    match (args.animation.turntable, args.animation.series.is_empty()) {
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
pub enum OutputKind {
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
pub fn output_kind(
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
pub fn output_files(args: &RenderArgs, kind: OutputKind, inputs: usize) -> Vec<PathBuf> {
    let frames = args.animation.turntable.map_or(inputs, |n| n as usize);
    match AnimationKind::from_path(&args.out.output) {
        Some(AnimationKind::PngSequence) if kind == OutputKind::Animation => (0..frames)
            .filter_map(|i| volray_io::sequence_path(&args.out.output, i))
            .collect(),
        _ => vec![args.out.output.clone()],
    }
}

/// Refuses, before any work, an output that cannot be written where it is
/// asked for (overwriting an input is refused by `overwrite.rs`).
pub fn check_output(output: &Path) -> Result<(), CliError> {
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

#[cfg(test)]
mod tests {
    use super::*;

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
