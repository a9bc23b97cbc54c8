//! Projections of the scalar along a ray (maximum, minimum, average; see
//! [`Blend`]): the running value of a ray, or of a piece of it, and how
//! pieces merge.

use crate::kernels::blend::Blend;

/// One ray's projection of its scalar samples so far: the running
/// maximum, minimum or sum, and how many samples it took. The same for a
/// piece of the ray: the projections of the pieces of one ray [`merge`]
/// into the ray's (the maximum of maxima, the sum of sums and counts), in
/// any order.
///
/// The fast maximum and minimum skip samples that cannot change the
/// result and count 1 for any number: for them only whether `count` is 0
/// matters.
///
/// [`merge`]: Projected::merge
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected {
    pub value: f64,
    pub count: u64,
}

impl Projected {
    /// No sample yet. `blend` must be a projection ([`Blend::Composite`]
    /// is treated as the mean).
    pub fn empty(blend: Blend) -> Self {
        let value = match blend {
            Blend::Maximum => f64::NEG_INFINITY,
            Blend::Minimum => f64::INFINITY,
            Blend::Average | Blend::Composite => 0.0,
        };
        Projected { value, count: 0 }
    }

    /// Takes the next sample's value.
    #[inline]
    pub fn add(&mut self, blend: Blend, f: f64) {
        self.value = match blend {
            Blend::Maximum => self.value.max(f),
            Blend::Minimum => self.value.min(f),
            Blend::Average | Blend::Composite => self.value + f,
        };
        self.count += 1;
    }

    /// The projection of the samples of `self` and of `other` together.
    #[inline]
    pub fn merge(self, blend: Blend, other: Projected) -> Projected {
        let value = match blend {
            Blend::Maximum => self.value.max(other.value),
            Blend::Minimum => self.value.min(other.value),
            Blend::Average | Blend::Composite => self.value + other.value,
        };
        Projected {
            value,
            count: self.count + other.count,
        }
    }

    /// The projected value, or `None` if the ray took no sample.
    pub fn value(&self, blend: Blend) -> Option<f64> {
        match self.count {
            0 => None,
            n => Some(match blend {
                Blend::Maximum | Blend::Minimum => self.value,
                Blend::Average | Blend::Composite => self.value / n as f64,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projections_of_known_samples() {
        let samples = [0.25, -1.5, 3.0, 0.75];
        let project = |blend, samples: &[f64]| {
            let mut p = Projected::empty(blend);
            samples.iter().for_each(|&f| p.add(blend, f));
            p
        };
        let value = |blend| project(blend, &samples).value(blend);
        assert_eq!(value(Blend::Maximum), Some(3.0));
        assert_eq!(value(Blend::Minimum), Some(-1.5));
        assert_eq!(value(Blend::Average), Some(0.625));
        assert_eq!(Projected::empty(Blend::Maximum).value(Blend::Maximum), None);
        // The pieces of a ray merge into the whole ray's projection, in
        // either order, with empty pieces changing nothing.
        for blend in [Blend::Maximum, Blend::Minimum, Blend::Average] {
            let whole = project(blend, &samples);
            for cut in 0..=samples.len() {
                let (a, b) = samples.split_at(cut);
                let (a, b) = (project(blend, a), project(blend, b));
                assert_eq!(a.merge(blend, b), whole, "{blend:?} cut {cut}");
                assert_eq!(b.merge(blend, a), whole, "{blend:?} cut {cut}");
            }
        }
    }
}
