//! One hydrogen state `ψ_nlm(x, y, z) = R_nl(r) Y_lm(θ, φ)` (or its real
//! form `R_nl(r) S_lm(θ, φ)`), evaluated at Cartesian points in units of `a₀`.

use volray_core::glam::DVec3;

use super::angular::{Complex, SphericalHarmonic};
use super::radial::Radial;

/// A hydrogen eigenstate ready to evaluate: the radial and angular factors
/// with their constants precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct Orbital {
    radial: Radial,
    angular: SphericalHarmonic,
    real: bool,
}

impl Orbital {
    /// The state `(n, l, m)`, complex (`Y_lm`, Condon–Shortley phase) or real
    /// (`S_lm`, the chemists' p_x, d_xy, …). Errors name the rule broken.
    pub fn new(n: u32, l: u32, m: i32, real: bool) -> Result<Self, String> {
        Ok(Orbital {
            radial: Radial::new(n, l)?,
            angular: SphericalHarmonic::new(l, m)?,
            real,
        })
    }

    /// The radial factor.
    pub fn radial(&self) -> &Radial {
        &self.radial
    }

    /// The angular factor.
    pub fn angular(&self) -> &SphericalHarmonic {
        &self.angular
    }

    /// Whether this is the real orbital `R_nl S_lm`.
    pub fn is_real(&self) -> bool {
        self.real
    }

    /// `ψ(p)` in `a₀^(−3/2)` at `p` in `a₀` (imaginary part 0 for real
    /// orbitals). At the nucleus the direction is undefined but `ψ` is not:
    /// `R_n0(0) Y_00` for s states, 0 otherwise.
    pub fn psi(&self, p: DVec3) -> Complex {
        let r = p.length();
        let radial = self.radial.value(r);
        if radial == 0.0 {
            // Also where r overflowed to ∞ and the direction is undefined.
            return Complex::default();
        }
        if r == 0.0 {
            return if self.angular.l() == 0 {
                Complex::new(radial * self.angular.real_value(0.0, 0.0), 0.0)
            } else {
                Complex::default()
            };
        }
        if self.real {
            Complex::new(radial * self.angular.real_cartesian(p, r), 0.0)
        } else {
            self.angular.cartesian(p, r).scale(radial)
        }
    }

    /// `|ψ(p)|²` in `a₀^(−3)`.
    pub fn density(&self, p: DVec3) -> f64 {
        self.psi(p).norm_sqr()
    }
}
