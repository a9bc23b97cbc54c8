//! A density peaked on a torus around the z axis.
//!
//! On the cube `[−1, 1]³`, with major radius `R`, minor radius `r`, and
//! `d` the distance from `p` to the ring of radius `R` in the plane z = 0,
//!
//! ```text
//! d(p) = √((√(x² + y²) − R)² + z²)
//! f(p) = exp(−d² / (2σ²)),  σ = r/2
//! ```
//!
//! so `f = 1` on the ring, `e^(−1/2) ≈ 0.61` at `d = r/2` and
//! `e^(−2) ≈ 0.14` at `d = r`, the surface of the solid torus. The volume is
//! symmetric under rotation about z and under every axis mirror; its hole
//! makes it a test for isosurface topology and for depth ordering. `d` is
//! the torus distance function of J. C. Hart, "Sphere tracing: a geometric
//! method for the antialiased ray tracing of implicit surfaces", The Visual
//! Computer 12(10), pp. 527–545, 1996.

use std::fmt;

use volray_core::Volume;
use volray_core::glam::DVec3;

use crate::{Args, DataError, SourceInfo, SourceSpec, grid};

/// The registry entry.
pub const INFO: SourceInfo = SourceInfo {
    name: "torus",
    usage: "torus[:N][,major=R][,minor=r]",
    description: "Gaussian density peaked on a ring of radius R (default 0.6) around the z axis \
                  in [-1,1]^3, tube radius r (default 0.25) at 2σ, N points per side (default 64)",
    build,
};

fn build(spec: &SourceSpec) -> Result<Volume, DataError> {
    Torus::from_spec(spec)?.volume()
}

/// The torus density sampled on `n³` points over `[−1, 1]³`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Torus {
    /// Points per side, 2..=1025.
    pub n: usize,
    /// Radius `R` of the ring the density peaks on, ≥ 0.
    pub major: f64,
    /// Tube radius `r` = 2σ, > 0.
    pub minor: f64,
}

impl Default for Torus {
    fn default() -> Self {
        Torus {
            n: 64,
            major: 0.6,
            minor: 0.25,
        }
    }
}

/// The canonical spec, e.g. `torus:64,major=0.6,minor=0.25`.
impl fmt::Display for Torus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{},major={},minor={}",
            INFO.name, self.n, self.major, self.minor
        )
    }
}

impl Torus {
    /// Reads `torus[:N][,major=R][,minor=r]` (or `n=N`) and checks it.
    pub fn from_spec(spec: &SourceSpec) -> Result<Self, DataError> {
        let args = Args::new(spec, &["n"], &["major", "minor"])?;
        let d = Self::default();
        let torus = Torus {
            n: args.usize_or("n", d.n)?,
            major: args.f64_or("major", d.major)?,
            minor: args.f64_or("minor", d.minor)?,
        };
        torus.check().map_err(DataError::invalid(spec))?;
        Ok(torus)
    }

    fn check(&self) -> Result<(), String> {
        grid::check_points(self.n)?;
        if !(self.major.is_finite() && self.major >= 0.0) {
            return Err(format!(
                "major radius must be finite and >= 0, got {}",
                self.major
            ));
        }
        if !(self.minor.is_finite() && self.minor > 0.0) {
            return Err(format!(
                "minor radius must be positive and finite, got {}",
                self.minor
            ));
        }
        Ok(())
    }

    /// `d(p)`, the distance from `p` to the ring.
    pub fn ring_distance(&self, p: DVec3) -> f64 {
        (p.x.hypot(p.y) - self.major).hypot(p.z)
    }

    /// `f(p)` at world position `p`.
    pub fn density(&self, p: DVec3) -> f64 {
        let d = self.ring_distance(p);
        let sigma = 0.5 * self.minor;
        (-d * d / (2.0 * sigma * sigma)).exp()
    }

    /// The sampled volume: origin `(−1, −1, −1)`, spacing `2/(n − 1)`.
    pub fn volume(&self) -> Result<Volume, DataError> {
        let spec = self.to_string();
        self.check().map_err(DataError::invalid(&spec))?;
        grid::cube_volume(&spec, self.n, 1.0, |p| self.density(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate;

    #[test]
    fn closed_form_values() {
        let t = Torus::default();
        for p in [
            DVec3::new(0.6, 0.0, 0.0),
            DVec3::new(0.0, -0.6, 0.0),
            DVec3::new(0.36, 0.48, 0.0),
        ] {
            assert!((t.density(p) - 1.0).abs() < 1e-12, "{p}");
        }
        // d = r/2 = σ: e^(−1/2); d = r: e^(−2), radially or vertically.
        assert!((t.density(DVec3::new(0.725, 0.0, 0.0)) - (-0.5f64).exp()).abs() < 1e-12);
        assert!((t.density(DVec3::new(0.0, 0.6, 0.25)) - (-2.0f64).exp()).abs() < 1e-12);
        assert!((t.density(DVec3::new(-0.35, 0.0, 0.0)) - (-2.0f64).exp()).abs() < 1e-12);
        // The hole: d = R at the centre, e^(−R²/(2σ²)) = e^(−11.52).
        assert!((t.density(DVec3::ZERO) - (-11.52f64).exp()).abs() < 1e-15);
        assert!(t.density(DVec3::ZERO) < 1e-4);
    }

    #[test]
    fn volume_peaks_on_the_ring_and_is_hollow() {
        // n = 51: spacing 0.04, so (35, 25, 25) is at (0.4, 0, 0).
        let v = generate("torus:51,major=0.4,minor=0.2").unwrap();
        assert_eq!(v.dims(), [51, 51, 51]);
        assert!((v.get(35, 25, 25) - 1.0).abs() < 1e-6);
        assert!((v.get(25, 15, 25) - 1.0).abs() < 1e-6);
        assert!(v.get(25, 25, 25) < 1e-3);
        // Ring at 0.4, σ = 0.1: on the z axis at z = ±0.2, d = √0.2.
        let expected = (-0.2f64 / 0.02).exp();
        assert!((v.get(25, 25, 30) as f64 - expected).abs() < 1e-6);
        // Mirror symmetric and invariant under swapping x and y.
        let n = 51;
        for (i, j, k) in [(3, 17, 40), (35, 25, 25), (10, 30, 22), (0, 50, 12)] {
            let f = v.get(i, j, k);
            assert_eq!(f, v.get(n - 1 - i, j, k));
            assert_eq!(f, v.get(i, n - 1 - j, k));
            assert_eq!(f, v.get(i, j, n - 1 - k));
            assert!((f - v.get(j, i, k)).abs() < 1e-6);
        }
        let (lo, hi) = v.value_range().unwrap();
        assert!(lo >= 0.0 && hi <= 1.0 && hi > 0.999);
    }

    #[test]
    fn rejects_bad_parameters() {
        let err = |s: &str| generate(s).unwrap_err().to_string();
        assert_eq!(
            err("torus:64,minor=-0.1"),
            "torus:64,minor=-0.1: minor radius must be positive and finite, got -0.1"
        );
        assert_eq!(
            err("torus:major=-1"),
            "torus:major=-1: major radius must be finite and >= 0, got -1"
        );
        assert_eq!(
            err("torus:minor=nan"),
            "torus:minor=nan: minor must be a finite number, got `nan`"
        );
        assert!(generate("torus:9,major=0").is_ok());
    }
}
