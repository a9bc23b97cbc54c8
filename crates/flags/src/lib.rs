//! The `volray` command's words: its flags, split by concern as ripgrep
//! splits its own, each group a clap `Args` struct in its own module that
//! the subcommands' arguments flatten; the command line parsed (errors
//! on one line); and the flags as volray-options' [`Options`](volray_options::Options)
//! ([`options()`]), which every front end checks and turns into settings
//! alike.
//!
//! A library, not the binary's private module, because three readers of
//! `volray render` words need one parser: the `volray` binary (its
//! command line), `volray view` (the page's state is written as a
//! `volray render` command and parsed back here, so the frame the page
//! shows is that command's frame by construction), and tests and scripts
//! that check a command means what it should.
//!
//! ```
//! use clap::Parser;
//! use volray_flags::{Cli, Command};
//!
//! let cli = Cli::try_parse_from(["volray", "render", "ct.nrrd", "--azimuth", "30", "-o", "a.png"])
//!     .unwrap();
//! let Command::Render(args) = cli.command else { unreachable!() };
//! let options = volray_flags::options(&args.view, None);
//! assert_eq!(options.camera.azimuth, 30.0);
//! let settings = volray_options::settings(&options).unwrap();
//! assert_eq!(settings.camera.azimuth, 30.0);
//! ```
//!
//! - `input.rs`: INPUT and how to read it (render, bench, info);
//! - `view.rs`: how to render a frame (render, bench), made of
//!   `camera.rs` (the image size, the eye, the projection, clipping),
//!   `look.rs` (classification, shading, blending) and `sampling.rs`
//!   (the step, jitter, the path, non-finite values), and `--threads`;
//! - `output.rs` and `animation.rs`: render's output file, and its
//!   turntables and series; `scene.rs`: several volumes in one picture
//!   (`--channels`, `--overlay`) and a file's time points (`--frames`);
//!   `figure.rs`: annotations drawn into a still (`--colorbar`,
//!   `--scale-bar`, `--title`, `--label`);
//! - `render.rs`, `bench.rs`, `info.rs`, `convert.rs`, `generate.rs`, `paper.rs`,
//!   `viewer.rs` (`volray view`): each subcommand's arguments (`bench.rs`
//!   also says which groups `--peers` refuses), `demo.rs`: `volray
//!   render` with no INPUT;
//! - `parse.rs`: the value parsers, and clap's errors on one line;
//! - `options.rs`: the flags as volray-options' options;
//! - `reproduce.rs`: `volray view`'s page state as `volray render` words
//!   (volray-app's), parsed back here into the frame's settings.

mod animation;
mod bench;
mod camera;
mod convert;
pub mod demo;
mod figure;
mod generate;
mod info;
mod input;
mod look;
mod options;
mod output;
mod paper;
mod parse;
mod render;
pub mod reproduce;
mod sampling;
mod scene;
mod view;
mod viewer;

pub use bench::BenchArgs;
pub use camera::CameraArgs;
pub use convert::ConvertArgs;
pub use figure::{ColorBarSide, FigureArgs, ScaleLength};
pub use generate::{FractalArgs, GenerateArgs, GenerateKind, HydrogenArgs};
pub use info::InfoArgs;
pub use input::InputArgs;
pub use look::{BlendMode, LookArgs};
pub use options::{Flags, camera, look, options, sampling};
pub use paper::{PaperArgs, PaperItem};
pub use parse::one_line_error;
pub use render::RenderArgs;
pub use sampling::SamplingArgs;
pub use scene::{Channels, Frames, MixMode, SceneArgs};
pub use view::ViewArgs;
pub use viewer::ViewerArgs;

use clap::error::ErrorKind;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::ffi::OsString;
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(
    name = "volray",
    version,
    about = "Ray-casting volume renderer (Ramesh & Athithan 1993, after Levoy 1988)",
    long_about = "Ray-casting volume renderer (Ramesh & Athithan 1993, after Levoy 1988).\n\n\
        Exit codes: 0 success, 1 bad input or arguments, 2 I/O failure, \
        130 interrupted (Ctrl-C; 128 + the signal for SIGTERM and SIGHUP)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a volume to an image (PNG, OpenEXR), or a turntable or a
    /// series of volumes to an animation (animated PNG, GIF, numbered PNGs).
    Render(RenderArgs),
    /// Time frames of a volume: median of several views, each new.
    Bench(BenchArgs),
    /// Describe a volume: format, dims, spacing, origin, sample type, value
    /// range, a histogram, and what the header said versus what was used.
    Info(InfoArgs),
    /// Write a volume volray reads to another format: NRRD (keeps spacing
    /// and origin), .npy or raw, its samples in their type. A volume over
    /// --max-memory that maps from its file converts in bounded memory.
    Convert(ConvertArgs),
    /// Write a generated volume to a file: a hydrogen-atom density or a
    /// fractal cloud (the paper's two test data sets).
    Generate(GenerateArgs),
    /// Reproduce the paper's Figures 1a, 1b, 1c, 2a, 2b and Table 1 into a
    /// directory (figure1a.png ... figure2b.png, table1.md).
    Paper(PaperArgs),
    /// Explore a volume in a web browser: serves a page that orbits,
    /// zooms and pans, edits the transfer function and shows the `volray
    /// render` command of the current view; frames are rendered here.
    /// Prints the page's URL (with its access token) and serves until
    /// Ctrl-C.
    View(ViewerArgs),
}

/// The command line, parsed; or, when it asks for help or the version or
/// is wrong, that printed (an error on one line, naming the argument,
/// without the usage block) and the exit code to end with: 0 for help and
/// the version, 1 otherwise.
pub fn parse() -> Result<Cli, ExitCode> {
    let argv: Vec<OsString> = std::env::args_os().collect();
    let matches = Cli::command()
        .try_get_matches_from(&argv)
        .map_err(refused)?;
    let demo = matches
        .subcommand_matches("render")
        .and_then(|render| demo::words(&argv, render));
    // The command line is parsed once; only the demo's is parsed again,
    // with its words.
    let Some(words) = demo else {
        return Cli::from_arg_matches(&matches).map_err(refused);
    };
    let cli = Cli::try_parse_from(&words).map_err(refused)?;
    eprintln!("{}", demo::note());
    Ok(cli)
}

/// The exit code of a command line clap refused or answered (help, the
/// version), its text printed.
fn refused(e: clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            ExitCode::SUCCESS
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            ExitCode::from(1)
        }
        _ => {
            eprintln!("volray: {}", parse::one_line_error(&e));
            ExitCode::from(1)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blend_names_and_aliases() {
        let blend = |name: &str| {
            let cli = Cli::try_parse_from(["volray", "render", "-o", "x.png", "--blend", name])
                .map_err(|e| e.to_string())?;
            match cli.command {
                Command::Render(args) => Ok(args.view.look.blend),
                _ => Err("not render".to_string()),
            }
        };
        assert_eq!(blend("mip"), Ok(BlendMode::Mip));
        assert_eq!(blend("maximum"), Ok(BlendMode::Mip));
        assert_eq!(blend("minimum"), Ok(BlendMode::Minip));
        assert_eq!(blend("average"), Ok(BlendMode::Average));
        assert!(blend("sum").is_err());
    }

    #[test]
    fn several_inputs_and_repeated_clip_planes() {
        let cli = Cli::try_parse_from([
            "volray",
            "render",
            "a.cube",
            "b.cube",
            "c.cube",
            "-o",
            "x.gif",
            "--clip",
            "0,0,0,1,0,0",
            "--clip",
            "0,0,0,0,-1,0",
        ])
        .unwrap();
        let Command::Render(args) = cli.command else {
            panic!("not render")
        };
        assert_eq!(args.input.input.as_deref(), Some("a.cube"));
        assert_eq!(args.animation.series, ["b.cube", "c.cube"]);
        assert_eq!(args.view.camera.clip.len(), 2);
        assert_eq!(args.view.camera.clip[1].1, [0.0, -1.0, 0.0]);
    }
}
