//! Compositing: the colour of a ray from its samples (the paper's
//! transparency formula), and of a pixel from the partial pixels of
//! several pieces of a volume.
//!
//! Sample 0 is the nearest to the eye. Back to front (the paper, and the
//! reference path): `C_out = C_in·(1 − αᵢ) + Cᵢ·αᵢ`, from the last sample
//! down to 0, which sums to `C = Σ_j Cⱼ αⱼ Π_{i<j} (1 − αᵢ)`. Front to back
//! (the fast paths, [`FrontToBack`]) sums the same series in the other
//! order, keeping the transmittance `T = Π(1 − αᵢ)` of what lies in front;
//! once `T` is below [`TERMINATION_TRANSMITTANCE`], nothing behind can
//! change the colour by more than `T` and the ray stops (early ray
//! termination, Levoy 1990).
//!
//! **Partial pixels.** A ray's result is kept as its *premultiplied*
//! colour `C` and its transmittance `T`, `[r, g, b, T]`, with no
//! background: a partial pixel. The paper's opaque background is its last
//! sample; applying it is one more step, done once at the very end
//! ([`over_background`]): `C + T·background`, with the volume's opacity
//! `1 − T`. Two partial pixels of the same ray, from two pieces of the
//! volume that the ray crosses one after the other, combine by
//! [`over`] (Porter & Duff 1984): `C = C_front + T_front·C_back`,
//! `T = T_front·T_back`, which is exactly the compositing of the
//! concatenated samples, and is associative, so the pieces of a volume
//! split among threads or machines can be rendered apart and combined in
//! visibility order (sort-last compositing).

use glam::{DVec3, DVec4};
use wide::f32x4;

/// Rays stop when less than this fraction of light gets through: colours
/// are in [0, 1], so what lies behind could change the pixel by at most
/// this much, well under 1/255.
pub const TERMINATION_TRANSMITTANCE: f32 = 1.0 / 1024.0;

/// A ray's partial pixel: premultiplied colour and transmittance
/// `[r, g, b, T]`, no background. Nothing composited yet is `[0, 0, 0, 1]`.
pub type PartialPixel = [f32; 4];

/// The partial pixel of a ray that has taken no sample.
pub const EMPTY: PartialPixel = [0.0, 0.0, 0.0, 1.0];

/// Front-to-back accumulation along one ray: the colour so far in SIMD
/// lanes r, g, b (lane 3 unused), and the transmittance.
#[derive(Debug, Clone, Copy)]
pub struct FrontToBack {
    color: f32x4,
    transmittance: f32,
}

impl Default for FrontToBack {
    fn default() -> Self {
        Self::NEW
    }
}

impl FrontToBack {
    /// Nothing composited yet.
    pub const NEW: FrontToBack = FrontToBack {
        color: f32x4::ZERO,
        transmittance: 1.0,
    };

    /// Adds the sample `(r, g, b, α)` behind everything added so far:
    /// `C += T·α·c`, `T ·= 1 − α`.
    #[inline(always)]
    pub fn add(&mut self, sample: f32x4) {
        let alpha = sample.as_array()[3];
        self.color += sample * f32x4::splat(self.transmittance * alpha);
        self.transmittance *= 1.0 - alpha;
    }

    /// `Π(1 − αᵢ)` over the samples added.
    #[inline(always)]
    pub fn transmittance(&self) -> f32 {
        self.transmittance
    }

    /// Whether so little light gets through that the ray may stop
    /// ([`TERMINATION_TRANSMITTANCE`]).
    #[inline(always)]
    pub fn is_opaque(&self) -> bool {
        self.transmittance < TERMINATION_TRANSMITTANCE
    }

    /// The ray's partial pixel `[r, g, b, T]`.
    #[inline]
    pub fn partial(&self) -> PartialPixel {
        let [r, g, b, _] = self.color.to_array();
        [r, g, b, self.transmittance]
    }
}

/// `front` over `back`: the partial pixel of a ray that crosses the piece
/// of `front`, then the piece of `back`.
#[inline]
pub fn over(front: PartialPixel, back: PartialPixel) -> PartialPixel {
    let t = front[3];
    [
        front[0] + t * back[0],
        front[1] + t * back[1],
        front[2] + t * back[2],
        t * back[3],
    ]
}

/// The finished pixel of partial pixel `p` over the opaque `background`:
/// the colour `C + T·background` and, in alpha, the volume's accumulated
/// opacity `1 − T`.
#[inline]
pub fn over_background(p: PartialPixel, background: [f32; 3]) -> [f32; 4] {
    let t = p[3];
    [
        p[0] + t * background[0],
        p[1] + t * background[1],
        p[2] + t * background[2],
        1.0 - t,
    ]
}

/// What a caster writes for each ray: its partial pixel, for a compositor
/// to combine with others, or, where the ray is the whole story (one
/// process renders the whole volume), the finished pixel over the
/// background, applied as the ray's last step so that the frame needs no
/// second pass over its pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Finish {
    /// `[r, g, b, T]`, no background.
    Partial,
    /// [`over_background`] of the partial pixel.
    Over([f32; 3]),
}

impl Finish {
    /// The pixel written for a ray whose partial pixel is `p`.
    #[inline]
    pub fn apply(self, p: PartialPixel) -> [f32; 4] {
        match self {
            Finish::Partial => p,
            Finish::Over(background) => over_background(p, background),
        }
    }
}

/// The paper's back-to-front compositing of `samples` (r, g, b, α),
/// nearest first, in `f64`: the premultiplied colour in `xyz` and the
/// transmittance `Π(1 − αᵢ)` in `w` (the partial pixel; the background is
/// the last sample, [`over_background`]).
pub fn back_to_front(samples: &[DVec4]) -> DVec4 {
    let mut color = DVec3::ZERO;
    let mut transmittance = 1.0;
    for s in samples.iter().rev() {
        color = color * (1.0 - s.w) + s.truncate() * s.w;
        transmittance *= 1.0 - s.w;
    }
    color.extend(transmittance)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn front_to_back(samples: &[DVec4]) -> FrontToBack {
        let mut f = FrontToBack::NEW;
        for s in samples {
            f.add(f32x4::new(s.as_vec4().to_array()));
        }
        f
    }

    fn finish64(p: DVec4, bg: DVec3) -> DVec4 {
        (p.truncate() + p.w * bg).extend(1.0 - p.w)
    }

    /// Deterministic samples with colours and opacities all over [0, 1).
    fn mixed(n: usize, seed: f64) -> Vec<DVec4> {
        (0..n)
            .map(|i| {
                let x = i as f64 + seed;
                DVec4::new(
                    (x * 0.37).sin().abs(),
                    (x * 0.11).cos().abs(),
                    0.5,
                    0.3 * (x * 0.7).sin().abs(),
                )
            })
            .collect()
    }

    #[test]
    fn a_uniform_medium_has_the_closed_form_colour() {
        // K samples of colour c and opacity α over background bg:
        // c·(1 − (1 − α)^K) + bg·(1 − α)^K.
        let (c, alpha, bg) = (DVec3::new(0.9, 0.5, 0.1), 0.15, DVec3::new(0.0, 0.2, 1.0));
        for k in [0usize, 1, 2, 17, 100] {
            let samples = vec![c.extend(alpha); k];
            let keep = (1.0 - alpha).powi(k as i32);
            let want = (c * (1.0 - keep) + bg * keep).extend(1.0 - keep);
            let got = finish64(back_to_front(&samples), bg);
            assert!((got - want).abs().max_element() < 1e-12, "K = {k}");
            let fast = over_background(front_to_back(&samples).partial(), bg.as_vec3().into());
            let fast = DVec4::from(fast.map(f64::from));
            assert!((fast - want).abs().max_element() < 1e-5, "K = {k}");
        }
    }

    #[test]
    fn the_nearest_sample_wins_when_opaque() {
        let samples = [
            DVec4::new(1.0, 0.0, 0.0, 1.0),
            DVec4::new(0.0, 1.0, 0.0, 1.0),
        ];
        let want = DVec4::new(1.0, 0.0, 0.0, 1.0);
        assert_eq!(finish64(back_to_front(&samples), DVec3::ONE), want);
        let f = front_to_back(&samples);
        assert!(f.is_opaque());
        assert_eq!(over_background(f.partial(), [1.0; 3]), [1.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn both_orders_agree_on_mixed_samples() {
        let samples = mixed(40, 0.0);
        let bg = DVec3::new(0.2, 0.3, 0.4);
        let slow = finish64(back_to_front(&samples), bg);
        let fast = over_background(front_to_back(&samples).partial(), [0.2, 0.3, 0.4]);
        let diff = (DVec4::from(fast.map(f64::from)) - slow).abs();
        assert!(diff.max_element() < 1e-5, "{diff:?}");
    }

    #[test]
    fn over_equals_compositing_the_concatenated_samples() {
        // The samples of one ray cut into pieces at every place: each
        // piece composited alone, then the pieces combined by `over`.
        let samples = mixed(30, 3.0);
        let whole = front_to_back(&samples).partial();
        for cut in 0..=samples.len() {
            let (a, b) = samples.split_at(cut);
            let joined = over(front_to_back(a).partial(), front_to_back(b).partial());
            for c in 0..4 {
                assert!(
                    (joined[c] - whole[c]).abs() < 1e-6,
                    "cut {cut}: {joined:?} vs {whole:?}"
                );
            }
        }
        // In f64, exactly the back-to-front result of the whole ray.
        let (a, b) = samples.split_at(11);
        let (pa, pb) = (back_to_front(a), back_to_front(b));
        let joined = (pa.truncate() + pa.w * pb.truncate()).extend(pa.w * pb.w);
        assert!((joined - back_to_front(&samples)).abs().max_element() < 1e-15);
        // Nothing composited is the identity on either side.
        assert_eq!(over(EMPTY, whole), whole);
        assert_eq!(over(whole, EMPTY), whole);
    }

    #[test]
    fn over_is_associative() {
        let pieces: Vec<PartialPixel> = (0..12)
            .map(|i| front_to_back(&mixed(5 + i % 4, i as f64 * 1.7)).partial())
            .collect();
        let mut worst = 0.0f32;
        for w in pieces.windows(3) {
            let (a, b, c) = (w[0], w[1], w[2]);
            let left = over(over(a, b), c);
            let right = over(a, over(b, c));
            for k in 0..4 {
                worst = worst.max((left[k] - right[k]).abs());
            }
        }
        assert!(worst <= 1e-6, "{worst}");
    }
}
