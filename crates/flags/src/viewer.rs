//! `volray view`'s flags: the input and every rendering option (the view
//! it starts from, as `render` takes them; the volumes of a scene and a
//! time axis, as `render` takes them), and where to serve: `--port`,
//! `--bind`, `--no-browser`. (`view.rs` beside this file is the group of
//! flags that render a frame, which `render` and `bench` share too.)

use super::figure::FigureArgs;
use super::input::InputArgs;
use super::scene::SceneArgs;
use super::view::ViewArgs;
use clap::Args;
use std::net::IpAddr;

/// `volray view`.
#[derive(Debug, Args)]
pub struct ViewerArgs {
    #[command(flatten)]
    pub input: InputArgs,

    #[command(flatten)]
    pub view: ViewArgs,

    /// Several volumes in one picture, each with its panel in the page
    /// (`--channels`, `--overlay`), or a time axis with a slider
    /// (`--frames`).
    #[command(flatten)]
    pub scene: SceneArgs,

    /// What the frames start with drawn into them (the page's Figure
    /// controls change it).
    #[command(flatten)]
    pub figure: FigureArgs,

    /// The port to serve on; 0 picks a free one.
    #[arg(long, value_name = "N", default_value_t = 0, help_heading = "Serving")]
    pub port: u16,

    /// The address to listen on. Anything but a loopback address lets
    /// other machines reach the viewer (with the token): use an SSH
    /// tunnel instead where you can.
    #[arg(
        long,
        value_name = "ADDR",
        default_value = "127.0.0.1",
        help_heading = "Serving"
    )]
    pub bind: IpAddr,

    /// Do not open a browser (by default one is opened when a display is
    /// present).
    #[arg(long, help_heading = "Serving")]
    pub no_browser: bool,
}
