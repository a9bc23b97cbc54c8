//! Compositing: the colour of a ray from its samples (the paper's
//! transparency formula).
//!
//! Sample 0 is the nearest to the eye; the opaque background is sample K.
//! Back to front (the paper, and the reference path):
//! `C_out = C_in·(1 − αᵢ) + Cᵢ·αᵢ`, from `i = K` down to 0, which sums to
//! `C = Σ_j Cⱼ αⱼ Π_{i<j} (1 − αᵢ)`. Front to back (the fast path) sums the
//! same series in the other order, keeping the transmittance `T = Π(1 − αᵢ)`
//! of what lies in front; once `T` is below a threshold, nothing behind can
//! change the colour by more than `T` and the ray stops (early ray
//! termination, Levoy 1990).

use glam::{DVec3, DVec4, Vec3, Vec4};

/// The paper's back-to-front compositing of `samples` (r, g, b, α), nearest
/// first, over an opaque `background`. Returns the colour and, in `w`, the
/// volume's accumulated opacity `1 − Π(1 − αᵢ)`.
pub fn back_to_front(samples: &[DVec4], background: DVec3) -> DVec4 {
    let mut color = background;
    let mut transmittance = 1.0;
    for s in samples.iter().rev() {
        color = color * (1.0 - s.w) + s.truncate() * s.w;
        transmittance *= 1.0 - s.w;
    }
    color.extend(1.0 - transmittance)
}

/// Front-to-back accumulation along one ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontToBack {
    color: Vec3,
    transmittance: f32,
}

impl Default for FrontToBack {
    fn default() -> Self {
        Self::new()
    }
}

impl FrontToBack {
    pub fn new() -> Self {
        FrontToBack {
            color: Vec3::ZERO,
            transmittance: 1.0,
        }
    }

    /// Adds the sample behind everything added so far: `(r, g, b, α)`.
    #[inline]
    pub fn add(&mut self, sample: Vec4) {
        let alpha = sample.w;
        self.color += (self.transmittance * alpha) * sample.truncate();
        self.transmittance *= 1.0 - alpha;
    }

    /// `Π(1 − αᵢ)` over the samples added.
    #[inline]
    pub fn transmittance(&self) -> f32 {
        self.transmittance
    }

    /// The final colour over the opaque `background`, with the volume's
    /// accumulated opacity in `w`.
    pub fn finish(&self, background: Vec3) -> Vec4 {
        (self.color + self.transmittance * background).extend(1.0 - self.transmittance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_medium_has_the_closed_form_colour() {
        // K samples of colour c and opacity α over background bg:
        // c·(1 − (1 − α)^K) + bg·(1 − α)^K.
        let (c, alpha, bg) = (DVec3::new(0.9, 0.5, 0.1), 0.15, DVec3::new(0.0, 0.2, 1.0));
        for k in [0usize, 1, 2, 17, 100] {
            let samples = vec![c.extend(alpha); k];
            let keep = (1.0 - alpha).powi(k as i32);
            let want = c * (1.0 - keep) + bg * keep;
            let got = back_to_front(&samples, bg);
            assert!(
                (got.truncate() - want).abs().max_element() < 1e-12,
                "K = {k}"
            );
            assert!((got.w - (1.0 - keep)).abs() < 1e-12);
            let mut f = FrontToBack::new();
            samples.iter().for_each(|s| f.add(s.as_vec4()));
            let fast = f.finish(bg.as_vec3());
            assert!(
                (fast.as_dvec4() - got).abs().max_element() < 1e-5,
                "K = {k}"
            );
        }
    }

    #[test]
    fn nearest_sample_wins_when_opaque() {
        let samples = [
            DVec4::new(1.0, 0.0, 0.0, 1.0),
            DVec4::new(0.0, 1.0, 0.0, 1.0),
        ];
        assert_eq!(
            back_to_front(&samples, DVec3::ONE),
            DVec4::new(1.0, 0.0, 0.0, 1.0)
        );
        let mut f = FrontToBack::new();
        samples.iter().for_each(|s| f.add(s.as_vec4()));
        assert_eq!(f.finish(Vec3::ONE), Vec4::new(1.0, 0.0, 0.0, 1.0));
    }

    #[test]
    fn orders_agree_on_mixed_samples() {
        let samples: Vec<DVec4> = (0..40)
            .map(|i| {
                let x = i as f64;
                DVec4::new(
                    (x * 0.37).sin().abs(),
                    (x * 0.11).cos().abs(),
                    0.5,
                    0.3 * (x * 0.7).sin().abs(),
                )
            })
            .collect();
        let bg = DVec3::new(0.2, 0.3, 0.4);
        let mut f = FrontToBack::new();
        samples.iter().for_each(|s| f.add(s.as_vec4()));
        let diff = (f.finish(bg.as_vec3()).as_dvec4() - back_to_front(&samples, bg)).abs();
        assert!(diff.max_element() < 1e-5, "{diff:?}");
    }
}
