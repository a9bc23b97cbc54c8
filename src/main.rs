//! `volray`: the command line: output writing and progress display. It
//! parses arguments with `volray-flags` (every flag, one module per group
//! and one per subcommand, and the flags as volray-options' options) and
//! calls the libraries: `volray-app` for
//! what the front ends share (the input, its plan, the memory budget,
//! scenes, animations, the files an input reads, volumes written back),
//! `volray-core` to render, `volray-io` for the images, `volray-view` to
//! serve the browser viewer.
//!
//! Where things are:
//!
//! - one module per subcommand: `render.rs` (one still image, and the
//!   checks before any work) with `animate.rs` (turntables, series and
//!   `--frames`, written frame by frame) and `scene.rs` (several volumes in
//!   one picture: `--channels`, `--overlay`), `bench.rs`, `info.rs` (their
//!   timing, reading and describing are volray-app's), `convert.rs` (the
//!   flags of volray-app's `convert`, also what `generate` writes with),
//!   `generate.rs`, `paper.rs`, `view.rs` (the flags as volray-view's
//!   `open` and `Launch`, its page's commands reproduced by volray-flags'
//!   `reproduce`; `view/scene.rs`; `view/browser.rs`), `movie/` (movies,
//!   encoded by volray-io's `ffmpeg`);
//! - what they share: `settings.rs` (the flags' settings, the `--tf`
//!   file read, option errors worded with the flags), `session.rs` (the
//!   flags as volray-app's input requests, plans and renderers within the
//!   `--max-memory` budget, threads, progress, which flag a render error
//!   is about), `outfile.rs` and `figure.rs` (the output file, the
//!   annotations);
//! - the process: `error.rs` (one-line errors and their exit codes: 0
//!   success, 1 bad input, 2 I/O, 128 + the signal when interrupted),
//!   `output.rs` (standard output), `interrupt.rs` (Ctrl-C and friends).
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
mod generate;
mod info;
mod interrupt;
mod movie;
#[cfg(feature = "mpi")]
mod mpi;
mod outfile;
mod paper;
mod render;
mod scene;
mod session;
mod settings;
mod view;

use std::process::ExitCode;
use volray_flags::Command;

fn main() -> ExitCode {
    let cli = match volray_flags::parse() {
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
