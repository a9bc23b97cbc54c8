//! Blend modes: how the samples along a ray make the pixel.
//!
//! [`Blend::Composite`] is the paper's: classified, shaded samples
//! composited with the transparency formula (see [`crate::kernels::composite`]).
//! The others are projections of the interpolated *scalar* along the ray,
//! as VTK's `vtkVolumeMapper` blend modes MAXIMUM_INTENSITY,
//! MINIMUM_INTENSITY and AVERAGE_INTENSITY: the maximum, the minimum or the
//! mean of the values at the ray's samples (inside the cropped and clipped
//! part of the volume). The value is then shown through the colour map:
//! the pixel is the classifier's colour of the value's normalised scalar
//! `t`, opaque, with no shading and no opacity. Without a colour function
//! the map is grey, `t` clamped to [0, 1] (a white map would show nothing
//! but the volume's silhouette), so with `--range 0,1` a maximum intensity
//! pixel's grey level is the ray's maximum. A ray with no sample shows the
//! background.

use crate::settings::Blend;
use crate::transfer::classifier::Classifier;

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

/// The pixel colour of projected value `f`: the classifier's colour map of
/// `f`'s normalised scalar, grey without one.
pub fn projection_color(classifier: &Classifier, f: f32) -> [f32; 3] {
    match classifier.color() {
        Some(_) => classifier.material(f),
        None => [classifier.normalise(f).clamp(0.0, 1.0); 3],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::classifier::OpacityMap;
    use crate::transfer::function::PiecewiseLinear;

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

    #[test]
    fn colour_is_the_map_of_the_normalised_value() {
        let ramp = OpacityMap::Ramp { p: 0.0, q: 0.5 };
        let grey = Classifier::new((2.0, 6.0), ramp.clone(), None, 1.0);
        assert_eq!(projection_color(&grey, 3.0), [0.25; 3]);
        assert_eq!(projection_color(&grey, 9.0), [1.0; 3]);
        assert_eq!(projection_color(&grey, 0.0), [0.0; 3]);
        let red_blue = PiecewiseLinear::new(
            "color",
            vec![(0.0, [1.0, 0.0, 0.0]), (1.0, [0.0, 0.0, 1.0])],
        )
        .unwrap();
        let mapped = Classifier::new((2.0, 6.0), ramp, Some(red_blue), 1.0);
        assert_eq!(projection_color(&mapped, 3.0), [0.75, 0.0, 0.25]);
    }
}
