//! `volray paper`: the paper's figures and Table 1 into a directory, made
//! by `volray-paper`.

use crate::error::CliError;
use crate::session::thread_pool;
use volray_flags::{PaperArgs, PaperItem};
use volray_paper::{Item, PaperError, Sizes};

pub fn run(args: &PaperArgs) -> Result<(), CliError> {
    let items: Vec<Item> = match args.what {
        PaperItem::Figure1a => vec![Item::Figure1a],
        PaperItem::Figure1b => vec![Item::Figure1b],
        PaperItem::Figure1c => vec![Item::Figure1c],
        PaperItem::Figure2a => vec![Item::Figure2a],
        PaperItem::Figure2b => vec![Item::Figure2b],
        PaperItem::Table1 => vec![Item::Table1],
        PaperItem::All => Item::ALL.to_vec(),
    };
    let sizes = if args.quick {
        Sizes::QUICK
    } else {
        Sizes::PAPER
    };
    let pool = thread_pool(args.threads)?;
    pool.install(|| volray_paper::make(&items, &args.out, &sizes, &mut |line| outln!("{line}")))
        .map_err(|e: PaperError| {
            if e.is_io_failure() {
                CliError::io(e.to_string())
            } else {
                CliError::input(e.to_string())
            }
        })?;
    Ok(())
}
