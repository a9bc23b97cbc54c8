//! `volray convert`'s flags: the input (as `render` reads it) and the
//! output file.

use super::input::InputArgs;
use clap::Args;
use std::path::PathBuf;

/// `volray convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// The file to write, its format named by its extension: `.nrrd`
    /// (keeps spacing and origin), `.npy` or `.raw`; samples keep their
    /// type (u8, i8, u16, i16 or f32, as volray reads them).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
}
