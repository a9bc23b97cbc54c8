//! Stage 1 classification: a voxel's value → its material colour and opacity.
//!
//! The paper's default is opacity proportional to intensity on a
//! sub-interval `[p, q]` of [0, 1]:
//! `α = p + (f − fmin)/(fmax − fmin)·(q − p)`. A transfer function (see
//! [`crate::transfer_function`]) may replace the ramp and add a colour. Both
//! use the normalised scalar `t = (f − lo)/(hi − lo)`; for a constant volume
//! (`hi = lo`) `t` is 0 everywhere, so nothing divides by zero.
//!
//! Opacities are per unit distance of one voxel (the smallest spacing, the
//! paper's step). Sampling at another step `s` (in voxels) corrects each
//! voxel's opacity to `α_s = 1 − (1 − α)^s`, so that a ray through a uniform
//! medium gathers the same opacity per unit length whatever the step.

use crate::transfer_function::{PiecewiseLinear, TransferFunction};

/// How opacity is assigned before the step correction.
#[derive(Debug, Clone, PartialEq)]
pub enum OpacityMap {
    /// The paper's linear ramp from `p` at `t = 0` to `q` at `t = 1`.
    Ramp { p: f32, q: f32 },
    /// A piecewise-linear function of `t`.
    Table(PiecewiseLinear<1>),
}

/// Maps values to (material colour, per-sample opacity) for one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Classifier {
    lo: f32,
    inv_range: f32,
    opacity: OpacityMap,
    color: Option<PiecewiseLinear<3>>,
    step_voxels: f32,
}

impl Classifier {
    /// A classifier over `[lo, hi]` (`hi = lo` allowed) for samples taken
    /// `step_voxels` voxels apart.
    pub fn new(
        (lo, hi): (f32, f32),
        opacity: OpacityMap,
        color: Option<PiecewiseLinear<3>>,
        step_voxels: f32,
    ) -> Self {
        let range = hi - lo;
        Classifier {
            lo,
            inv_range: if range > 0.0 { 1.0 / range } else { 0.0 },
            opacity,
            color,
            step_voxels,
        }
    }

    /// The classifier a transfer function describes, falling back to the
    /// ramp `[p, q]` for opacity and to the volume's `value_range` for the domain.
    pub fn from_transfer_function(
        tf: &TransferFunction,
        value_range: (f32, f32),
        ramp: (f32, f32),
        step_voxels: f32,
    ) -> Self {
        let domain = tf
            .domain
            .map(|(lo, hi)| (lo as f32, hi as f32))
            .unwrap_or(value_range);
        let opacity = match &tf.opacity {
            Some(table) => OpacityMap::Table(table.clone()),
            None => OpacityMap::Ramp {
                p: ramp.0,
                q: ramp.1,
            },
        };
        Classifier::new(domain, opacity, tf.color.clone(), step_voxels)
    }

    /// The normalised scalar `t` of value `f`.
    #[inline]
    pub fn normalise(&self, f: f32) -> f32 {
        (f - self.lo) * self.inv_range
    }

    /// Opacity per unit voxel distance, before the step correction.
    #[inline]
    pub fn unit_opacity(&self, f: f32) -> f32 {
        let t = self.normalise(f);
        match &self.opacity {
            OpacityMap::Ramp { p, q } => p + t.clamp(0.0, 1.0) * (q - p),
            OpacityMap::Table(table) => table.eval(t)[0],
        }
    }

    /// Opacity of one sample taken `step` voxels from the last:
    /// `α_s = 1 − (1 − α)^s`.
    #[inline]
    pub fn sample_opacity(&self, f: f32) -> f32 {
        correct_opacity(self.unit_opacity(f), self.step_voxels)
    }

    /// Whether every value in `[lo, hi]` gets zero opacity, so that a
    /// region whose values all lie there contributes nothing to any ray
    /// (the zero-opacity test of empty-space skipping, Levoy 1990).
    /// Exact: a piecewise-linear opacity is zero on an interval iff it is
    /// zero at the interval's ends and at every break point inside it.
    pub fn is_transparent_between(&self, lo: f32, hi: f32) -> bool {
        // `normalise` is monotone (a subtraction and a non-negative scale).
        let (t0, t1) = (self.normalise(lo), self.normalise(hi));
        match &self.opacity {
            // q > p >= 0, so the ramp is zero only at p = 0, for t <= 0.
            OpacityMap::Ramp { p, .. } => *p == 0.0 && t1 <= 0.0,
            OpacityMap::Table(table) => {
                table.eval(t0)[0] == 0.0
                    && table.eval(t1)[0] == 0.0
                    && table
                        .points()
                        .iter()
                        .filter(|(t, _)| t0 < *t && *t < t1)
                        .all(|(_, a)| a[0] == 0.0)
            }
        }
    }

    /// Material colour of value `f` (white without a colour function).
    #[inline]
    pub fn material(&self, f: f32) -> [f32; 3] {
        match &self.color {
            Some(color) => color.eval(self.normalise(f)),
            None => [1.0; 3],
        }
    }

    /// `(lo, 1/(hi − lo))`: [`Self::normalise`] is `(f − lo)·(1/(hi − lo))`
    /// (the second is 0 for a constant volume).
    pub fn normalisation(&self) -> (f32, f32) {
        (self.lo, self.inv_range)
    }

    /// The colour function, if any (white without one).
    pub fn color(&self) -> Option<&PiecewiseLinear<3>> {
        self.color.as_ref()
    }
}

/// `1 − (1 − α)^step`: the opacity of a slab `step` voxels thick made of
/// material with opacity `α` per voxel.
#[inline]
pub fn correct_opacity(alpha: f32, step: f32) -> f32 {
    if step == 1.0 {
        alpha
    } else {
        1.0 - (1.0 - alpha).powf(step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_ramp_spans_p_to_q() {
        let c = Classifier::new((2.0, 6.0), OpacityMap::Ramp { p: 0.1, q: 0.5 }, None, 1.0);
        assert_eq!(c.sample_opacity(2.0), 0.1);
        assert!((c.sample_opacity(4.0) - 0.3).abs() < 1e-7);
        assert_eq!(c.sample_opacity(6.0), 0.5);
        assert_eq!(c.material(4.0), [1.0; 3]);
    }

    #[test]
    fn constant_volume_does_not_divide_by_zero() {
        let c = Classifier::new((3.0, 3.0), OpacityMap::Ramp { p: 0.2, q: 0.9 }, None, 1.0);
        assert_eq!(c.normalise(3.0), 0.0);
        assert_eq!(c.sample_opacity(3.0), 0.2);
    }

    #[test]
    fn step_correction_composes() {
        // Two half-voxel samples must be as opaque as one whole-voxel sample.
        let half = correct_opacity(0.6, 0.5);
        assert!((1.0 - (1.0 - half) * (1.0 - half) - 0.6).abs() < 1e-6);
        assert_eq!(correct_opacity(0.0, 0.37), 0.0);
        assert_eq!(correct_opacity(1.0, 0.37), 1.0);
        assert_eq!(correct_opacity(0.42, 1.0), 0.42);
    }

    #[test]
    fn zero_opacity_ranges_are_found_exactly() {
        let table = PiecewiseLinear::new(
            "opacity",
            vec![
                (0.0, [0.0]),
                (0.2, [0.0]),
                (0.5, [0.6]),
                (0.7, [0.0]),
                (0.8, [0.0]),
            ],
        )
        .unwrap();
        let c = Classifier::new((0.0, 10.0), OpacityMap::Table(table), None, 0.5);
        assert!(c.is_transparent_between(-3.0, 2.0));
        assert!(!c.is_transparent_between(-3.0, 2.01));
        // Both ends transparent, the bump between them is not.
        assert!(!c.is_transparent_between(1.0, 7.5));
        assert!(c.is_transparent_between(7.0, 100.0));
        assert!(!c.is_transparent_between(6.9, 100.0));
        // Whatever the test says, sampling agrees.
        for (lo, hi) in [(-3.0, 2.0), (7.0, 100.0)] {
            for i in 0..=100 {
                let f = lo + (hi - lo) * i as f32 / 100.0;
                assert_eq!(c.sample_opacity(f), 0.0, "{f}");
            }
        }
        let ramp = |p| Classifier::new((0.0, 1.0), OpacityMap::Ramp { p, q: 0.5 }, None, 1.0);
        assert!(ramp(0.0).is_transparent_between(-1.0, 0.0));
        assert!(!ramp(0.0).is_transparent_between(-1.0, 0.01));
        assert!(!ramp(0.1).is_transparent_between(-1.0, -0.5));
    }

    #[test]
    fn transfer_function_domain_and_fallbacks() {
        let tf = TransferFunction::from_json(
            r#"{"domain": [0, 10], "color": [[0, 1, 0, 0], [1, 0, 0, 1]]}"#,
        )
        .unwrap();
        let c = Classifier::from_transfer_function(&tf, (-5.0, 100.0), (0.0, 0.8), 1.0);
        assert_eq!(c.normalise(5.0), 0.5);
        assert_eq!(c.material(5.0), [0.5, 0.0, 0.5]);
        assert!((c.unit_opacity(5.0) - 0.4).abs() < 1e-7);
        // Beyond the domain the ramp holds its end value.
        assert_eq!(c.unit_opacity(50.0), 0.8);
    }
}
