//! The Marschner–Lobb test signal.
//!
//! S. R. Marschner and R. J. Lobb, "An evaluation of reconstruction filters
//! for volume rendering", Proc. IEEE Visualization '94, pp. 100–107, 1994.
//!
//! On the cube `[−1, 1]³`:
//!
//! ```text
//! ρ(x, y, z) = (1 − sin(πz/2) + α·(1 + ρ_r(√(x² + y²)))) / (2·(1 + α))
//! ρ_r(r)     = cos(2π·f_M·cos(πr/2))
//! ```
//!
//! with `f_M = 6` and `α = 0.25` in the paper. For `α ≥ 0`, ρ lies in
//! `[0, 1]`. The signal has much of its energy near the Nyquist rate of the
//! paper's 41³ grid (spacing 0.05), so it exposes reconstruction and
//! gradient errors: the rings in an isosurface at ρ = 0.5 should be smooth
//! and evenly spaced.

use std::f64::consts::PI;
use std::fmt;

use volray_core::Volume;
use volray_core::glam::DVec3;

use crate::{Args, DataError, SourceInfo, SourceSpec, grid};

/// The registry entry.
pub const INFO: SourceInfo = SourceInfo {
    name: "marschner-lobb",
    usage: "marschner-lobb[:N][,fm=F][,alpha=A]",
    description: "Marschner–Lobb test signal on [-1,1]^3, N points per side \
                  (default 41, the paper's grid), fm=6, alpha=0.25",
    build,
};

fn build(spec: &SourceSpec) -> Result<Volume, DataError> {
    MarschnerLobb::from_spec(spec)?.volume()
}

/// The Marschner–Lobb signal sampled on `n³` points over `[−1, 1]³`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarschnerLobb {
    /// Points per side, 2..=1025.
    pub n: usize,
    /// Frequency of the radial ripples, `f_M`, ≥ 0.
    pub fm: f64,
    /// Weight of the radial term, `α`, ≥ 0.
    pub alpha: f64,
}

impl Default for MarschnerLobb {
    /// The paper's setting: 41³ points, `f_M = 6`, `α = 0.25`.
    fn default() -> Self {
        MarschnerLobb {
            n: 41,
            fm: 6.0,
            alpha: 0.25,
        }
    }
}

/// The canonical spec, e.g. `marschner-lobb:41,fm=6,alpha=0.25`.
impl fmt::Display for MarschnerLobb {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{},fm={},alpha={}",
            INFO.name, self.n, self.fm, self.alpha
        )
    }
}

impl MarschnerLobb {
    /// Reads `marschner-lobb[:N][,fm=F][,alpha=A]` (`N` may also be given as
    /// `n=N`) and checks the values.
    pub fn from_spec(spec: &SourceSpec) -> Result<Self, DataError> {
        let args = Args::new(spec, &["n"], &["fm", "alpha"])?;
        let d = Self::default();
        let ml = MarschnerLobb {
            n: args.usize_or("n", d.n)?,
            fm: args.f64_or("fm", d.fm)?,
            alpha: args.f64_or("alpha", d.alpha)?,
        };
        ml.check().map_err(DataError::invalid(spec))?;
        Ok(ml)
    }

    fn check(&self) -> Result<(), String> {
        grid::check_points(self.n)?;
        if !(self.fm.is_finite() && self.fm >= 0.0) {
            return Err(format!("fm must be finite and >= 0, got {}", self.fm));
        }
        if !(self.alpha.is_finite() && self.alpha >= 0.0) {
            return Err(format!("alpha must be finite and >= 0, got {}", self.alpha));
        }
        Ok(())
    }

    /// The radial term `ρ_r(r) = cos(2π·f_M·cos(πr/2))`.
    pub fn radial(&self, r: f64) -> f64 {
        (2.0 * PI * self.fm * (PI * r / 2.0).cos()).cos()
    }

    /// `ρ(p)`, the exact signal at world position `p`.
    pub fn density(&self, p: DVec3) -> f64 {
        let r = p.x.hypot(p.y);
        (1.0 - (PI * p.z / 2.0).sin() + self.alpha * (1.0 + self.radial(r)))
            / (2.0 * (1.0 + self.alpha))
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

    /// The formula written out independently of [`MarschnerLobb::density`].
    fn rho(x: f64, y: f64, z: f64, fm: f64, alpha: f64) -> f64 {
        let r = (x * x + y * y).sqrt();
        let rho_r = (2.0 * PI * fm * (PI * r / 2.0).cos()).cos();
        (1.0 - (PI * z / 2.0).sin() + alpha * (1.0 + rho_r)) / (2.0 * (1.0 + alpha))
    }

    /// A small deterministic generator (SplitMix64) for picking voxels.
    fn splitmix(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    #[test]
    fn closed_form_values() {
        let ml = MarschnerLobb::default();
        // Centre: ρ_r(0) = cos(2π·6) = 1, sin 0 = 0 → (1 + 2α)/(2(1 + α)) = 0.6.
        assert!((ml.radial(0.0) - 1.0).abs() < 1e-12);
        assert!((ml.density(DVec3::ZERO) - 0.6).abs() < 1e-12);
        // Top of the z axis: sin(π/2) = 1 → 2α/(2(1 + α)) = 0.2.
        assert!((ml.density(DVec3::Z) - 0.2).abs() < 1e-12);
        // Bottom: sin(−π/2) = −1 → (2 + 2α)/(2(1 + α)) = 1.
        assert!((ml.density(-DVec3::Z) - 1.0).abs() < 1e-12);
        // r = 1: cos(π/2) = 0 → ρ_r = 1, so at z = 0 the value is again 0.6.
        assert!((ml.density(DVec3::X) - 0.6).abs() < 1e-12);
        assert!((ml.density(DVec3::new(0.6, -0.8, 0.0)) - 0.6).abs() < 1e-12);
        // cos(πr/2) = 1/12 makes 2π·6·(1/12) = π, so ρ_r = −1 and the radial
        // term vanishes: ρ = (1 − sin(πz/2))/(2(1 + α)) = 0.4 at z = 0.
        let r = 2.0 / PI * (1.0f64 / 12.0).acos();
        assert!((ml.radial(r) + 1.0).abs() < 1e-12);
        assert!((ml.density(DVec3::new(0.0, r, 0.0)) - 0.4).abs() < 1e-12);
        // Other parameters: α = 0 drops the radial term entirely.
        let flat = MarschnerLobb { alpha: 0.0, ..ml };
        assert!(
            (flat.density(DVec3::new(0.3, 0.2, 0.5)) - (1.0 - (PI / 4.0).sin()) / 2.0).abs()
                < 1e-12
        );
        let p = DVec3::new(0.3, -0.45, 0.1);
        assert!((ml.density(p) - rho(p.x, p.y, p.z, 6.0, 0.25)).abs() < 1e-15);
    }

    #[test]
    fn default_grid_is_the_papers() {
        let v = generate("marschner-lobb").unwrap();
        assert_eq!(v.dims(), [41, 41, 41]);
        assert_eq!(v.spacing(), DVec3::splat(0.05));
        assert_eq!(v.origin(), DVec3::splat(-1.0));
        let (lo, hi) = v.bounds();
        assert_eq!(lo, DVec3::splat(-1.0));
        assert!((hi - DVec3::ONE).abs().max_element() < 1e-12);
        assert_eq!(v, generate("marschner-lobb:41,fm=6,alpha=0.25").unwrap());
        assert_eq!(v, generate("marschner-lobb:n=41").unwrap());
        assert_eq!(v, MarschnerLobb::default().volume().unwrap());
        // Grid points with closed forms: centre (20, 20, 20), the z-axis ends.
        assert!((v.get(20, 20, 20) - 0.6).abs() < 1e-6);
        assert!((v.get(20, 20, 40) - 0.2).abs() < 1e-6);
        assert!((v.get(20, 20, 0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn voxels_match_the_formula_at_their_positions() {
        let cases = [(41, 6.0, 0.25), (33, 3.0, 1.0), (64, 6.5, 0.0)];
        for (n, fm, alpha) in cases {
            let v = generate(&format!("marschner-lobb:{n},fm={fm},alpha={alpha}")).unwrap();
            assert_eq!(v.dims(), [n, n, n]);
            assert_eq!(v.spacing(), DVec3::splat(2.0 / (n - 1) as f64));
            let mut state = n as u64;
            for _ in 0..200 {
                let i = (splitmix(&mut state) % n as u64) as usize;
                let j = (splitmix(&mut state) % n as u64) as usize;
                let k = (splitmix(&mut state) % n as u64) as usize;
                let p = v.world_position(i, j, k);
                let expected = rho(p.x, p.y, p.z, fm, alpha);
                let got = v.get(i, j, k) as f64;
                assert!(
                    (got - expected).abs() < 1e-6,
                    "n={n} ({i},{j},{k}) at {p}: {got} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn values_lie_in_unit_interval() {
        for spec in [
            "marschner-lobb",
            "marschner-lobb:64,alpha=3",
            "marschner-lobb:20,fm=0",
        ] {
            let v = generate(spec).unwrap();
            assert_eq!(v.count_non_finite(), 0);
            let (lo, hi) = v.value_range().unwrap();
            assert!(lo >= 0.0 && hi <= 1.0, "{spec}: {lo}..{hi}");
            assert!(hi - lo > 0.5, "{spec}: {lo}..{hi}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        let err = |s: &str| generate(s).unwrap_err().to_string();
        assert_eq!(
            err("marschner-lobb:1"),
            "marschner-lobb:1: grid must have at least 2 points per side, got 1"
        );
        assert_eq!(
            err("marschner-lobb:1026"),
            "marschner-lobb:1026: grid must have at most 1025 points per side, got 1026"
        );
        assert_eq!(
            err("marschner-lobb:forty"),
            "marschner-lobb:forty: n must be a non-negative integer, got `forty`"
        );
        assert_eq!(
            err("marschner-lobb:41,alpha=-1"),
            "marschner-lobb:41,alpha=-1: alpha must be finite and >= 0, got -1"
        );
        assert_eq!(
            err("marschner-lobb:41,fm=-6"),
            "marschner-lobb:41,fm=-6: fm must be finite and >= 0, got -6"
        );
        assert_eq!(
            err("marschner-lobb:41,fm=NaN"),
            "marschner-lobb:41,fm=NaN: fm must be a finite number, got `NaN`"
        );
        assert_eq!(
            err("marschner-lobb:41,freq=6"),
            "marschner-lobb:41,freq=6: unknown parameter `freq`; marschner-lobb takes n, fm, alpha"
        );
        assert_eq!(
            err("marschner-lobb:41,6"),
            "marschner-lobb:41,6: surplus positional argument `6`; marschner-lobb takes at most 1 (n)"
        );
        // Programmatic use is checked too, naming the canonical spec.
        let bad = MarschnerLobb {
            alpha: f64::NAN,
            ..Default::default()
        };
        assert_eq!(
            bad.volume().unwrap_err().to_string(),
            "marschner-lobb:41,fm=6,alpha=NaN: alpha must be finite and >= 0, got NaN"
        );
    }
}
