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

/// One ray's projection of its scalar samples: the running maximum,
/// minimum or sum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalarProjection {
    blend: Blend,
    value: f64,
    count: usize,
}

impl ScalarProjection {
    /// No sample yet. `blend` must be a projection (not
    /// [`Blend::Composite`], which is treated as the mean).
    pub fn new(blend: Blend) -> Self {
        let value = match blend {
            Blend::Maximum => f64::NEG_INFINITY,
            Blend::Minimum => f64::INFINITY,
            Blend::Average | Blend::Composite => 0.0,
        };
        ScalarProjection {
            blend,
            value,
            count: 0,
        }
    }

    /// Takes the next sample's value.
    #[inline]
    pub fn add(&mut self, f: f64) {
        self.value = match self.blend {
            Blend::Maximum => self.value.max(f),
            Blend::Minimum => self.value.min(f),
            Blend::Average | Blend::Composite => self.value + f,
        };
        self.count += 1;
    }

    /// The projected value, or `None` if the ray took no sample.
    pub fn value(&self) -> Option<f64> {
        match self.count {
            0 => None,
            n => Some(match self.blend {
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
        let project = |blend| {
            let mut p = ScalarProjection::new(blend);
            samples.iter().for_each(|&f| p.add(f));
            p.value()
        };
        assert_eq!(project(Blend::Maximum), Some(3.0));
        assert_eq!(project(Blend::Minimum), Some(-1.5));
        assert_eq!(project(Blend::Average), Some(0.625));
        assert_eq!(ScalarProjection::new(Blend::Maximum).value(), None);
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
