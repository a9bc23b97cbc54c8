//! The angular part of the hydrogen wavefunction: associated Legendre
//! functions by the Morse–Feshbach T-series, the normalised complex
//! spherical harmonics `Y_lm(θ, φ)` and the real harmonics chemists use.
//!
//! `θ` is the polar angle from +z, `φ` the azimuth from +x towards +y.
//!
//! # Formulas (the paper, errata 3)
//!
//! For `m ≥ 0` and `n' = l − m`,
//!
//! ```text
//! P_l^m(z) = (−1)^m (2l − 1)!!/(l − m)! · (1 − z²)^(m/2) · T(z)
//! T(z)     = z^n' − n'(n' − 1)/(2(2l − 1)) z^(n'−2)
//!                 + n'(n' − 1)(n' − 2)(n' − 3)/(2·4 (2l − 1)(2l − 3)) z^(n'−4) − …
//! ```
//!
//! which is the paper's `T_(l−m)^m` (Morse & Feshbach, *Methods of
//! Theoretical Physics*, 1953, ch. 10; `2n' + 2m − 1 = 2l − 1`) with its
//! constant `C₂` made explicit: `(2l − 1)!!/(l − m)!` is the leading
//! coefficient of `d^m P_l/dz^m`, since `P_l` leads with `(2l)!/(2^l l!²) z^l`.
//! Term `k + 1` comes from term `k` by the factor
//! `−(n' − 2k)(n' − 2k − 1) / (2(k + 1)(2l − 2k − 1)) · z^(−2)`; the series is
//! summed from its lowest power upwards (small terms first), so no
//! factorial is formed and `z = 0` needs no special case.
//!
//! ```text
//! Y_lm(θ, φ)   = N_lm P_l^m(cos θ) e^(imφ),   N_lm = √((2l + 1)/(4π) · (l − m)!/(l + m)!)
//! Y_l,−m       = (−1)^m conj(Y_lm)
//! ```
//!
//! normalised so that `∫|Y_lm|² dΩ = 1`. The products `N_lm (2l − 1)!!/(l − m)!`
//! are formed from exact integers (`u128`) with one square root.
//!
//! # Phase conventions
//!
//! The complex harmonics carry the **Condon–Shortley phase** `(−1)^m` for
//! `m > 0` (inside `P_l^m`, as in Arfken, Jackson, Griffiths, SciPy's
//! `sph_harm` and Mathematica's `SphericalHarmonicY`): `Y_11 = −√(3/8π) sin θ
//! e^(iφ)`, `Y_1,−1 = +√(3/8π) sin θ e^(−iφ)`.
//!
//! The **real harmonics** are the chemists' orbitals with positive lobes
//! along the positive axes, i.e. without the Condon–Shortley sign:
//!
//! ```text
//! m > 0:  S_lm = √2 N_lm |P_l^m(cos θ)| cos(mφ)    (p_x, d_xz, d_x²−y², …)
//! m = 0:  S_l0 = Y_l0                              (s, p_z, d_z², …)
//! m < 0:  S_lm = √2 N_l|m| |P_l^|m|(cos θ)| sin(|m|φ) (p_y, d_yz, d_xy, …)
//! ```
//!
//! (|…| meaning `P_l^m` without its `(−1)^m`); so `S_11 = √(3/4π) x/r`
//! (p_x), `S_1,−1 = √(3/4π) y/r` (p_y), `S_2,−2 ∝ xy/r²` (d_xy). They are
//! `S_lm = √2 (−1)^m Re Y_lm` and `S_l,−m = √2 (−1)^m Im Y_lm` for `m > 0`,
//! and `S_lm² + S_l,−m² = 2|Y_lm|²` (see [`real_orbital_label`]).
//!
//! # Precision
//!
//! The T-series alternates too. Measured like the radial series (against
//! the same sum in double-double arithmetic, `tests/hydrogen_precision.rs`),
//! over `θ ∈ [0, π]`, worst case over `m`, the error of `N_lm P_l^m`:
//!
//! ```text
//!  l | T-series: error / max|P|   error / |P|*  | recurrence: / max|P|   / |P|*
//!  3 |            5.6e−16          3.3e−14      |              6.0e−16    2.6e−14
//!  6 |            4.9e−15          1.7e−12      |              2.2e−15    1.6e−13
//!  9 |            4.1e−14          7.6e−12      |              4.0e−15    6.6e−13
//! 11 |            2.9e−13          1.8e−11      |              6.2e−15    3.5e−13
//!                                  (* where |P| ≥ 1e−3 max|P|)
//! ```
//!
//! So, as for the radial part, [`SphericalHarmonic::polar`] keeps the
//! T-series where its terms cancel by at most
//! [`SERIES_MAX_CANCELLATION`] (one digit) and otherwise uses the upward
//! recurrence in `l` (A&S 8.5.3) started from `P_m^m`, which stays within
//! 1e−14 of the maximum for every `l ≤ 11` (6.4e−15 at l = 11). Near the
//! nodal cones the relative error grows as for any method, like `1/|P|`.
//! `sin θ` is formed as `√((1 − z)(1 + z))` from `z = cos θ`, which keeps
//! full relative precision near the poles where `1 − z²` cancels.

use std::f64::consts::PI;

use volray_core::glam::DVec3;

use super::radial::{MAX_N, SERIES_MAX_CANCELLATION, SeriesSum};

/// The largest `l` supported: `MAX_N − 1`, the range the precision was
/// verified over.
pub const MAX_L: u32 = MAX_N - 1;

/// A complex number `re + i·im` (amplitudes of complex orbitals).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Complex {
    /// The real part.
    pub re: f64,
    /// The imaginary part.
    pub im: f64,
}

impl Complex {
    /// `re + i·im`.
    pub const fn new(re: f64, im: f64) -> Self {
        Complex { re, im }
    }

    /// `|z|²`.
    pub fn norm_sqr(self) -> f64 {
        self.re * self.re + self.im * self.im
    }

    /// `|z|`.
    pub fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }

    /// The phase `arg z` in `(−π, π]`.
    pub fn arg(self) -> f64 {
        self.im.atan2(self.re)
    }

    /// The complex conjugate.
    pub fn conj(self) -> Self {
        Complex::new(self.re, -self.im)
    }

    /// `s·z` for real `s`.
    pub fn scale(self, s: f64) -> Self {
        Complex::new(s * self.re, s * self.im)
    }

    /// `z^k` by repeated multiplication (`k` is small here: at most `MAX_L`).
    pub fn powu(self, k: u32) -> Self {
        (0..k).fold(Complex::new(1.0, 0.0), |p, _| p * self)
    }
}

impl std::ops::Mul for Complex {
    type Output = Complex;

    fn mul(self, w: Complex) -> Complex {
        Complex::new(
            self.re * w.re - self.im * w.im,
            self.re * w.im + self.im * w.re,
        )
    }
}

/// Checks `0 ≤ l ≤ MAX_L` and `|m| ≤ l`, returning the rule broken (wide
/// integers, so that values from a spec are checked before narrowing).
pub fn check_l_m(l: i64, m: i64) -> Result<(), String> {
    if !(0..=i64::from(MAX_L)).contains(&l) {
        return Err(format!("l must satisfy 0 <= l <= {MAX_L}, got l = {l}"));
    }
    if m.unsigned_abs() > l.unsigned_abs() {
        return Err(format!("m must satisfy |m| <= l = {l}, got m = {m}"));
    }
    Ok(())
}

/// The chemists' name of the real orbital `S_lm` for `l ≤ 3` (`"p_x"`,
/// `"d_xy"`, `"f_z(x2-y2)"`, …), or `None` beyond.
pub fn real_orbital_label(l: u32, m: i32) -> Option<&'static str> {
    let label = match (l, m) {
        (0, 0) => "s",
        (1, 0) => "p_z",
        (1, 1) => "p_x",
        (1, -1) => "p_y",
        (2, 0) => "d_z2",
        (2, 1) => "d_xz",
        (2, -1) => "d_yz",
        (2, 2) => "d_x2-y2",
        (2, -2) => "d_xy",
        (3, 0) => "f_z3",
        (3, 1) => "f_xz2",
        (3, -1) => "f_yz2",
        (3, 2) => "f_z(x2-y2)",
        (3, -2) => "f_xyz",
        (3, 3) => "f_x(x2-3y2)",
        (3, -3) => "f_y(3x2-y2)",
        _ => return None,
    };
    Some(label)
}

/// `a · (a + 1) ⋯ b` in exact integer arithmetic (1 for an empty range).
fn product(a: u32, b: u32, step: usize) -> u128 {
    (a..=b).step_by(step).fold(1u128, |p, i| {
        p.checked_mul(u128::from(i))
            .expect("factorials up to (2 MAX_L)! fit u128")
    })
}

/// `Y_lm` for one `(l, m)`, with the T-series coefficients and the
/// normalisation precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct SphericalHarmonic {
    l: u32,
    m: i32,
    /// `N_l|m| (2l − 1)!!/(l − |m|)!` times the T-series coefficients,
    /// lowest power first: `coefficients[i]` multiplies
    /// `z^(parity + 2i)`, `parity = (l − |m|) mod 2`.
    coefficients: Vec<f64>,
    /// `N_l|m|`, for the recurrence.
    norm: f64,
    /// `(2|m| − 1)!!`, where the recurrence starts.
    start: f64,
}

impl SphericalHarmonic {
    /// `Y_lm`; errors name the rule broken (`l ≤ 11`, `|m| ≤ l`).
    pub fn new(l: u32, m: i32) -> Result<Self, String> {
        check_l_m(l.into(), m.into())?;
        let am = m.unsigned_abs();
        let np = l - am;
        // N_lm (2l − 1)!!/(l − m)! = √((2l + 1)/4π) (2l − 1)!! / √((l − m)! (l + m)!).
        let double_factorial = product(1, (2 * l).saturating_sub(1), 2) as f64;
        let (low, high) = (product(1, l - am, 1), product(1, l + am, 1));
        let front = (f64::from(2 * l + 1) / (4.0 * PI)).sqrt();
        let leading = front * double_factorial / ((low * high) as f64).sqrt();
        let norm = front * (low as f64 / high as f64).sqrt();
        let start = product(1, (2 * am).saturating_sub(1), 2) as f64;
        let mut coefficients = vec![leading];
        for k in 0..np / 2 {
            let (k, np, l) = (f64::from(k), f64::from(np), f64::from(l));
            let last = coefficients[coefficients.len() - 1];
            coefficients.push(
                -last * (np - 2.0 * k) * (np - 2.0 * k - 1.0)
                    / (2.0 * (k + 1.0) * (2.0 * l - 2.0 * k - 1.0)),
            );
        }
        coefficients.reverse();
        Ok(SphericalHarmonic {
            l,
            m,
            coefficients,
            norm,
            start,
        })
    }

    /// The degree `l`.
    pub fn l(&self) -> u32 {
        self.l
    }

    /// The order `m`.
    pub fn m(&self) -> i32 {
        self.m
    }

    /// The number of nodal cones (planes through the z axis are not
    /// counted): `l − |m|`, the zeros of `P_l^m(cos θ)` in `0 < θ < π`.
    pub fn nodal_cones(&self) -> u32 {
        self.l - self.m.unsigned_abs()
    }

    /// The normalised T-series `N_l|m| (2l − 1)!!/(l − |m|)! · T(z)`, summed
    /// term by term from its lowest power, with its magnitude sum.
    pub fn t_series(&self, z: f64) -> SeriesSum {
        let z2 = z * z;
        let mut power = if self.nodal_cones() % 2 == 1 { z } else { 1.0 };
        let mut sum = SeriesSum {
            value: 0.0,
            abs_sum: 0.0,
        };
        for c in &self.coefficients {
            let term = c * power;
            sum.value += term;
            sum.abs_sum += term.abs();
            power *= z2;
        }
        sum
    }

    /// The same polynomial, `N_l|m| Q_l(z)`, by the upward recurrence in `l`
    /// of `Q_l = P_l^|m| / ((−1)^m (1 − z²)^(m/2))` (A&S 8.5.3):
    /// `Q_m = (2m − 1)!!`, `Q_(m+1) = (2m + 1) z Q_m`,
    /// `(j − m + 1) Q_(j+1) = (2j + 1) z Q_j − (j + m) Q_(j−1)`.
    pub fn recurrence(&self, z: f64) -> f64 {
        let am = self.m.unsigned_abs();
        let mut previous = self.start;
        if self.l == am {
            return self.norm * previous;
        }
        let mut current = f64::from(2 * am + 1) * z * previous;
        for j in am + 1..self.l {
            let next = (f64::from(2 * j + 1) * z * current - f64::from(j + am) * previous)
                / f64::from(j - am + 1);
            previous = current;
            current = next;
        }
        self.norm * current
    }

    /// `N_l|m| (2l − 1)!!/(l − |m|)! · T(z)`: the T-series where its terms
    /// cancel by at most [`SERIES_MAX_CANCELLATION`], else the recurrence
    /// (module docs, "Precision").
    pub fn polar(&self, z: f64) -> f64 {
        let series = self.t_series(z);
        if series.abs_sum <= SERIES_MAX_CANCELLATION * series.value.abs() {
            series.value
        } else {
            self.recurrence(z)
        }
    }

    /// The Condon–Shortley sign `(−1)^m` for `m > 0`, else 1.
    fn condon_shortley(&self) -> f64 {
        if self.m > 0 && self.m % 2 == 1 {
            -1.0
        } else {
            1.0
        }
    }

    /// `N_l|m| P_l^|m|(z)` with the Condon–Shortley phase, for `|z| ≤ 1`:
    /// `Y_l|m|(θ, 0)` at `z = cos θ`.
    pub fn legendre(&self, z: f64) -> f64 {
        let am = self.m.unsigned_abs() as i32;
        let sign = if am % 2 == 1 { -1.0 } else { 1.0 };
        // (1 − z)(1 + z) rather than 1 − z², which cancels near the poles.
        let sin_theta = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
        sign * sin_theta.powi(am) * self.polar(z)
    }

    /// `|Y_lm(θ, φ)|²`, which does not depend on `φ`.
    pub fn norm_sqr(&self, theta: f64) -> f64 {
        let am = self.m.unsigned_abs() as i32;
        let t = theta.sin().powi(am) * self.polar(theta.cos());
        t * t
    }

    /// `Y_lm(θ, φ)`.
    pub fn value(&self, theta: f64, phi: f64) -> Complex {
        let am = self.m.unsigned_abs();
        let (sin_t, cos_t) = theta.sin_cos();
        let phase = f64::from(self.m) * phi;
        let magnitude = self.condon_shortley() * sin_t.powi(am as i32) * self.polar(cos_t);
        Complex::new(magnitude * phase.cos(), magnitude * phase.sin())
    }

    /// The real harmonic `S_lm(θ, φ)` (module docs; `p_x` for `l = m = 1`).
    pub fn real_value(&self, theta: f64, phi: f64) -> f64 {
        let am = self.m.unsigned_abs();
        let (sin_t, cos_t) = theta.sin_cos();
        let radial = sin_t.powi(am as i32) * self.polar(cos_t);
        let phase = f64::from(am) * phi;
        match self.m {
            0 => radial,
            m if m > 0 => std::f64::consts::SQRT_2 * radial * phase.cos(),
            _ => std::f64::consts::SQRT_2 * radial * phase.sin(),
        }
    }

    /// `Y_lm` in the direction of `d` (any length; the zero vector gives
    /// NaN), from Cartesian components without trigonometry:
    /// `sin^m θ e^(imφ) = ((x + iy)/r)^m`, `cos θ = z/r`.
    pub fn value_at(&self, d: DVec3) -> Complex {
        self.cartesian(d, d.length())
    }

    /// The real harmonic `S_lm` in the direction of `d` (the zero vector
    /// gives NaN).
    pub fn real_value_at(&self, d: DVec3) -> f64 {
        self.real_cartesian(d, d.length())
    }

    /// `Y_lm` at `d` whose length `r = |d| > 0` is known.
    pub(crate) fn cartesian(&self, d: DVec3, r: f64) -> Complex {
        let am = self.m.unsigned_abs();
        let t = self.polar(d.z / r);
        let w = Complex::new(d.x / r, d.y / r).powu(am);
        let w = if self.m < 0 { w.conj() } else { w };
        w.scale(self.condon_shortley() * t)
    }

    /// `S_lm` at `d` whose length `r = |d| > 0` is known.
    pub(crate) fn real_cartesian(&self, d: DVec3, r: f64) -> f64 {
        let t = self.polar(d.z / r);
        let w = Complex::new(d.x / r, d.y / r).powu(self.m.unsigned_abs());
        match self.m {
            0 => t,
            m if m > 0 => std::f64::consts::SQRT_2 * t * w.re,
            _ => std::f64::consts::SQRT_2 * t * w.im,
        }
    }
}

/// `P_l^m(z)` for `0 ≤ m ≤ l ≤ MAX_L`, with the Condon–Shortley phase
/// (unnormalised: `P_1^1(z) = −√(1 − z²)`).
pub fn associated_legendre(l: u32, m: u32, z: f64) -> Result<f64, String> {
    check_l_m(l.into(), m.into())?;
    let y = SphericalHarmonic::new(l, i32::try_from(m).expect("m <= l <= MAX_L"))?;
    Ok(y.legendre(z) / y.norm)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1.0)
    }

    #[test]
    fn legendre_closed_forms() {
        // A&S table 8.x with the Condon–Shortley phase.
        type Case = (u32, u32, fn(f64) -> f64);
        let cases: [Case; 7] = [
            (0, 0, |_| 1.0),
            (1, 0, |z| z),
            (1, 1, |z| -(1.0 - z * z).sqrt()),
            (2, 0, |z| 0.5 * (3.0 * z * z - 1.0)),
            (2, 1, |z| -3.0 * z * (1.0 - z * z).sqrt()),
            (2, 2, |z| 3.0 * (1.0 - z * z)),
            (3, 1, |z| -1.5 * (5.0 * z * z - 1.0) * (1.0 - z * z).sqrt()),
        ];
        for (l, m, f) in cases {
            for z in [-1.0, -0.7, -0.2, 0.0, 0.3, 0.5, 0.95, 1.0] {
                let got = associated_legendre(l, m, z).unwrap();
                assert!(
                    close(got, f(z), 1e-14),
                    "P_{l}^{m}({z}) = {got}, want {}",
                    f(z)
                );
            }
        }
        assert!(associated_legendre(2, 3, 0.5).is_err());
    }

    #[test]
    fn harmonics_closed_forms_and_phase() {
        let (theta, phi) = (0.7f64, 2.1f64);
        let (s, c) = theta.sin_cos();
        let y = |l, m| SphericalHarmonic::new(l, m).unwrap().value(theta, phi);
        let a11 = (3.0 / (8.0 * PI)).sqrt() * s;
        let y11 = y(1, 1);
        assert!(close(y11.re, -a11 * phi.cos(), 1e-15) && close(y11.im, -a11 * phi.sin(), 1e-15));
        let y1m1 = y(1, -1);
        assert!(close(y1m1.re, a11 * phi.cos(), 1e-15) && close(y1m1.im, -a11 * phi.sin(), 1e-15));
        let y20 = y(2, 0);
        assert!(close(
            y20.re,
            (5.0 / (16.0 * PI)).sqrt() * (3.0 * c * c - 1.0),
            1e-15
        ));
        assert_eq!(y20.im, 0.0);
        let y22 = y(2, 2);
        let a22 = (15.0 / (32.0 * PI)).sqrt() * s * s;
        assert!(close(y22.re, a22 * (2.0 * phi).cos(), 1e-15));
        assert!(close(y22.im, a22 * (2.0 * phi).sin(), 1e-15));
        assert_eq!(
            SphericalHarmonic::new(0, 0).unwrap().value(1.0, 1.0),
            Complex::new((0.25 / PI).sqrt(), 0.0)
        );
    }

    #[test]
    fn real_harmonics_are_the_chemists_orbitals() {
        let d = DVec3::new(0.3, -0.5, 0.8);
        let r = d.length();
        let real = |l, m| SphericalHarmonic::new(l, m).unwrap().real_value_at(d);
        let p = (3.0 / (4.0 * PI)).sqrt();
        assert!(close(real(1, 1), p * d.x / r, 1e-15), "p_x");
        assert!(close(real(1, -1), p * d.y / r, 1e-15), "p_y");
        assert!(close(real(1, 0), p * d.z / r, 1e-15), "p_z");
        let dxy = (15.0 / (4.0 * PI)).sqrt();
        assert!(close(real(2, -2), dxy * d.x * d.y / (r * r), 1e-15), "d_xy");
        assert!(close(real(2, 1), dxy * d.x * d.z / (r * r), 1e-15), "d_xz");
        let dx2y2 = (15.0 / (16.0 * PI)).sqrt();
        assert!(
            close(real(2, 2), dx2y2 * (d.x * d.x - d.y * d.y) / (r * r), 1e-15),
            "d_x2-y2"
        );
        assert_eq!(real_orbital_label(2, -2), Some("d_xy"));
        assert_eq!(real_orbital_label(4, 0), None);
    }

    #[test]
    fn angle_and_cartesian_forms_agree() {
        for l in 0..=MAX_L {
            for m in -(l as i32)..=l as i32 {
                let y = SphericalHarmonic::new(l, m).unwrap();
                for (theta, phi) in [(0.0f64, 0.0f64), (0.4, -2.0), (1.3, 0.9), (2.9, 3.0)] {
                    let d = DVec3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    ) * 2.5;
                    let (a, b) = (y.value(theta, phi), y.value_at(d));
                    let scale = y.norm_sqr(theta).sqrt().max(1e-3);
                    assert!(
                        close(a.re, b.re, 1e-13 * scale.max(1.0)),
                        "{l},{m}: {a:?} {b:?}"
                    );
                    assert!(
                        close(a.im, b.im, 1e-13 * scale.max(1.0)),
                        "{l},{m}: {a:?} {b:?}"
                    );
                    assert!(close(y.real_value(theta, phi), y.real_value_at(d), 1e-13));
                    assert!(close(a.norm_sqr(), y.norm_sqr(theta), 1e-13));
                }
            }
        }
    }

    #[test]
    fn rejects_bad_l_and_m() {
        assert_eq!(
            SphericalHarmonic::new(12, 0).unwrap_err(),
            "l must satisfy 0 <= l <= 11, got l = 12"
        );
        assert_eq!(
            SphericalHarmonic::new(2, -3).unwrap_err(),
            "m must satisfy |m| <= l = 2, got m = -3"
        );
    }
}
