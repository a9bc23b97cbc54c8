//! `volray convert`'s flags: the input (as `render` reads it), the
//! output, and how an OME-Zarr output is laid out.

use super::input::InputArgs;
use clap::Args;
use std::path::PathBuf;

/// `volray convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    #[command(flatten)]
    pub input: InputArgs,

    /// The file to write, its format named by its extension: `.nrrd`
    /// (keeps spacing and origin), `.npy`, `.raw`, or `.zarr`/`.ome.zarr`
    /// (an OME-Zarr image, a directory, with its pyramid of levels);
    /// samples keep their type (u8, i8, u16, i16 or f32, as volray reads
    /// them).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,

    /// OME-Zarr output: Zarr v3 (OME-Zarr 0.5: chunks in shards, zstd) or
    /// Zarr v2 (OME-Zarr 0.4: chunks, blosc-zstd) [default: 3].
    #[arg(long, value_name = "2|3", value_parser = parse_zarr_version)]
    pub zarr_version: Option<u8>,

    /// OME-Zarr output: the side of a chunk, 2 to 1024 [default: 64];
    /// shards are 256 (a multiple of it), and levels are made down to the
    /// first that fits in one chunk.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(2..=1024))]
    pub chunk: Option<u16>,

    /// OME-Zarr output: the values are labels (a segmentation): lower
    /// levels take each 2x2x2 block's most common value, not its mean.
    #[arg(long)]
    pub labels: bool,
}

/// A `--zarr-version`: 2 or 3.
fn parse_zarr_version(text: &str) -> Result<u8, String> {
    match text.trim() {
        "2" => Ok(2),
        "3" => Ok(3),
        _ => Err(format!(
            "\"{text}\" is not a Zarr version: give 3 (OME-Zarr 0.5) or 2 (OME-Zarr 0.4)"
        )),
    }
}
