//! Where `render` writes its image or animation, and at what bit depth.

use super::parse::parse_bit_depth;
use clap::Args;
use std::path::PathBuf;

/// The output file.
#[derive(Debug, Args)]
pub struct OutputArgs {
    /// Output image, written atomically (never half-written): PNG, or
    /// OpenEXR (32-bit float RGBA, unquantised) if the name ends in .exr.
    /// An animation (--turntable, several inputs) is an animated PNG
    /// (.png), a GIF (.gif) or numbered PNGs (a name with %03d or %d).
    #[arg(short, long, value_name = "OUT.png|OUT.exr|OUT.gif|OUT_%03d.png")]
    pub output: PathBuf,

    /// Bits per channel of a PNG.
    #[arg(long, value_name = "8|16", default_value = "8", value_parser = parse_bit_depth, allow_hyphen_values = true)]
    pub bit_depth: u8,
}
