//! `volray paper`'s flags: which figure or table, and where.

use clap::Args;
use std::path::PathBuf;

/// `volray paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// What to make: one figure, the table, or all of them.
    #[arg(value_enum, default_value = "all")]
    pub what: PaperItem,
    /// Output directory, created if missing; files in it are replaced
    /// atomically.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Reduced sizes for tests and CI: 30³ grids and 40² panels, 33³ clouds
    /// at 96², small Table 1 cases timed once. Not the paper's sizes.
    #[arg(long)]
    pub quick: bool,
    /// Worker threads [default: one per core]; Table 1 reports the count.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..), allow_hyphen_values = true)]
    pub threads: Option<u16>,
}

/// The items of `volray paper`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PaperItem {
    Figure1a,
    Figure1b,
    Figure1c,
    Figure2a,
    Figure2b,
    Table1,
    All,
}
