//! How big the reproduction is: the paper's grids and windows, or reduced
//! ones for tests and CI (`volray paper --quick`), which keep every
//! structure (21 panels, two clouds, four timed cases) at a fraction of
//! the cost.

use crate::table1::CaseSizes;

/// Grid and image sizes of every figure and of Table 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sizes {
    /// Points per side of the hydrogen densities (Figures 1a, 1b).
    pub hydrogen_grid: usize,
    /// Side of a Figure 1 panel, pixels.
    pub panel: usize,
    /// θ cells of a Figure 1c surface (φ has twice as many).
    pub surface_theta_steps: usize,
    /// Points per side of the Figure 2 clouds (2^k + 1).
    pub cloud_grid: usize,
    /// Side of a Figure 2 image, pixels.
    pub cloud_window: usize,
    /// Table 1's cases.
    pub table: CaseSizes,
    /// Timed runs per case and path in Table 1.
    pub runs: usize,
}

impl Sizes {
    /// The paper's: 50³ grids and 120² panels, 129³ clouds at 480²,
    /// Table 1's sizes, 5 timed runs.
    pub const PAPER: Sizes = Sizes {
        hydrogen_grid: 50,
        panel: 120,
        surface_theta_steps: crate::surfaces::THETA_STEPS,
        cloud_grid: 129,
        cloud_window: 480,
        table: CaseSizes::PAPER,
        runs: 5,
    };

    /// Reduced, for tests: 30³ grids and 40² panels (wide enough for the
    /// labels), 33³ clouds at 96², small timed cases, one timed run.
    pub const QUICK: Sizes = Sizes {
        hydrogen_grid: 30,
        panel: 40,
        surface_theta_steps: 24,
        cloud_grid: 33,
        cloud_window: 96,
        table: CaseSizes {
            hydrogen: (20, 40),
            fractal: (17, 60),
            large_fractal: (33, 120),
        },
        runs: 1,
    };

    /// Whether these are not the paper's sizes.
    pub fn is_reduced(&self) -> bool {
        *self != Sizes::PAPER
    }
}
