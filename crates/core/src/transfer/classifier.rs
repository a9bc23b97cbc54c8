//! Stage 1 classification: a voxel's value → its material colour and opacity.
//!
//! The paper's default is opacity proportional to intensity on a
//! sub-interval `[p, q]` of [0, 1]:
//! `α = p + (f − fmin)/(fmax − fmin)·(q − p)`. A transfer function (see
//! [`crate::transfer::function`]) may replace the ramp and add a colour. Both
//! use the normalised scalar `t = (f − lo)/(hi − lo)`; for a constant volume
//! (`hi = lo`) `t` is 0 everywhere, so nothing divides by zero.
//!
//! Opacities are per unit distance of one voxel (the smallest spacing, the
//! paper's step). Sampling at another step `s` (in voxels) corrects each
//! voxel's opacity to `α_s = 1 − (1 − α)^s`, so that a ray through a uniform
//! medium gathers the same opacity per unit length whatever the step.
//!
//! Two options make opacity depend on the gradient as well as the value
//! ([`Classifier::opacity_at`]): Levoy's isovalue contours
//! ([`crate::transfer::iso`]), which replace the value's opacity by eq. 3 of Levoy
//! 1988 with `α_v` the opacity at the isovalue, and gradient-magnitude
//! opacity ([`crate::transfer::gradient_opacity`]), which multiplies it by a ramp of
//! `|∇f|`. Both act on the unit opacity, before the step correction.

use crate::kernels::gradient::magnitude;
use crate::transfer::function::{PiecewiseLinear, TransferFunction};
use crate::transfer::gradient_opacity::GradientOpacity;
use crate::transfer::iso::{IsoContour, IsoSurface};

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
    iso: Option<IsoContour>,
    gradient_opacity: Option<GradientOpacity>,
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
            iso: None,
            gradient_opacity: None,
        }
    }

    /// The same classifier drawing Levoy's isovalue contour of `iso`
    /// instead of the value's opacity, with `α_v` from [`Self::iso_alpha`]. `voxel_size` is the smallest grid spacing
    /// (the unit of the thickness) and `max_gradient` the largest world
    /// gradient magnitude of the volume ([`crate::kernels::gradient::max_magnitude`]),
    /// which bounds the contour for [`Self::is_transparent_between`].
    pub fn with_iso(mut self, iso: IsoSurface, voxel_size: f32, max_gradient: f32) -> Self {
        let alpha = self.iso_alpha(iso.value);
        self.iso = Some(IsoContour::new(iso, alpha, voxel_size, max_gradient));
        self
    }

    /// The same classifier with opacity multiplied by the ramp of
    /// `|∇f|/max_gradient` from 0 at `lo` to 1 at `hi`
    /// ([`crate::transfer::gradient_opacity`]).
    pub fn with_gradient_opacity(mut self, (lo, hi): (f32, f32), max_gradient: f32) -> Self {
        self.gradient_opacity = Some(GradientOpacity::new((lo, hi), max_gradient));
        self
    }

    /// Levoy's `α_v`, the opacity of the isovalue `f_v`: an opacity table's
    /// value at `f_v`, or with the paper's ramp its top opacity `q`. (The
    /// ramp's value at `f_v` would make a contour at a low value, the
    /// usual case for densities, all but invisible: the ramp spreads
    /// opacity over values, while a contour has the one value.)
    pub fn iso_alpha(&self, f_v: f32) -> f32 {
        match &self.opacity {
            OpacityMap::Ramp { q, .. } => *q,
            OpacityMap::Table(table) => table.eval(self.normalise(f_v))[0],
        }
    }

    /// Whether [`Self::opacity_at`] depends on the gradient (an iso-surface
    /// or gradient-magnitude opacity); if not, it is [`Self::sample_opacity`].
    #[inline]
    pub fn uses_gradient(&self) -> bool {
        self.iso.is_some() || self.gradient_opacity.is_some()
    }

    /// The iso-surface's contour, if any.
    pub fn iso(&self) -> Option<&IsoContour> {
        self.iso.as_ref()
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

    /// The classifier a frame of `settings` uses for a volume whose values
    /// span `value_range` (the transfer function's domain when it names
    /// none), whose smallest spacing is `voxel_size`, and whose largest
    /// gradient magnitude `max_gradient` gives (asked only for an
    /// iso-surface or gradient opacity without its own maximum): one
    /// definition for a renderer and for a renderer of pieces deciding
    /// which pieces to read.
    pub fn for_frame(
        settings: &crate::RenderSettings,
        value_range: (f32, f32),
        voxel_size: f32,
        max_gradient: impl Fn() -> f32,
    ) -> Self {
        let mut classifier = Classifier::from_transfer_function(
            &settings.transfer_function,
            value_range,
            settings.opacity_ramp,
            settings.step as f32,
        );
        if let Some(iso) = settings.iso {
            classifier = classifier.with_iso(iso, voxel_size, max_gradient());
        }
        if let Some(range) = settings.gradient_opacity {
            let max = settings.gradient_opacity_max.unwrap_or_else(&max_gradient);
            classifier = classifier.with_gradient_opacity(range, max);
        }
        classifier
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

    /// Opacity of one sample taken `step` voxels from the last, from the
    /// value alone: `α_s = 1 − (1 − α)^s`. This ignores an iso-surface and
    /// gradient-magnitude opacity; [`Self::opacity_at`] is the opacity.
    #[inline]
    pub fn sample_opacity(&self, f: f32) -> f32 {
        correct_opacity(self.unit_opacity(f), self.step_voxels)
    }

    /// Opacity of one sample of value `f` with world gradient `gradient`,
    /// taken `step` voxels from the last: the unit opacity (Levoy's
    /// contour for an iso-surface, else the value's), times the
    /// gradient-magnitude ramp if any, then corrected for the step. Without
    /// either option it is exactly [`Self::sample_opacity`].
    #[inline]
    pub fn opacity_at(&self, f: f32, gradient: [f32; 3]) -> f32 {
        if !self.uses_gradient() {
            return self.sample_opacity(f);
        }
        let g = magnitude(gradient);
        let mut alpha = match &self.iso {
            Some(iso) => iso.opacity(f, g),
            None => self.unit_opacity(f),
        };
        if let Some(ramp) = &self.gradient_opacity {
            alpha *= ramp.factor(g);
        }
        correct_opacity(alpha, self.step_voxels)
    }

    /// The same classification for samples `step_voxels` voxels apart
    /// (the shadow rays', `shadows`).
    pub fn with_step(&self, step_voxels: f32) -> Classifier {
        Classifier {
            step_voxels,
            ..self.clone()
        }
    }

    /// Whether every value in `[lo, hi]` gets zero opacity, so that a
    /// region whose values all lie there contributes nothing to any ray
    /// (the zero-opacity test of empty-space skipping, Levoy 1990),
    /// whatever the gradients in the volume. Exact: a piecewise-linear
    /// opacity is zero on an interval iff it is zero at the interval's ends
    /// and at every break point inside it. An iso-surface decides by the
    /// distance to its isovalue (see [`IsoContour::is_transparent_between`]);
    /// gradient-magnitude opacity only multiplies, so the value's test holds.
    pub fn is_transparent_between(&self, lo: f32, hi: f32) -> bool {
        if let Some(iso) = &self.iso {
            return iso.is_transparent_between(lo, hi);
        }
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

    /// The pixel colour of a projected value `f` (maximum, minimum or
    /// average intensity, see [`Blend`](crate::Blend)): the colour map of
    /// `f`'s normalised scalar, grey without one (`t` clamped to [0, 1]).
    pub fn projection_colour(&self, f: f32) -> [f32; 3] {
        match self.color() {
            Some(_) => self.material(f),
            None => [self.normalise(f).clamp(0.0, 1.0); 3],
        }
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

    /// A table with a zero stretch, a bump and a jump, over [0, 10].
    fn table_classifier(step: f32) -> Classifier {
        let table = PiecewiseLinear::new(
            "opacity",
            vec![(0.1, [0.0]), (0.4, [0.7]), (0.6, [0.2]), (0.6, [0.9])],
        )
        .unwrap();
        Classifier::new((0.0, 10.0), OpacityMap::Table(table), None, step)
    }

    #[test]
    fn without_options_opacity_at_is_the_value_opacity_to_the_bit() {
        for c in [
            table_classifier(0.37),
            Classifier::new((-1.0, 3.0), OpacityMap::Ramp { p: 0.1, q: 0.6 }, None, 1.0),
        ] {
            assert!(!c.uses_gradient());
            for i in 0..=200 {
                let f = -2.0 + 14.0 * i as f32 / 200.0;
                for g in [[0.0; 3], [1.0, -2.0, 0.5], [1e6, 0.0, 0.0]] {
                    assert_eq!(c.opacity_at(f, g).to_bits(), c.sample_opacity(f).to_bits());
                }
            }
        }
    }

    #[test]
    fn iso_opacity_is_levoys_contour_with_the_transfer_functions_alpha() {
        // α_v = q = 0.7 for the ramp 0.2..0.7 (not its 0.45 at f_v = 5); r = 3 voxels
        // of 0.5, so the contour reaches 1.5·|∇f| either side of 5.
        let iso = IsoSurface {
            value: 5.0,
            thickness: 3.0,
        };
        let ramp = Classifier::new((0.0, 10.0), OpacityMap::Ramp { p: 0.2, q: 0.7 }, None, 1.0);
        let c = ramp.clone().with_iso(iso, 0.5, 8.0);
        assert!(c.uses_gradient());
        let alpha_v = ramp.iso_alpha(5.0);
        assert_eq!(alpha_v, 0.7);
        assert_eq!(c.iso().unwrap().alpha(), alpha_v);
        let g = [0.0, 2.0, 0.0]; // |∇f| = 2: the contour spans 5 ± 3
        assert_eq!(c.opacity_at(5.0, g), alpha_v);
        assert!((c.opacity_at(6.0, g) - 0.7 * (2.0 / 3.0)).abs() < 1e-6);
        assert!((c.opacity_at(3.5, g) - 0.7 * 0.5).abs() < 1e-6);
        assert_eq!(c.opacity_at(8.0, g), 0.0);
        assert_eq!(c.opacity_at(1.0, g), 0.0);
        // The value's own opacity no longer counts: 10 is opaque on the ramp.
        assert_eq!(c.opacity_at(10.0, g), 0.0);
        assert_eq!(c.opacity_at(5.0, [0.0; 3]), alpha_v);
        assert_eq!(c.opacity_at(5.5, [0.0; 3]), 0.0);
        // The step corrects the contour's opacity as any other.
        let half = Classifier::new((0.0, 10.0), OpacityMap::Ramp { p: 0.2, q: 0.7 }, None, 0.5)
            .with_iso(iso, 0.5, 8.0);
        assert_eq!(
            half.opacity_at(6.0, g),
            correct_opacity(c.opacity_at(6.0, g), 0.5)
        );
        // Changing the iso-surface makes a different classifier (the fast
        // path reclassifies on any change).
        assert_ne!(c, ramp.with_iso(IsoSurface { value: 5.5, ..iso }, 0.5, 8.0));
    }

    #[test]
    fn iso_transparency_agrees_with_sampling_at_every_gradient() {
        // |∇f| <= 8 world units and r·h = 1.5: values within 12 of f_v = 5
        // may be opaque; the table's zero stretch below t = 0.1 no longer
        // matters.
        let iso = IsoSurface {
            value: 5.0,
            thickness: 3.0,
        };
        let c = table_classifier(0.6).with_iso(iso, 0.5, 8.0);
        assert!(!c.is_transparent_between(-20.0, -6.9));
        assert!(!c.is_transparent_between(16.9, 20.0));
        assert!(!c.is_transparent_between(4.0, 4.5));
        let transparent = [(-30.0f32, -7.1f32), (17.1, 40.0)];
        for (lo, hi) in transparent {
            assert!(c.is_transparent_between(lo, hi), "{lo}..{hi}");
        }
        // The test is sharp: just inside the reach a voxel is opaque.
        let steepest = [8.0, 0.0, 0.0];
        assert!(c.opacity_at(-6.9, steepest) > 0.0);
        assert!(c.opacity_at(16.9, steepest) > 0.0);
        for (lo, hi) in transparent {
            for i in 0..=100 {
                let f = lo + (hi - lo) * i as f32 / 100.0;
                for k in 0..=16 {
                    let g = [k as f32 * 0.3, -(k as f32) * 0.4, 0.0]; // |g| = k/2
                    assert_eq!(c.opacity_at(f, g), 0.0, "{f} {g:?}");
                }
            }
        }
        // α_v = 0 (f_v in the table's zero stretch): nothing is ever opaque.
        let hidden = table_classifier(1.0).with_iso(
            IsoSurface {
                value: 0.5,
                thickness: 3.0,
            },
            0.5,
            8.0,
        );
        assert!(hidden.is_transparent_between(-100.0, 100.0));
        assert_eq!(hidden.opacity_at(0.5, [1.0, 0.0, 0.0]), 0.0);
    }

    #[test]
    fn gradient_opacity_multiplies_the_value_opacity() {
        // Ramp from 0 at 25% to 1 at 75% of |∇f| = 4.
        let base = table_classifier(1.0);
        let c = base.clone().with_gradient_opacity((0.25, 0.75), 4.0);
        assert!(c.uses_gradient());
        let f = 4.0; // α = 0.7
        assert_eq!(base.opacity_at(f, [0.0; 3]), 0.7);
        assert_eq!(c.opacity_at(f, [0.0; 3]), 0.0);
        assert_eq!(c.opacity_at(f, [0.0, 0.0, -1.0]), 0.0);
        assert!((c.opacity_at(f, [0.0, 2.0, 0.0]) - 0.35).abs() < 1e-6);
        assert_eq!(c.opacity_at(f, [3.0, 0.0, 0.0]), 0.7);
        assert_eq!(c.opacity_at(f, [4.0, 0.0, 0.0]), 0.7);
        // Only a multiplier: the value's zero-opacity test stands.
        assert_eq!(
            c.is_transparent_between(0.0, 1.0),
            base.is_transparent_between(0.0, 1.0)
        );
        assert!(c.is_transparent_between(0.0, 1.0));
        assert!(!c.is_transparent_between(0.0, 1.1));
        // With an iso-surface, both apply: the contour times the ramp.
        let iso = IsoSurface {
            value: 4.0,
            thickness: 1.0,
        };
        let both = base
            .with_iso(iso, 1.0, 4.0)
            .with_gradient_opacity((0.25, 0.75), 4.0);
        assert!((both.opacity_at(4.5, [2.0, 0.0, 0.0]) - 0.7 * 0.75 * 0.5).abs() < 1e-6);
    }

    #[test]
    fn a_projected_value_takes_the_colour_map_of_its_normalised_value() {
        let ramp = OpacityMap::Ramp { p: 0.0, q: 0.5 };
        let grey = Classifier::new((2.0, 6.0), ramp.clone(), None, 1.0);
        assert_eq!(grey.projection_colour(3.0), [0.25; 3]);
        assert_eq!(grey.projection_colour(9.0), [1.0; 3]);
        assert_eq!(grey.projection_colour(0.0), [0.0; 3]);
        let red_blue = PiecewiseLinear::new(
            "color",
            vec![(0.0, [1.0, 0.0, 0.0]), (1.0, [0.0, 0.0, 1.0])],
        )
        .unwrap();
        let mapped = Classifier::new((2.0, 6.0), ramp, Some(red_blue), 1.0);
        assert_eq!(mapped.projection_colour(3.0), [0.75, 0.0, 0.25]);
    }
}
