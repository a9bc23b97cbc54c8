//! `volray`: the command line. It parses arguments and calls the libraries:
//! `volray-io` and `volray-data` for the input, `volray-core` to render,
//! `volray-io` again for the PNG.
//!
//! Where things are:
//!
//! - `flags/`: every flag, one module per group (input, camera, look,
//!   sampling, output, animation) and one per subcommand; `flags/mod.rs`
//!   parses the command line and lists them all;
//! - one module per subcommand: `render.rs` (one still image, and the
//!   checks before any work) with `animate.rs` (turntables, series and
//!   `--frames`) and `scene.rs` (several volumes in one picture:
//!   `--channels`, `--overlay`), `bench.rs`, `info.rs` (their timing,
//!   reading and describing are volray-app's), `convert.rs` (a volume to NRRD, `.npy` or raw, also what `generate`
//!   writes with), `generate.rs`, `paper.rs`, `view.rs` (the browser viewer, with
//!   `view/reproduce.rs`: the page's state as a `volray render` command);
//! - what they share: `settings.rs` (the flags as volray-core's
//!   `RenderSettings`), `session.rs` (the flags as volray-app's input
//!   requests and plans, the renderer within the `--max-memory` budget,
//!   threads, progress, which flag a render error is about); volray-app
//!   reads INPUT, plans it and budgets its frames;
//! - the process: `error.rs` (one-line errors and their exit codes: 0
//!   success, 1 bad input, 2 I/O, 128 + the signal when interrupted),
//!   `output.rs` (standard output), `overwrite.rs` (never writing over an
//!   input), `interrupt.rs` (Ctrl-C and friends).
//!
//! This file only dispatches: parse, catch signals, run the subcommand,
//! print its error on one line and exit with its code.

// First, so that its `outln!` macro reaches every module below.
#[macro_use]
mod output;

mod animate;
mod bench;
mod convert;
mod error;
mod figure;
mod flags;
mod generate;
mod info;
mod interrupt;
#[cfg(feature = "mpi")]
mod mpi;
mod outfile;
mod paper;
mod render;
mod scene;
mod session;
mod settings;
mod view;

use flags::Command;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match flags::parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    interrupt::install();
    #[cfg(feature = "mpi")]
    if mpi::launched() {
        let result = match &cli.command {
            Command::Render(args) => Some(mpi::render(args)),
            Command::Bench(args) => Some(mpi::bench(args)),
            _ => None,
        };
        if let Some(result) = result {
            return exit(result);
        }
    }
    let result = match &cli.command {
        Command::Render(args) => render::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Info(args) => info::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Paper(args) => paper::run(args),
        Command::View(args) => view::run(args),
    };
    exit(result)
}

/// The exit code of a command's outcome, its error printed.
fn exit(result: Result<(), error::CliError>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One write, so that the lines of several processes (MPI
            // ranks) do not interleave.
            let line = format!("volray: error: {e}\n");
            let _ = std::io::Write::write_all(&mut std::io::stderr(), line.as_bytes());
            ExitCode::from(e.code)
        }
    }
}
