//! `volray render`'s flags, each group in its own module.

use super::animation::AnimationArgs;
use super::figure::FigureArgs;
use super::input::InputArgs;
use super::output::OutputArgs;
use super::scene::SceneArgs;
use super::view::ViewArgs;
use clap::Args;

/// `volray render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub input: InputArgs,

    #[command(flatten)]
    pub out: OutputArgs,

    #[command(flatten)]
    pub animation: AnimationArgs,

    #[command(flatten)]
    pub scene: SceneArgs,

    #[command(flatten)]
    pub figure: FigureArgs,

    #[command(flatten)]
    pub view: ViewArgs,
}
