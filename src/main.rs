//! `volray`: the command line. It parses arguments and calls the libraries:
//! `volray-io` and `volray-data` for the input, `volray-core` to render,
//! `volray-io` again for the PNG.

// First, so that its `outln!` macro reaches every module below.
#[macro_use]
mod output;

mod animate;
mod bench;
mod error;
mod flags;
mod generate;
mod info;
mod input;
mod interrupt;
mod memory;
mod overwrite;
mod paper;
mod render;
mod session;
mod settings;

use flags::Command;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match flags::parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    interrupt::install();
    let result = match &cli.command {
        Command::Render(args) => render::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Info(args) => info::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Paper(args) => paper::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("volray: error: {e}");
            ExitCode::from(e.code)
        }
    }
}
