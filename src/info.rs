//! `volray info`: what a volume file holds and how volray reads it
//! (described by `volray_app::describe`), printed.

use crate::error::CliError;
use volray_flags::InfoArgs;

pub fn run(args: &InfoArgs) -> Result<(), CliError> {
    let lines = volray_app::describe::lines(&args.input.request(), args.bins, args.json)?;
    for line in lines {
        outln!("{line}");
    }
    Ok(())
}
