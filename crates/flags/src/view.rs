//! How to render a frame, the flags `render` and `bench` share: the
//! [camera](super::camera), the [look](super::look) (classification and
//! shading), the [sampling](super::sampling) along the rays, and the
//! worker threads.

use super::camera::CameraArgs;
use super::look::LookArgs;
use super::sampling::SamplingArgs;
use clap::Args;

/// How to render a frame.
#[derive(Debug, Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub camera: CameraArgs,

    #[command(flatten)]
    pub look: LookArgs,

    #[command(flatten)]
    pub sampling: SamplingArgs,

    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..), allow_hyphen_values = true)]
    pub threads: Option<u16>,
}
