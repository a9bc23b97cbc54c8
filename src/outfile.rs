//! The output file of `volray render`: its kind, from the name and
//! `--bit-depth` ([`output_kind`]), the files a run will write, the check
//! that they can be written, and a still frame written. Shared by the
//! renders of one volume (`render.rs`), its animations (`animate.rs`),
//! several volumes in one picture (`scene.rs`) and MPI
//! (`distributed.rs`, through `render.rs`), which each call it and none
//! of which it calls.

use crate::error::CliError;
use std::path::{Path, PathBuf};
use volray_flags::RenderArgs;
use volray_io::{Animation, AnimationKind, BitDepth};

/// Frames per second when `--fps` is not given.
pub const DEFAULT_FPS: f64 = 24.0;

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
                DEFAULT_FPS,
            )?;
            gif.push(image)?;
            gif.finish()?;
        }
        OutputKind::Animation => unreachable!("animations are rendered by animate.rs"),
    }
    Ok(())
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
/// asked for (overwriting an input is refused by volray-app's `reads`).
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
