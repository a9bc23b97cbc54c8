//! `volray info`'s flags: the input, the histogram's bins, `--json`.

use super::input::InputArgs;
use clap::Args;

/// `volray info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// Histogram bins.
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=1000), allow_hyphen_values = true)]
    pub bins: u16,

    /// Print the description as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}
