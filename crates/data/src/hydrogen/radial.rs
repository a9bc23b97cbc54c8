//! The radial part `R_nl(r)` of the hydrogen wavefunction, normalised so that
//! `∫₀^∞ r² R_nl(r)² dr = 1`, in units of the Bohr radius `a₀` (`r` in `a₀`,
//! `R_nl` in `a₀^(−3/2)`).
//!
//! # Formula (the paper, errata 2)
//!
//! ```text
//! R_nl(r) = N_nl · e^(−ρ/2) · ρ^l · ₁F₁(−(n − l − 1); 2l + 2; ρ),   ρ = 2r/(n a₀)
//! ₁F₁(a; b; ρ) = Σ_j (a)_j / ((b)_j j!) · ρ^j                      (the paper's F(a | b | ρ))
//! N_nl = (2/n)^(3/2) · √((n + l)! / (2n (n − l − 1)!)) / (2l + 1)!
//! ```
//!
//! `(a)_j` is the rising factorial. With `a = −k`, `k = n − l − 1`, the series
//! stops after `k + 1` terms: it is the associated Laguerre polynomial
//! `L_k^(2l+1)(ρ) = C(n + l, k) · ₁F₁(−k; 2l + 2; ρ)` (Abramowitz & Stegun
//! 22.5.54), and `N_nl` is the textbook constant
//! `(2/n)^(3/2) √((n − l − 1)!/(2n (n + l)!))` of `L_k^(2l+1)` (e.g. Griffiths,
//! *Introduction to Quantum Mechanics*, eq. 4.89, with the modern Laguerre
//! normalisation) times that binomial. Each term comes from the one before by
//! the ratio `(j − k) ρ / ((b + j)(j + 1))`, so no factorial is ever formed;
//! the constants are exact integer products (they fit a `u128` for n ≤ 12)
//! followed by one square root and one division.
//!
//! # Where the series loses precision, and what replaces it there
//!
//! The terms alternate in sign. Summing them in `f64` commits a rounding
//! error of about `k·u·Σ|t_j|` (`u = 2⁻⁵³`), while the value is `|Σ t_j|`, so
//! the ratio `Σ|t_j| / |Σ t_j|` is the factor by which rounding is
//! amplified. Inside the oscillatory region (`ρ` below about `4k + 2b`,
//! where the polynomial has its `k` zeros) that ratio grows with `ρ` far
//! beyond what the polynomial's envelope explains. Measured against the same
//! series summed in double-double arithmetic (`tests/hydrogen_precision.rs`;
//! its ignored `precision_study` test prints the table), over `ρ` from 0 to
//! the corner of the default cube, worst case over `l`:
//!
//! ```text
//!  n | series: error / max|R|   error / |R|*  | recurrence: / max|R|   / |R|*
//!  3 |          1.4e−16          3.4e−14      |             1.4e−16    5.1e−15
//!  6 |          2.0e−15          5.3e−13      |             8.1e−16    1.7e−13
//!  8 |          1.6e−14          8.2e−12      |             1.3e−15    4.1e−14
//! 10 |          9.0e−14          3.6e−11      |             1.7e−15    1.7e−13
//! 12 |          9.6e−13          2.1e−10      |             2.8e−15    3.8e−13
//!                                    (* where |R| ≥ 1e−3 max|R|, i.e. |ψ|² ≥ 1e−6 of its maximum)
//! ```
//!
//! So the series is exact to rounding for n ≤ 5 and loses up to three
//! digits by n = 12, while the three-term recurrence of the Laguerre
//! polynomials (A&S 22.7.12),
//!
//! ```text
//! (j + 1) L_(j+1)^α(ρ) = (2j + 1 + α − ρ) L_j^α(ρ) − (j + α) L_(j−1)^α(ρ),
//! ```
//!
//! run upwards from `L_0 = 1`, `L_1 = 1 + α − ρ`, stays within a few units
//! of rounding of the envelope for every n ≤ 12 (the polynomial is the
//! dominant solution of the recurrence; errors grow only linearly in `j`).
//! [`Radial::polynomial`] therefore sums the paper's series term by term
//! and keeps it wherever the measured amplification `Σ|t_j| / |Σ t_j|` is
//! at most [`SERIES_MAX_CANCELLATION`] (at most one decimal digit lost);
//! elsewhere — near the radial nodes, and for n ≳ 6 over most of the
//! oscillatory region — it evaluates the same polynomial by the recurrence.
//! The result is within 2.3e−15 of `max|R_nl|` for every state (the tests
//! hold it below 4e−15), i.e. as good as the recurrence alone.

/// The largest principal quantum number supported: the paper's states and
/// the range over which the precision of every method here was verified.
pub const MAX_N: u32 = 12;

/// Beyond `ρ = 2r/n` this large, `R_nl` underflows `f64` for every n ≤ 12
/// (`e^(−ρ/2) ρ^(n−1)` < 1e−390 at ρ = 2000), so [`Radial::value`] returns 0
/// there rather than risk `∞ · 0` from the growing polynomial.
pub const RHO_CUTOFF: f64 = 2000.0;

/// The series is kept where the sum of its terms' magnitudes is at most this
/// many times the magnitude of their sum (at most about one decimal digit
/// lost to cancellation); elsewhere the recurrence is used. 100 or 1000
/// would keep the series more often at 2× or 10× the error (module docs).
pub const SERIES_MAX_CANCELLATION: f64 = 10.0;

/// A sum of an alternating series, with the sum of its terms' magnitudes,
/// which bounds how much rounding the cancellation amplified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeriesSum {
    /// `Σ t_j`.
    pub value: f64,
    /// `Σ |t_j|`.
    pub abs_sum: f64,
}

impl SeriesSum {
    /// `Σ|t_j| / |Σ t_j|`: 1 without cancellation, infinite at a zero.
    pub fn amplification(&self) -> f64 {
        self.abs_sum / self.value.abs()
    }
}

/// The terminating confluent hypergeometric series `₁F₁(−k; b; x)` (the
/// paper's `F(−k | b | x)`), summed term by term with each term obtained
/// from the previous one by the ratio `(j − k) x / ((b + j)(j + 1))`.
pub fn hypergeometric_1f1(k: u32, b: f64, x: f64) -> SeriesSum {
    let mut term = 1.0;
    let mut sum = SeriesSum {
        value: 1.0,
        abs_sum: 1.0,
    };
    for j in 0..k {
        let j = f64::from(j);
        term *= (j - f64::from(k)) * x / ((b + j) * (j + 1.0));
        sum.value += term;
        sum.abs_sum += term.abs();
    }
    sum
}

/// The associated Laguerre polynomial `L_k^α(x)` by the upward three-term
/// recurrence (A&S 22.7.12), the stable method.
pub fn laguerre(k: u32, alpha: f64, x: f64) -> f64 {
    let mut previous = 1.0;
    if k == 0 {
        return previous;
    }
    let mut current = 1.0 + alpha - x;
    for j in 1..k {
        let j = f64::from(j);
        let next = ((2.0 * j + 1.0 + alpha - x) * current - (j + alpha) * previous) / (j + 1.0);
        previous = current;
        current = next;
    }
    current
}

/// Checks `1 ≤ n ≤ MAX_N` and `0 ≤ l < n`, returning the rule broken (wide
/// integers, so that values from a spec are checked before narrowing).
pub fn check_n_l(n: i64, l: i64) -> Result<(), String> {
    if !(1..=i64::from(MAX_N)).contains(&n) {
        return Err(format!("n must satisfy 1 <= n <= {MAX_N}, got n = {n}"));
    }
    if !(0..n).contains(&l) {
        return Err(format!("l must satisfy 0 <= l < n = {n}, got l = {l}"));
    }
    Ok(())
}

/// `a · (a + 1) ⋯ b` in exact integer arithmetic (1 for an empty range).
fn product(a: u32, b: u32) -> u128 {
    (a..=b).fold(1u128, |p, i| {
        p.checked_mul(u128::from(i))
            .expect("products of at most 2n − 1 integers ≤ 2n fit u128 for n ≤ MAX_N")
    })
}

/// `R_nl` for one `(n, l)`, with its constants precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct Radial {
    n: u32,
    l: u32,
    /// `k = n − l − 1`, the polynomial's degree and the number of nodes.
    k: u32,
    /// Ratios `(j − k)/((b + j)(j + 1))` between successive series terms.
    ratios: Vec<f64>,
    /// `N_nl`, the constant in front of the `₁F₁` form.
    norm_series: f64,
    /// `N_nl / C(n + l, k)`, the constant in front of `L_k^(2l+1)`.
    norm_laguerre: f64,
}

impl Radial {
    /// The radial function of `(n, l)`; errors name the rule broken
    /// (`1 ≤ n ≤ 12`, `0 ≤ l < n`).
    pub fn new(n: u32, l: u32) -> Result<Self, String> {
        check_n_l(n.into(), l.into())?;
        let k = n - l - 1;
        let b = f64::from(2 * l + 2);
        let ratios = (0..k)
            .map(|j| {
                let j = f64::from(j);
                (j - f64::from(k)) / ((b + j) * (j + 1.0))
            })
            .collect();
        // (n + l)!/(n − l − 1)! = (k + 1)(k + 2)⋯(n + l), and (2l + 1)!.
        let rising = product(k + 1, n + l) as f64;
        let factorial = product(1, 2 * l + 1) as f64;
        let nf = f64::from(n);
        let front = (2.0 / nf).powf(1.5) / (2.0 * nf).sqrt();
        Ok(Radial {
            n,
            l,
            k,
            ratios,
            norm_series: front * rising.sqrt() / factorial,
            norm_laguerre: front / rising.sqrt(),
        })
    }

    /// The principal quantum number n.
    pub fn n(&self) -> u32 {
        self.n
    }

    /// The angular momentum quantum number l.
    pub fn l(&self) -> u32 {
        self.l
    }

    /// The number of radial nodes, `n − l − 1`.
    pub fn nodes(&self) -> u32 {
        self.k
    }

    /// `N_nl`, the normalisation constant of the `₁F₁` form (`R_nl(0) = N_n0`
    /// for s states).
    pub fn normalisation(&self) -> f64 {
        self.norm_series
    }

    /// The paper's series `₁F₁(−k; 2l + 2; ρ)` at `ρ`, term by term.
    pub fn series(&self, rho: f64) -> SeriesSum {
        let mut term = 1.0;
        let mut sum = SeriesSum {
            value: 1.0,
            abs_sum: 1.0,
        };
        for ratio in &self.ratios {
            term *= ratio * rho;
            sum.value += term;
            sum.abs_sum += term.abs();
        }
        sum
    }

    /// `N_nl · ₁F₁(−k; 2l + 2; ρ)`: the series where it keeps precision,
    /// else the Laguerre recurrence (see the module docs).
    pub fn polynomial(&self, rho: f64) -> f64 {
        let series = self.series(rho);
        if series.abs_sum <= SERIES_MAX_CANCELLATION * series.value.abs() {
            self.norm_series * series.value
        } else {
            self.norm_laguerre * laguerre(self.k, f64::from(2 * self.l + 1), rho)
        }
    }

    /// `R_nl(r)` for `r ≥ 0` in units of `a₀`, in `a₀^(−3/2)`; exactly 0 where
    /// it underflows (`2r/n > RHO_CUTOFF`).
    pub fn value(&self, r: f64) -> f64 {
        let rho = 2.0 * r / f64::from(self.n);
        if rho > RHO_CUTOFF {
            return 0.0;
        }
        self.polynomial(rho) * (-0.5 * rho).exp() * rho.powi(self.l as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_of_low_states() {
        // Griffiths, table 4.7: R10 = 2e^(−r), R20 = (1/√2)(1 − r/2)e^(−r/2),
        // R21 = (1/(2√6)) r e^(−r/2), R32 = (4/(81√30)) r² e^(−r/3).
        type Case = (u32, u32, fn(f64) -> f64);
        let cases: [Case; 5] = [
            (1, 0, |r| 2.0 * (-r).exp()),
            (2, 0, |r| (1.0 - r / 2.0) * (-r / 2.0).exp() / 2f64.sqrt()),
            (2, 1, |r| r * (-r / 2.0).exp() / (2.0 * 6f64.sqrt())),
            (3, 0, |r| {
                2.0 / 27f64.sqrt() * (1.0 - 2.0 * r / 3.0 + 2.0 * r * r / 27.0) * (-r / 3.0).exp()
            }),
            (3, 2, |r| {
                4.0 / (81.0 * 30f64.sqrt()) * r * r * (-r / 3.0).exp()
            }),
        ];
        for (n, l, f) in cases {
            let radial = Radial::new(n, l).unwrap();
            for r in [0.0, 0.1, 0.5, 1.0, 1.7, 3.0, 7.5, 20.0] {
                let (got, want) = (radial.value(r), f(r));
                assert!(
                    (got - want).abs() <= 1e-14 * want.abs().max(1e-3),
                    "R{n}{l}({r}) = {got}, want {want}"
                );
            }
        }
    }

    #[test]
    fn series_and_recurrence_agree_where_well_conditioned() {
        // L_k^α = C(k + α, k) ₁F₁(−k; α + 1; x) with integer α.
        for (k, alpha) in [(0u32, 1u32), (1, 1), (3, 3), (5, 1), (7, 9)] {
            let binomial = product(alpha + 1, k + alpha) as f64 / product(1, k) as f64;
            for x in [0.0, 0.25, 1.0, 2.5] {
                let series = hypergeometric_1f1(k, f64::from(alpha + 1), x);
                let recurrence = laguerre(k, f64::from(alpha), x);
                assert!(
                    (binomial * series.value - recurrence).abs() <= 1e-13 * recurrence.abs(),
                    "k={k} α={alpha} x={x}"
                );
            }
        }
        // L_2^α(x) = x²/2 − (α + 2)x + (α + 2)(α + 1)/2.
        assert_eq!(laguerre(2, 3.0, 2.0), 2.0 - 10.0 + 10.0);
        assert_eq!(hypergeometric_1f1(1, 2.0, 4.0).value, -1.0);
        assert_eq!(hypergeometric_1f1(1, 2.0, 4.0).abs_sum, 3.0);
        assert_eq!(hypergeometric_1f1(0, 2.0, 4.0).value, 1.0);
    }

    #[test]
    fn normalisation_constants_are_exact_products() {
        // n = 12, l = 11: N = (1/6)^(3/2) √(23!/24) / 23!.
        let r = Radial::new(12, 11).unwrap();
        let f23 = (1..=23u32).fold(1.0f64, |p, i| p * f64::from(i));
        let want = (1.0f64 / 6.0).powf(1.5) * (f23 / 24.0).sqrt() / f23;
        assert!((r.normalisation() - want).abs() <= 1e-14 * want);
        assert_eq!(Radial::new(1, 0).unwrap().normalisation(), 2.0);
        assert_eq!(r.nodes(), 0);
        assert_eq!(Radial::new(7, 2).unwrap().nodes(), 4);
    }

    #[test]
    fn huge_radii_underflow_to_zero_without_nan() {
        let radial = Radial::new(12, 0).unwrap();
        for r in [1.2e4, 1e6, 1e300, f64::MAX, f64::INFINITY] {
            assert_eq!(radial.value(r), 0.0, "{r}");
        }
        assert!(radial.value(f64::NAN).is_nan());
    }

    #[test]
    fn rejects_out_of_range_quantum_numbers() {
        assert_eq!(
            Radial::new(0, 0).unwrap_err(),
            "n must satisfy 1 <= n <= 12, got n = 0"
        );
        assert_eq!(
            Radial::new(13, 0).unwrap_err(),
            "n must satisfy 1 <= n <= 12, got n = 13"
        );
        assert_eq!(
            Radial::new(3, 3).unwrap_err(),
            "l must satisfy 0 <= l < n = 3, got l = 3"
        );
    }
}
