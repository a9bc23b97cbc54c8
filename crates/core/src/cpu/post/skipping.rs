//! Which bricks and which sample values can add nothing to an image: the
//! bricks whose value range (widened for rounding) is transparent at every
//! gradient, and the transparent stretches at either end of the volume's
//! range ([`TransparentValues`]).

use crate::bricks::macrocells::Macrocells;
use crate::transfer::classifier::Classifier;

/// Bytes per brick of a frame's transparency flags ([`transparent_bricks`]).
pub(crate) const FRAME_BYTES_PER_BRICK: usize = size_of::<bool>();

/// A brick's value range is widened by this many `f32::EPSILON` of its
/// largest magnitude before the transparency test: twice the bound on how
/// far rounding can carry a trilinear sample past its voxels' range.
pub const RANGE_MARGIN: f32 = 16.0;

/// The values trilinear samples of voxels in `[lo, hi]` can take in `f32`:
/// the range widened by [`RANGE_MARGIN`]`·ε·max(|lo|, |hi|)`, unless all
/// the voxels are equal (see the module's notes on rounding).
pub fn sample_range((lo, hi): (f32, f32)) -> (f32, f32) {
    if lo < hi {
        let margin = RANGE_MARGIN * f32::EPSILON * lo.abs().max(hi.abs());
        (lo - margin, hi + margin)
    } else {
        (lo, hi)
    }
}

/// Whether each brick of `macrocells` is transparent under `classifier`
/// for every sample it can hold.
pub fn transparent_bricks(macrocells: &Macrocells, classifier: &Classifier) -> Vec<bool> {
    (macrocells.ranges.iter())
        .map(|&range| {
            let (lo, hi) = sample_range(range);
            classifier.is_transparent_between(lo, hi)
        })
        .collect()
}

/// The values that get zero opacity at every gradient at the bottom and
/// the top of the range samples can take: a sample whose value is among
/// them is passed over after its interpolation, before classifying it
/// (which costs a table search and, at steps other than 1, a power). Found
/// by bisection with [`Classifier::is_transparent_between`], which is
/// exact, so passing over them changes nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransparentValues {
    /// The range samples can take: the volume's, widened for rounding
    /// (see the module's notes).
    lowest: f32,
    highest: f32,
    /// `[lowest, below]` is transparent (`below = −∞`: no such values).
    below: f32,
    /// `[above, highest]` is transparent (`above = +∞`: none).
    above: f32,
}

impl TransparentValues {
    /// The transparent ends of the values samples of a volume whose values
    /// span `value_range` can take, under `classifier`.
    pub fn new(classifier: &Classifier, value_range: (f32, f32)) -> Self {
        let (lowest, highest) = sample_range(value_range);
        let transparent = |lo: f32, hi: f32| classifier.is_transparent_between(lo, hi);
        // The end of the transparent stretch from `from` towards `to`,
        // given that `from` itself is transparent and `to` is not: the
        // test is monotone (a part of a transparent interval is transparent).
        let bisect = |from: f32, to: f32, holds: &dyn Fn(f32) -> bool| {
            let (mut ok, mut bad) = (from, to);
            loop {
                let mid = ok / 2.0 + bad / 2.0;
                // Down to neighbouring floats.
                let between = if ok < bad {
                    ok < mid && mid < bad
                } else {
                    bad < mid && mid < ok
                };
                if !between {
                    return ok;
                }
                if holds(mid) {
                    ok = mid;
                } else {
                    bad = mid;
                }
            }
        };
        let (below, above) = if transparent(lowest, highest) {
            (highest, lowest)
        } else {
            let below = if transparent(lowest, lowest) {
                bisect(lowest, highest, &|x| transparent(lowest, x))
            } else {
                f32::NEG_INFINITY
            };
            let above = if transparent(highest, highest) {
                bisect(highest, lowest, &|x| transparent(x, highest))
            } else {
                f32::INFINITY
            };
            (below, above)
        };
        TransparentValues {
            lowest,
            highest,
            below,
            above,
        }
    }

    /// Whether a sample of value `f` has zero opacity whatever its gradient.
    #[inline]
    pub fn contains(&self, f: f32) -> bool {
        (self.lowest <= f && f <= self.below) || (self.above <= f && f <= self.highest)
    }
}

/// The volume's `(min, max)`, from its bricks' ranges.
pub(super) fn value_range(macrocells: &Macrocells) -> (f32, f32) {
    (macrocells.ranges.iter()).fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), r| {
        (lo.min(r.0), hi.max(r.1))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bricks::BrickGrid;
    use crate::transfer::classifier::OpacityMap;
    use crate::transfer::function::PiecewiseLinear;
    use crate::transfer::iso::IsoSurface;

    #[test]
    fn the_transparency_test_allows_for_rounding_past_a_bricks_range() {
        // Voxels a < b, and a sample on b's face (weight 1): in f32,
        // a + (b − a)·1 rounds to just above b. Under the paper's ramp over
        // [b, b + 1], zero exactly up to b, that sample is (faintly)
        // opaque, so a brick of values in [a, b] must not be skipped,
        // though the unwidened test calls [a, b] transparent.
        let (a, b) = (f32::from_bits(1043137375), f32::from_bits(1055846055));
        let sample = a + (b - a) * 1.0;
        assert!(a < b && sample > b, "{a} {b} {sample}");
        let ramp = OpacityMap::Ramp { p: 0.0, q: 0.5 };
        let classifier = Classifier::new((b, b + 1.0), ramp, None, 1.0);
        assert!(classifier.sample_opacity(sample) > 0.0);
        assert!(classifier.is_transparent_between(a, b));
        let brick = |range: (f32, f32)| Macrocells {
            grid: BrickGrid::new([9, 9, 9]),
            ranges: vec![range],
        };
        assert_eq!(transparent_bricks(&brick((a, b)), &classifier), [false]);
        // A brick of the one value b interpolates b exactly: skipped.
        assert_eq!(b + (b - b) * 0.37, b);
        assert_eq!(transparent_bricks(&brick((b, b)), &classifier), [true]);
        // Well below the ramp's foot the margin changes nothing.
        let lower = (a - 1.0, b - 1.0);
        assert_eq!(transparent_bricks(&brick(lower), &classifier), [true]);
    }

    #[test]
    fn transparent_values_are_exactly_the_zero_opacity_ends_of_the_range() {
        // Over [0, 10]: opacity zero up to t = 0.25 and from t = 0.9 on.
        let table =
            PiecewiseLinear::new("opacity", vec![(0.25, [0.0]), (0.5, [0.7]), (0.9, [0.0])])
                .unwrap();
        let c = Classifier::new((0.0, 10.0), OpacityMap::Table(table), None, 0.5);
        let v = TransparentValues::new(&c, (-2.0, 12.0));
        assert_eq!((v.below, v.above), (2.5, 9.0));
        // Just inside the visible stretch, the opacity is not zero.
        let (up, down) = (f32::from_bits(2.5f32.to_bits() + 1), 9.0f32.next_down());
        assert!(!v.contains(up) && c.sample_opacity(up) > 0.0);
        assert!(!v.contains(down) && c.sample_opacity(down) > 0.0);
        for i in 0..=1400 {
            let f = -2.0 + i as f32 / 100.0;
            assert_eq!(v.contains(f), c.sample_opacity(f) == 0.0, "{f}");
        }
        // With an iso-surface at 5 (thickness 1 voxel of 1, |∇f| <= 2),
        // values within 2 of it may be opaque, whatever the table says.
        let iso = IsoSurface {
            value: 5.0,
            thickness: 1.0,
        };
        let c = c.with_iso(iso, 1.0, 2.0);
        let v = TransparentValues::new(&c, (-2.0, 12.0));
        assert!((v.below - 3.0).abs() < 0.01 && v.below < 3.0, "{}", v.below);
        assert!((v.above - 7.0).abs() < 0.01 && v.above > 7.0, "{}", v.above);
        for i in 0..=1400 {
            let f = -2.0 + i as f32 / 100.0;
            if v.contains(f) {
                for k in 0..=20 {
                    let g = [0.1 * k as f32, 0.0, 0.0];
                    assert_eq!(c.opacity_at(f, g), 0.0, "{f} {g:?}");
                }
            }
        }
        // Opaque everywhere: nothing; transparent everywhere: everything.
        let ramp = |p| Classifier::new((0.0, 1.0), OpacityMap::Ramp { p, q: 0.5 }, None, 1.0);
        let v = TransparentValues::new(&ramp(0.1), (0.0, 1.0));
        assert!(!v.contains(0.0) && !v.contains(1.0));
        // The paper's ramp from 0: only the bottom of the domain.
        let v = TransparentValues::new(&ramp(0.0), (0.0, 1.0));
        assert_eq!(v.below, 0.0);
        assert!(v.contains(0.0) && !v.contains(1e-30) && !v.contains(1.0));
        let none = Classifier::new(
            (0.0, 1.0),
            OpacityMap::Table(PiecewiseLinear::constant([0.0])),
            None,
            1.0,
        );
        let v = TransparentValues::new(&none, (0.0, 1.0));
        assert!(v.contains(0.0) && v.contains(0.5) && v.contains(1.0));
    }
}
