//! The default half width of the sampling cube: the radius that holds 99.5%
//! of the radial probability, in place of the paper's trial and error.
//!
//! The probability of finding the electron beyond `r = nX/2` is
//!
//! ```text
//! Q(X) = ∫_r^∞ s² R_nl(s)² ds = (n/2)³ e^(−X) ∫₀^∞ (X + t)^(2l+2) P(X + t)² e^(−t) dt,
//! ```
//!
//! with `R_nl = e^(−ρ/2) ρ^l P(ρ)`, `P = N_nl ₁F₁(−(n − l − 1); 2l + 2; ρ)` a
//! polynomial of degree `n − l − 1`, and the substitution `ρ = X + t`. The
//! integrand is a polynomial of degree `2n` times `e^(−t)`, so the
//! [`GaussLaguerre`] rule with `MAX_N + 1` nodes integrates it **exactly**
//! (up to rounding): this is the exact CDF, not an approximation. Every
//! quadrature term is positive, so nothing cancels and `Q` is accurate to a
//! few units of rounding at any `X` (the tests check `Q(0) = 1`, i.e. the
//! normalisation, to 1e−13 for every state). `Q` decreases strictly in `X`;
//! the radius with `Q = 0.005` is found by bisection to full `f64` precision.
//!
//! The cube `[−R, R]³` contains the ball of radius `R`, so it holds at least
//! [`CONTAINED_PROBABILITY`] of `|ψ|²` for every `m`.

use super::gauss_laguerre::GaussLaguerre;
use super::radial::{MAX_N, Radial};

/// The share of the probability the default cube holds at least.
pub const CONTAINED_PROBABILITY: f64 = 0.995;

/// The probability `∫_r^∞ s² R_nl(s)² ds` beyond radius `r ≥ 0` (in `a₀`):
/// 1 at `r = 0` (the normalisation), decreasing to 0.
pub fn radial_tail(radial: &Radial, rule: &GaussLaguerre, r: f64) -> f64 {
    let n = f64::from(radial.n());
    let x = 2.0 * r / n;
    let power = 2 * radial.l() as i32 + 2;
    let integral = rule.integrate(|t| {
        let rho = x + t;
        let p = radial.polynomial(rho);
        rho.powi(power) * p * p
    });
    (n / 2.0).powi(3) * (-x).exp() * integral
}

/// The rule that integrates `radial_tail`'s polynomial of degree ≤ `2 MAX_N`
/// exactly.
pub fn tail_rule() -> GaussLaguerre {
    GaussLaguerre::new(MAX_N as usize + 1)
}

/// The radius `R` (in `a₀`) with `∫₀^R r² R_nl(r)² dr = 0.995`, the default
/// half width of the sampling cube for state `(n, l)`.
///
/// # Panics
///
/// If `(n, l)` is not a valid state (`1 ≤ n ≤ 12`, `0 ≤ l < n`): check with
/// `HydrogenParams::validate` first, or use
/// `HydrogenParams::resolved_extent`.
pub fn default_extent(n: u32, l: u32) -> f64 {
    enclosing_radius(n, l, CONTAINED_PROBABILITY)
}

/// The radius (in `a₀`) inside which state `(n, l)` has the share `share`
/// (0 < share < 1) of its radial probability: bisection on the exact
/// radial tail. Panics on an invalid `(n, l)`, as [`default_extent`].
pub fn enclosing_radius(n: u32, l: u32, share: f64) -> f64 {
    let radial = Radial::new(n, l).unwrap_or_else(|e| panic!("enclosing_radius: {e}"));
    let rule = tail_rule();
    let target = 1.0 - share;
    let tail = |r: f64| radial_tail(&radial, &rule, r);
    // The mean radius is n²(3 − l(l + 1)/n²)/2 ≤ 1.5 n²; grow from there.
    let mut hi = 1.5 * f64::from(n * n);
    let mut lo = 0.0;
    while tail(hi) > target {
        lo = hi;
        hi *= 2.0;
    }
    // Bisection until the bracket stops shrinking in f64.
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return hi;
        }
        if tail(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_at_zero_is_the_normalisation_for_every_state() {
        let rule = tail_rule();
        for n in 1..=MAX_N {
            for l in 0..n {
                let radial = Radial::new(n, l).unwrap();
                let q = radial_tail(&radial, &rule, 0.0);
                assert!((q - 1.0).abs() < 1e-13, "n={n} l={l}: {q}");
            }
        }
    }

    #[test]
    fn closed_form_for_1s() {
        // 1s: Q(r) = e^(−2r)(1 + 2r + 2r²); Q = 0.005 at r = 4.63687…
        let radial = Radial::new(1, 0).unwrap();
        let rule = tail_rule();
        for r in [0.3f64, 1.0, 2.5, 6.0, 15.0] {
            let want = (-2.0 * r).exp() * (1.0 + 2.0 * r + 2.0 * r * r);
            let got = radial_tail(&radial, &rule, r);
            assert!((got - want).abs() <= 1e-14 * want, "{r}: {got} vs {want}");
        }
        let r = default_extent(1, 0);
        let q = (-2.0 * r).exp() * (1.0 + 2.0 * r + 2.0 * r * r);
        assert!((q - 0.005).abs() < 1e-15, "{r}: {q}");
        assert!((r - 4.636_896).abs() < 1e-6, "{r}");
    }

    #[test]
    fn tail_matches_simpson_quadrature_of_the_radial_function() {
        // An independent check: composite Simpson on r² R_nl² from r to far
        // out, with R_nl from Radial::value.
        let rule = tail_rule();
        for (n, l) in [(3, 1), (6, 2), (9, 0), (12, 5)] {
            let radial = Radial::new(n, l).unwrap();
            let r0 = default_extent(n, l);
            let far = 4.0 * r0;
            let steps = 20_000;
            let h = (far - r0) / steps as f64;
            let f = |r: f64| r * r * radial.value(r).powi(2);
            let mut simpson = f(r0) + f(far);
            for i in 1..steps {
                simpson += f(r0 + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            simpson *= h / 3.0;
            let q = radial_tail(&radial, &rule, r0);
            assert!((q - 0.005).abs() < 1e-14, "{n},{l}: {q}");
            assert!((simpson - q).abs() < 1e-10, "{n},{l}: {simpson} vs {q}");
        }
    }

    #[test]
    fn extents_grow_with_n_and_shrink_with_l() {
        for n in 2..=MAX_N {
            assert!(default_extent(n, 0) > default_extent(n - 1, 0));
            for l in 1..n {
                assert!(default_extent(n, l) < default_extent(n, l - 1), "{n},{l}");
            }
        }
    }

    #[test]
    #[should_panic(expected = "l must satisfy 0 <= l < n = 2, got l = 2")]
    fn default_extent_panics_on_invalid_states() {
        default_extent(2, 2);
    }
}
