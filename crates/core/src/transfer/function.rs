//! Transfer functions: piecewise-linear opacity and colour, as in VTK and
//! ParaView, read from JSON.
//!
//! ```json
//! { "domain": [0.0, 250.0],
//!   "opacity": [[0.0, 0.0], [0.05, 0.0], [0.95, 0.95], [1.0, 0.95]],
//!   "color":   [[0.0, 0.23, 0.299, 0.754], [1.0, 0.706, 0.016, 0.15]] }
//! ```
//!
//! Both functions are of the normalised scalar `t = (f − lo)/(hi − lo)`,
//! where `[lo, hi]` is `domain` when given and the volume's `[fmin, fmax]`
//! otherwise. Outside its first and last points a function holds its end
//! values. Opacity is per unit distance of one voxel (the paper's step);
//! the renderer corrects it for other steps (see `transfer::classifier`).
//! Either function may be left out: opacity then falls back to the paper's
//! `[p, q]` ramp, colour to white.

use serde::Deserialize;
use thiserror::Error;

/// A transfer-function file that could not be used.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TransferFunctionError {
    #[error("not a valid transfer function: {0}")]
    Json(String),
    #[error("\"{0}\" needs at least one point")]
    Empty(&'static str),
    #[error("\"{what}\" point {index}: {problem}")]
    BadPoint {
        what: &'static str,
        index: usize,
        problem: String,
    },
    #[error("\"domain\" [{0}, {1}] must be two finite numbers with lo < hi")]
    BadDomain(f64, f64),
}

/// A piecewise-linear function from `t` to `N` values, held constant
/// beyond its end points.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear<const N: usize> {
    points: Vec<(f32, [f32; N])>,
}

impl<const N: usize> PiecewiseLinear<N> {
    /// Points sorted by `t` (ties allowed: a jump), every value in [0, 1].
    pub fn new(
        what: &'static str,
        points: Vec<(f32, [f32; N])>,
    ) -> Result<Self, TransferFunctionError> {
        if points.is_empty() {
            return Err(TransferFunctionError::Empty(what));
        }
        let bad = |index: usize, problem: String| TransferFunctionError::BadPoint {
            what,
            index,
            problem,
        };
        for (index, (t, values)) in points.iter().enumerate() {
            if !t.is_finite() {
                return Err(bad(index, format!("t = {t} is not finite")));
            }
            if index > 0 && *t < points[index - 1].0 {
                return Err(bad(
                    index,
                    format!("t = {t} is smaller than the point before it; sort the points by t"),
                ));
            }
            if let Some(v) = values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
                return Err(bad(index, format!("value {v} is outside [0, 1]")));
            }
        }
        Ok(PiecewiseLinear { points })
    }

    /// A function that is `value` everywhere.
    pub fn constant(value: [f32; N]) -> Self {
        PiecewiseLinear {
            points: vec![(0.0, value)],
        }
    }

    pub fn points(&self) -> &[(f32, [f32; N])] {
        &self.points
    }

    /// The function's value at `t`.
    pub fn eval(&self, t: f32) -> [f32; N] {
        let points = &self.points;
        // Index of the first point with t_i > t: the segment is [upper−1, upper].
        let upper = points.partition_point(|(ti, _)| *ti <= t);
        if upper == 0 {
            return points[0].1;
        }
        if upper == points.len() {
            return points[upper - 1].1;
        }
        let (t0, v0) = points[upper - 1];
        let (t1, v1) = points[upper];
        let w = (t - t0) / (t1 - t0);
        std::array::from_fn(|c| v0[c] + w * (v1[c] - v0[c]))
    }
}

/// Opacity and colour transfer functions over a value domain.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TransferFunction {
    /// `[lo, hi]` that maps to `t ∈ [0, 1]`; `None`: the volume's value range.
    pub domain: Option<(f64, f64)>,
    /// Opacity per unit voxel distance; `None`: the paper's `[p, q]` ramp.
    pub opacity: Option<PiecewiseLinear<1>>,
    /// Material colour; `None`: white.
    pub color: Option<PiecewiseLinear<3>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransferFunctionFile {
    domain: Option<[f64; 2]>,
    opacity: Option<Vec<[f32; 2]>>,
    color: Option<Vec<[f32; 4]>>,
}

impl TransferFunction {
    /// Parses the JSON form (see the module documentation).
    pub fn from_json(text: &str) -> Result<Self, TransferFunctionError> {
        let file: TransferFunctionFile =
            serde_json::from_str(text).map_err(|e| TransferFunctionError::Json(e.to_string()))?;
        let domain = match file.domain {
            Some([lo, hi]) if lo.is_finite() && hi.is_finite() && lo < hi => Some((lo, hi)),
            Some([lo, hi]) => return Err(TransferFunctionError::BadDomain(lo, hi)),
            None => None,
        };
        let opacity = file
            .opacity
            .map(|pts| {
                PiecewiseLinear::new("opacity", pts.iter().map(|[t, a]| (*t, [*a])).collect())
            })
            .transpose()?;
        let color = file
            .color
            .map(|pts| {
                PiecewiseLinear::new(
                    "color",
                    pts.iter().map(|[t, r, g, b]| (*t, [*r, *g, *b])).collect(),
                )
            })
            .transpose()?;
        Ok(TransferFunction {
            domain,
            opacity,
            color,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_linear_interpolates_and_clamps() {
        let f = PiecewiseLinear::new("opacity", vec![(0.05, [0.0]), (0.95, [0.9]), (1.0, [0.5])])
            .unwrap();
        assert_eq!(f.eval(-1.0), [0.0]);
        assert_eq!(f.eval(0.05), [0.0]);
        assert!((f.eval(0.5)[0] - 0.45).abs() < 1e-6);
        assert!((f.eval(0.975)[0] - 0.7).abs() < 1e-6);
        assert_eq!(f.eval(1.0), [0.5]);
        assert_eq!(f.eval(7.0), [0.5]);
    }

    #[test]
    fn equal_t_makes_a_jump() {
        let f = PiecewiseLinear::new(
            "opacity",
            vec![(0.0, [0.0]), (0.5, [0.0]), (0.5, [1.0]), (1.0, [1.0])],
        )
        .unwrap();
        assert_eq!(f.eval(0.49), [0.0]);
        assert_eq!(f.eval(0.5), [1.0]);
        assert_eq!(f.eval(0.51), [1.0]);
    }

    #[test]
    fn parses_the_documented_json() {
        let tf = TransferFunction::from_json(
            r#"{"domain": [10, 20], "opacity": [[0, 0], [1, 0.5]],
                "color": [[0, 1, 0, 0], [1, 0, 0, 1]]}"#,
        )
        .unwrap();
        assert_eq!(tf.domain, Some((10.0, 20.0)));
        assert_eq!(tf.opacity.unwrap().eval(0.5), [0.25]);
        assert_eq!(tf.color.unwrap().eval(0.5), [0.5, 0.0, 0.5]);
        let only_color = TransferFunction::from_json(r#"{"color": [[0.5, 1, 1, 0]]}"#).unwrap();
        assert!(only_color.opacity.is_none() && only_color.domain.is_none());
    }

    #[test]
    fn rejects_malformed_functions() {
        let cases = [
            (r#"{"opacity": []}"#, "at least one point"),
            (
                r#"{"opacity": [[0.5, 0.1], [0.2, 0.3]]}"#,
                "sort the points",
            ),
            (r#"{"opacity": [[0, 1.5]]}"#, "outside [0, 1]"),
            (r#"{"color": [[0, 1, -1, 0]]}"#, "outside [0, 1]"),
            (r#"{"color": [[0, 1, 0]]}"#, "not a valid"),
            (r#"{"domain": [3, 3]}"#, "lo < hi"),
            (r#"{"colour": [[0, 1, 1, 1]]}"#, "unknown field"),
            ("[1, 2", "not a valid"),
        ];
        for (json, expect) in cases {
            let err = TransferFunction::from_json(json).unwrap_err().to_string();
            assert!(err.contains(expect), "{json}: {err}");
        }
    }
}
