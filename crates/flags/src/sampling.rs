//! How the rays sample the volume: the step between samples, their
//! jitter, the path that takes them (the fast one or the paper's
//! reference), and what becomes of NaN and infinite values.
//!
//! `--step` is here rather than with the camera: the camera decides where
//! the rays go, not how finely they are sampled (in volray-core the step
//! is a render setting, not part of the `Camera`).

use super::parse::parse_step;
use clap::Args;

/// Sampling along the rays.
#[derive(Debug, Args)]
pub struct SamplingArgs {
    /// Sample spacing along the rays, in voxels (of the smallest spacing).
    #[arg(long, value_name = "S", default_value = "1", value_parser = parse_step, allow_hyphen_values = true)]
    pub step: f64,

    /// Use the reference path (the paper's back-to-front compositing, no
    /// shortcuts), the oracle for the fast default.
    #[arg(long)]
    pub reference: bool,

    /// Start each pixel's samples a fraction of a step further (a fixed
    /// hash of the pixel, the same every run) against wood-grain artifacts.
    #[arg(long, help_heading = "Rendering options")]
    pub jitter: bool,

    /// NaN and infinite voxel values: refuse the volume (naming their
    /// count), or render them as empty space: no opacity, not counted by
    /// mip/minip/average; the value window is the finite values'.
    #[arg(
        long,
        value_enum,
        value_name = "refuse|transparent",
        default_value = "refuse",
        help_heading = "Rendering options"
    )]
    pub nonfinite: NonFiniteMode,
}

/// `--nonfinite`: what to do with NaN and infinite voxel values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum NonFiniteMode {
    /// Refuse the volume.
    Refuse,
    /// Render them as empty space.
    Transparent,
}

impl From<NonFiniteMode> for volray_core::NonFinite {
    fn from(mode: NonFiniteMode) -> Self {
        match mode {
            NonFiniteMode::Refuse => volray_core::NonFinite::Refuse,
            NonFiniteMode::Transparent => volray_core::NonFinite::Transparent,
        }
    }
}
