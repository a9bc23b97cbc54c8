//! A few Gaussian blobs, placed so that the volume has no mirror symmetry.
//!
//! On the cube `[−1, 1]³`:
//!
//! ```text
//! f(p) = Σ_b h_b · exp(−|p − c_b|² / (2 σ_b²))
//! ```
//!
//! over the four blobs of [`BLOBS`], of different centres `c_b`, widths `σ_b`
//! and heights `h_b` (1, 0.75, 0.55, 0.35). They are far apart, so the maximum
//! is ≈ 1 at the tallest blob's centre; values lie in `[0, ~1]`. Since no
//! axis mirror maps the set of blobs onto itself, a renderer that flips or
//! swaps axes produces a visibly different image.
//!
//! Sums of Gaussians are Blinn's "blobby" density functions: J. F. Blinn,
//! "A generalization of algebraic surface drawing", ACM Transactions on
//! Graphics 1(3), pp. 235–256, 1982.

use std::fmt;

use volray_core::Volume;
use volray_core::glam::DVec3;

use crate::{Args, DataError, SourceInfo, SourceSpec, grid};

/// The registry entry.
pub const INFO: SourceInfo = SourceInfo {
    name: "blobs",
    usage: "blobs[:N]",
    description: "four Gaussian blobs of different sizes and heights on [-1,1]^3, \
                  no mirror symmetry, values in [0,1], N points per side (default 64)",
    build,
};

fn build(spec: &SourceSpec) -> Result<Volume, DataError> {
    Blobs::from_spec(spec)?.volume()
}

/// One Gaussian: `height · exp(−|p − centre|² / (2 sigma²))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blob {
    pub centre: DVec3,
    pub sigma: f64,
    pub height: f64,
}

impl Blob {
    /// This blob's value at `p`.
    pub fn value(&self, p: DVec3) -> f64 {
        self.height * (-(p - self.centre).length_squared() / (2.0 * self.sigma * self.sigma)).exp()
    }
}

/// The blobs, tallest first.
pub const BLOBS: [Blob; 4] = [
    Blob {
        centre: DVec3::new(-0.35, -0.25, -0.3),
        sigma: 0.28,
        height: 1.0,
    },
    Blob {
        centre: DVec3::new(0.4, 0.3, -0.1),
        sigma: 0.18,
        height: 0.75,
    },
    Blob {
        centre: DVec3::new(0.1, -0.45, 0.5),
        sigma: 0.14,
        height: 0.55,
    },
    Blob {
        centre: DVec3::new(-0.25, 0.45, 0.4),
        sigma: 0.22,
        height: 0.35,
    },
];

/// `f(p)`, the sum of [`BLOBS`] at world position `p`.
pub fn density(p: DVec3) -> f64 {
    BLOBS.iter().map(|b| b.value(p)).sum()
}

/// The blobs sampled on `n³` points over `[−1, 1]³`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blobs {
    /// Points per side, 2..=1025.
    pub n: usize,
}

impl Default for Blobs {
    fn default() -> Self {
        Blobs { n: 64 }
    }
}

/// The canonical spec, e.g. `blobs:64`.
impl fmt::Display for Blobs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", INFO.name, self.n)
    }
}

impl Blobs {
    /// Reads `blobs[:N]` (or `blobs:n=N`) and checks it.
    pub fn from_spec(spec: &SourceSpec) -> Result<Self, DataError> {
        let args = Args::new(spec, &["n"], &[])?;
        let blobs = Blobs {
            n: args.usize_or("n", Self::default().n)?,
        };
        grid::check_points(blobs.n).map_err(DataError::invalid(spec))?;
        Ok(blobs)
    }

    /// The sampled volume: origin `(−1, −1, −1)`, spacing `2/(n − 1)`.
    pub fn volume(&self) -> Result<Volume, DataError> {
        grid::cube_volume(&self.to_string(), self.n, 1.0, density)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate;

    /// Largest difference between `v` and `v` mirrored along `axis`.
    fn mirror_difference(v: &Volume, axis: usize) -> f32 {
        let n = v.dims()[0];
        let mut worst = 0.0f32;
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let mut m = [i, j, k];
                    m[axis] = n - 1 - m[axis];
                    worst = worst.max((v.get(i, j, k) - v.get(m[0], m[1], m[2])).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn default_grid_and_range() {
        let v = generate("blobs").unwrap();
        assert_eq!(v.dims(), [64, 64, 64]);
        assert_eq!(v.origin(), DVec3::splat(-1.0));
        assert_eq!(v.spacing(), DVec3::splat(2.0 / 63.0));
        let (lo, hi) = v.value_range().unwrap();
        assert!((0.0..1e-6).contains(&lo), "min {lo}");
        assert!(hi > 0.9 && hi <= 1.1, "max {hi}");
        assert_eq!(v, Blobs::default().volume().unwrap());
    }

    #[test]
    fn no_mirror_symmetry() {
        let v = generate("blobs:33").unwrap();
        for axis in 0..3 {
            let d = mirror_difference(&v, axis);
            assert!(d > 0.3, "axis {axis}: mirrored data differs by only {d}");
        }
        // Nor symmetry under swapping two axes.
        let n = 33;
        let swapped = (0..n)
            .flat_map(|k| (0..n).flat_map(move |j| (0..n).map(move |i| (i, j, k))))
            .map(|(i, j, k)| (v.get(i, j, k) - v.get(j, i, k)).abs())
            .fold(0.0f32, f32::max);
        assert!(swapped > 0.3);
    }

    #[test]
    fn peaks_at_the_tallest_blob() {
        let top = BLOBS[0];
        let f = density(top.centre);
        assert!((f - top.height).abs() < 1e-3, "{f}");
        // One σ from the centre a lone Gaussian drops to e^(−1/2).
        let p = top.centre + DVec3::new(top.sigma, 0.0, 0.0);
        assert!((density(p) - (-0.5f64).exp()).abs() < 1e-3);
        // Far corners are essentially empty.
        assert!(density(DVec3::ONE) < 1e-6);
        assert!(density(-DVec3::ONE) < 1e-3);
        // Heights and widths all differ.
        for (a, b) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            assert_ne!(BLOBS[a].height, BLOBS[b].height);
            assert_ne!(BLOBS[a].sigma, BLOBS[b].sigma);
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert_eq!(
            generate("blobs:0").unwrap_err().to_string(),
            "blobs:0: grid must have at least 2 points per side, got 0"
        );
        assert!(matches!(
            generate("blobs:64,radius=1"),
            Err(DataError::UnknownKey { .. })
        ));
        assert!(matches!(
            generate("blobs:64,2"),
            Err(DataError::SurplusPositional { .. })
        ));
    }
}
