//! Animations of `render`: the volumes after INPUT (a series, one frame
//! each), `--turntable` and `--fps`, which `animate.rs` renders; and
//! movies: `--keyframes` (volray-app's `movie`), encoded with ffmpeg at
//! `--crf`, resumable (`--resume`) and splittable (`--movie-frames`),
//! which `movie/` (beside `main.rs`) renders.

use super::parse::parse_fps;
use super::scene::{Frames, parse_frames};
use clap::Args;
use std::path::PathBuf;

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

    /// A movie: the camera and look moving through the keyframes of a
    /// JSON file (its schema: docs/movies.md), written as .mp4 or .webm
    /// (through ffmpeg), .gif, .png (animated) or numbered PNGs.
    #[arg(long, value_name = "FILE", help_heading = "Animations")]
    pub keyframes: Option<PathBuf>,

    /// Quality of an .mp4 (H.264) or .webm (VP9) movie: ffmpeg's constant
    /// rate factor, 0 (lossless for VP9, best) to 51 (worst) [default: 16].
    #[arg(long, value_name = "CRF", value_parser = clap::value_parser!(u8).range(0..=51), help_heading = "Animations")]
    pub crf: Option<u8>,

    /// Keep every finished frame of an animation (lossless PNGs in the
    /// folder OUTPUT.frames beside the output; a PNG sequence's frames
    /// are its own files) and, run again after an interruption, render
    /// only the missing ones.
    #[arg(long, help_heading = "Animations")]
    pub resume: bool,

    /// Render only the frames A up to B-1 of an animation (B left out: to
    /// the last) into its folder of finished frames (as --resume keeps
    /// them); the movie is written once every frame is there, by the
    /// part that completes it or a run with --resume.
    #[arg(long, value_name = "A:B", value_parser = parse_frames, help_heading = "Animations")]
    pub movie_frames: Option<Frames>,
}
