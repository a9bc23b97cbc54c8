//! Animations of `render`: the volumes after INPUT (a series, one frame
//! each), `--turntable` and `--fps`. `animate.rs` renders them.

use super::parse::parse_fps;
use clap::Args;

/// A turntable or a series, and its frame rate.
#[derive(Debug, Args)]
pub struct AnimationArgs {
    /// More volumes after INPUT: render them all as an animation, one
    /// frame per volume in the order given, with one transfer function
    /// (the value range spans every volume unless --range) and one framing
    /// (the box around every volume). They are read one at a time, twice.
    #[arg(value_name = "MORE")]
    pub series: Vec<String>,

    /// Render FRAMES views into an animation, the view point orbiting the
    /// up vector (azimuth --azimuth + 360·i/FRAMES for frame i) with the
    /// window fitted to the bounding sphere so the picture keeps its scale.
    #[arg(long, value_name = "FRAMES", value_parser = clap::value_parser!(u32).range(1..=100_000), allow_hyphen_values = true, help_heading = "Animations")]
    pub turntable: Option<u32>,

    /// Frames per second of an animation, in (0, 100] [default: 24]; GIF
    /// keeps the delay in hundredths of a second.
    #[arg(long, value_name = "FPS", value_parser = parse_fps, allow_hyphen_values = true, help_heading = "Animations")]
    pub fps: Option<f64>,
}
