//! `volray generate`'s flags: the hydrogen atom's quantum numbers and grid,
//! the fractal cloud's parameters, and the output file.

use clap::{Args, Subcommand};
use std::path::PathBuf;
use volray_data::fractal::FractalParams;

/// `volray generate`.
#[derive(Debug, Args)]
pub struct GenerateArgs {
    #[command(subcommand)]
    pub kind: GenerateKind,
}

#[derive(Debug, Subcommand)]
pub enum GenerateKind {
    /// The hydrogen-atom probability density |ψ_nlm|² (in a₀⁻³) on an
    /// N³ grid over [−R, R]³ (in a₀).
    Hydrogen(HydrogenArgs),
    /// A fractal cloud by 3-D midpoint displacement, post-processed as in
    /// the paper (ramp toward the boundary, threshold, negatives to 0).
    Fractal(FractalArgs),
}

#[derive(Debug, Args)]
pub struct HydrogenArgs {
    /// Principal quantum number, 1 to 12.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub n: u32,
    /// Orbital quantum number, 0 to n − 1.
    #[arg(long, value_name = "L", allow_hyphen_values = true)]
    pub l: u32,
    /// Magnetic quantum number, −l to l.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub m: i32,
    /// Points per side of the grid.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 50,
        allow_hyphen_values = true
    )]
    pub grid: usize,
    /// Half-width R of the cube [−R, R]³ in Bohr radii [default: the
    /// radius that holds 99.5% of the radial probability].
    #[arg(long, value_name = "R", allow_hyphen_values = true)]
    pub extent: Option<f64>,
    /// The real orbital chemists use (p_x, p_y, d_xy, ...: cos mφ for m > 0,
    /// sin |m|φ for m < 0) instead of the complex e^{imφ} one.
    #[arg(long)]
    pub real: bool,
    /// Output file: .nrrd (keeps spacing and origin), .npy or .raw
    /// (f32, little-endian, x fastest), written atomically.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct FractalArgs {
    /// Points per side: 2^k + 1 (3, 5, 9, ..., 1025).
    #[arg(long, value_name = "N", default_value_t = FractalParams::default().size, allow_hyphen_values = true)]
    pub size: usize,
    /// Fractal dimension D of the field's graph, 3 ≤ D < 4 (Hurst H = 4 − D).
    #[arg(long, value_name = "D", default_value_t = FractalParams::default().dimension, allow_hyphen_values = true)]
    pub dimension: f64,
    /// Standard deviation of the corner values (the coarsest displacements).
    #[arg(long, value_name = "SIGMA", default_value_t = FractalParams::default().sigma, allow_hyphen_values = true)]
    pub sigma: f64,
    /// Random seed: the same seed gives the same bytes on any machine.
    #[arg(long, value_name = "SEED", default_value_t = FractalParams::default().seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Post-processing: the fraction of the half width over which the
    /// field is ramped down to 0 at the boundary sphere (0 < R ≤ 1).
    #[arg(long, value_name = "R", default_value_t = FractalParams::default().ramp, allow_hyphen_values = true)]
    pub ramp: f64,
    /// Post-processing: subtracted from the field scaled to [0, 1] (after
    /// the ramp) before negatives are set to 0 (0 ≤ T < 1).
    #[arg(long, value_name = "T", default_value_t = FractalParams::default().threshold, allow_hyphen_values = true)]
    pub threshold: f64,
    /// Skip the post-processing: write the raw midpoint-displacement field.
    #[arg(long, conflicts_with_all = ["ramp", "threshold"])]
    pub raw_field: bool,
    /// Voss's successive random additions: displace every point at every
    /// level, for better statistics.
    #[arg(long)]
    pub random_additions: bool,
    /// Output file: .nrrd (keeps spacing and origin), .npy or .raw
    /// (f32, little-endian, x fastest), written atomically.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
}
