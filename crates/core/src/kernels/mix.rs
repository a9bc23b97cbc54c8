//! Mixing the samples of several volumes at one point of a ray into one
//! sample (`scene`'s composite mix): the opacity-weighted colour
//! `c = Σ αᵢcᵢ / Σ αᵢ` and the opacity of the volumes together,
//! `α = 1 − Π(1 − αᵢ)` (the light that gets through each volume's sample
//! gets through all of them: independent absorbers, Cai and Sakas 1999).
//! One sample is left as it is (up to rounding in `αc/α`); samples of zero
//! opacity change nothing; a sample of opacity 1 makes the mix opaque.
//! The sample is then composited like any other
//! ([`crate::kernels::composite`]).

use glam::{DVec3, DVec4};
use wide::f32x4;

/// The mix of samples `(r, g, b, α)`, in `f64` (the reference path).
pub fn mix_reference(samples: impl IntoIterator<Item = DVec4>) -> DVec4 {
    let (mut weighted, mut weight, mut keep) = (DVec3::ZERO, 0.0, 1.0);
    for s in samples {
        weighted += s.truncate() * s.w;
        weight += s.w;
        keep *= 1.0 - s.w;
    }
    if weight > 0.0 {
        (weighted / weight).extend(1.0 - keep)
    } else {
        DVec4::ZERO
    }
}

/// The running mix of samples `(r, g, b, α)` in `f32` lanes (the fast path).
#[derive(Debug, Clone, Copy)]
pub struct Mixer {
    /// `Σ αᵢ·(rᵢ, gᵢ, bᵢ, 1)`: the weighted colours, and the weight in lane 3.
    weighted: f32x4,
    /// `Π(1 − αᵢ)`.
    keep: f32,
}

impl Mixer {
    /// No sample yet.
    pub const NEW: Mixer = Mixer {
        weighted: f32x4::ZERO,
        keep: 1.0,
    };

    /// Adds one volume's sample.
    #[inline(always)]
    pub fn add(&mut self, sample: f32x4) {
        let alpha = sample.as_array()[3];
        // (r, g, b, α)·α with lane 3 set to α: the weight.
        let [r, g, b, _] = (sample * f32x4::splat(alpha)).to_array();
        self.weighted += f32x4::new([r, g, b, alpha]);
        self.keep *= 1.0 - alpha;
    }

    /// The mixed sample `(r, g, b, α)`, or `None` if every sample was
    /// transparent.
    #[inline(always)]
    pub fn sample(&self) -> Option<f32x4> {
        let [r, g, b, weight] = self.weighted.to_array();
        (weight > 0.0).then(|| {
            let inv = 1.0 / weight;
            f32x4::new([r * inv, g * inv, b * inv, 1.0 - self.keep])
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sample_is_itself_and_transparent_ones_change_nothing() {
        let s = DVec4::new(0.2, 0.5, 0.9, 0.3);
        let m = mix_reference([s, DVec4::new(1.0, 1.0, 1.0, 0.0)]);
        assert!((m - s).abs().max_element() < 1e-15, "{m:?}");
        assert_eq!(mix_reference([DVec4::new(1.0, 0.0, 0.0, 0.0)]), DVec4::ZERO);
        let mut f = Mixer::NEW;
        f.add(f32x4::new([0.2, 0.5, 0.9, 0.3]));
        f.add(f32x4::new([1.0, 1.0, 1.0, 0.0]));
        let got = f.sample().unwrap().to_array();
        for (g, w) in got.iter().zip([0.2, 0.5, 0.9, 0.3]) {
            assert!((g - w).abs() < 1e-6, "{got:?}");
        }
        assert!(Mixer::NEW.sample().is_none());
    }

    #[test]
    fn the_mix_is_the_weighted_colour_of_independent_absorbers() {
        // Red at 0.5 and blue at 0.25: opacity 1 − 0.5·0.75 = 0.625; colour
        // (0.5·red + 0.25·blue)/0.75 = (2/3, 0, 1/3).
        let m = mix_reference([
            DVec4::new(1.0, 0.0, 0.0, 0.5),
            DVec4::new(0.0, 0.0, 1.0, 0.25),
        ]);
        let want = DVec4::new(2.0 / 3.0, 0.0, 1.0 / 3.0, 0.625);
        assert!((m - want).abs().max_element() < 1e-15, "{m:?}");
        let mut f = Mixer::NEW;
        f.add(f32x4::new([1.0, 0.0, 0.0, 0.5]));
        f.add(f32x4::new([0.0, 0.0, 1.0, 0.25]));
        let got = f.sample().unwrap().to_array();
        for (g, w) in got.iter().zip(want.to_array()) {
            assert!((f64::from(*g) - w).abs() < 1e-6, "{got:?}");
        }
        // An opaque sample makes the mix opaque, whatever the others.
        let m = mix_reference([
            DVec4::new(0.0, 1.0, 0.0, 1.0),
            DVec4::new(1.0, 0.0, 0.0, 0.4),
        ]);
        assert_eq!(m.w, 1.0);
    }
}
