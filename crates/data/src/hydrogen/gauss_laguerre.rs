//! Gauss–Laguerre quadrature: `∫₀^∞ f(t) e^(−t) dt ≈ Σ w_i f(t_i)`, exact when
//! `f` is a polynomial of degree at most `2N − 1` (N nodes).
//!
//! The nodes are the zeros of the Laguerre polynomial `L_N`, found by Newton's
//! method from the asymptotic starting guesses of Numerical Recipes (Press et
//! al., 2nd ed., §4.5, `gaulag` with α = 0); `L_N` and `L_(N−1)` come from the
//! three-term recurrence, `L_N'(t) = N (L_N(t) − L_(N−1)(t))/t`, and the
//! weights are `w_i = −1/(N L_N'(t_i) L_(N−1)(t_i))` (A&S 25.4.45).

/// The nodes and weights of an N-point rule.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussLaguerre {
    /// The nodes `t_i`, increasing.
    pub nodes: Vec<f64>,
    /// The weights `w_i`, all positive, summing to 1.
    pub weights: Vec<f64>,
}

/// `(L_N(t), L_(N−1)(t))` by the upward recurrence.
fn laguerre_pair(n: usize, t: f64) -> (f64, f64) {
    let (mut current, mut previous) = (1.0, 0.0);
    for j in 1..=n {
        let j = j as f64;
        let next = ((2.0 * j - 1.0 - t) * current - (j - 1.0) * previous) / j;
        previous = current;
        current = next;
    }
    (current, previous)
}

impl GaussLaguerre {
    /// The rule with `n ≥ 1` nodes (n up to a few dozen: beyond that the
    /// smallest weights underflow).
    pub fn new(n: usize) -> Self {
        assert!(n >= 1, "a quadrature rule needs at least one node");
        let nf = n as f64;
        let mut nodes: Vec<f64> = Vec::with_capacity(n);
        let mut weights = Vec::with_capacity(n);
        let mut z = 0.0;
        for i in 0..n {
            z = match i {
                0 => 3.0 / (1.0 + 2.4 * nf),
                1 => z + 15.0 / (1.0 + 2.5 * nf),
                _ => {
                    let ai = (i - 1) as f64;
                    z + (1.0 + 2.55 * ai) / (1.9 * ai) * (z - nodes[i - 2])
                }
            };
            // Newton's method; the derivative and L_(N−1) of the last step
            // give the weight (their error is second order in the step).
            let (mut derivative, mut below) = (f64::NAN, f64::NAN);
            for _ in 0..100 {
                let (value, previous) = laguerre_pair(n, z);
                derivative = nf * (value - previous) / z;
                below = previous;
                let step = value / derivative;
                z -= step;
                if step.abs() <= 1e-15 * z.abs() {
                    break;
                }
            }
            nodes.push(z);
            weights.push(-1.0 / (derivative * nf * below));
        }
        GaussLaguerre { nodes, weights }
    }

    /// `Σ w_i f(t_i)`.
    pub fn integrate(&self, f: impl Fn(f64) -> f64) -> f64 {
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(|(&t, &w)| w * f(t))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_polynomials_up_to_degree_2n_minus_1() {
        // ∫₀^∞ t^j e^(−t) dt = j!.
        for n in [1usize, 2, 5, 13, 20] {
            let rule = GaussLaguerre::new(n);
            assert_eq!(rule.nodes.len(), n);
            assert!(rule.weights.iter().all(|&w| w > 0.0));
            assert!(rule.nodes.windows(2).all(|p| p[0] < p[1]));
            let mut factorial = 1.0;
            for j in 0..2 * n {
                if j > 0 {
                    factorial *= j as f64;
                }
                let got = rule.integrate(|t| t.powi(j as i32));
                assert!(
                    (got - factorial).abs() <= 1e-12 * factorial,
                    "n={n} j={j}: {got} vs {factorial}"
                );
            }
        }
        // One node: t = 1, w = 1. Two: t = 2 ∓ √2, w = (2 ± √2)/4.
        assert_eq!(GaussLaguerre::new(1).nodes, [1.0]);
        let two = GaussLaguerre::new(2);
        assert!((two.nodes[0] - (2.0 - 2f64.sqrt())).abs() < 1e-15);
        assert!((two.weights[0] - (2.0 + 2f64.sqrt()) / 4.0).abs() < 1e-15);
    }
}
