//! `volray`: the command line. It parses arguments and calls the libraries:
//! `volray-io` and `volray-data` for the input, `volray-core` to render,
//! `volray-io` again for the PNG.

// First, so that its `outln!` macro reaches every module below.
#[macro_use]
mod output;

mod animate;
mod bench;
mod cli;
mod error;
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

use clap::Parser;
use clap::error::ErrorKind;
use cli::{Cli, Command};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            return match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    let _ = e.print();
                    ExitCode::SUCCESS
                }
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = e.print();
                    ExitCode::from(1)
                }
                _ => {
                    // One line, naming the argument, without the usage block.
                    eprintln!("volray: {}", cli::one_line_error(&e));
                    ExitCode::from(1)
                }
            };
        }
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
