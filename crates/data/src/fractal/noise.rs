//! The fractal's random numbers: one standard normal per (seed, level,
//! stream, point), independent of the order in which points are visited.
//!
//! A point's number must not depend on scheduling, so there is no shared
//! generator. Instead each point seeds its own PCG generator
//! (`rand_pcg::Pcg64Mcg`, O'Neill's 128-bit MCG with XSL-RR output) from a
//! hash of its identity, and draws one Gaussian from it with
//! `rand_distr::StandardNormal` (a ziggurat, which occasionally takes a
//! second word from the generator). The hash is the SplitMix64 finaliser
//! (Steele, Lea & Flood, "Fast splittable pseudorandom number generators",
//! OOPSLA 2014; the constants of Vigna's `splitmix64.c`), a bijection on
//! `u64` whose output bits each depend on every input bit.
//!
//! A point is identified by its coordinates on its level's own grid: level
//! `l` has `2^l + 1` points per side with spacing `h = (n − 1)/2^l`, so point
//! `(x, y, z)` of the full grid is `(x/h, y/h, z/h)` there. Level `l` thus
//! draws the same numbers for a 129³ and a 257³ grid, which makes the raw
//! midpoint-displacement field of size `n` an exact decimation of the one
//! of size `2n − 1` with the same seed.

use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;

/// The SplitMix64 finaliser ("mix13" variant of Stafford): a bijection with
/// full avalanche.
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The SplitMix64 increment, 2^64/φ rounded to odd.
const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// Which of a level's two kinds of random numbers a stream holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// Displacements of the points a level creates (level 0: the corners).
    Displacement,
    /// Voss's random additions to every point present after the level.
    Addition,
}

/// The key of one (seed, level, stream): every point draws from a
/// generator seeded by this key and the point's index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamKey(u64);

impl StreamKey {
    /// The key for `seed`, refinement `level` (0 for the corners) and
    /// `stream`.
    pub fn new(seed: u64, level: u32, stream: Stream) -> Self {
        let tag = 2 * u64::from(level)
            + match stream {
                Stream::Displacement => 0,
                Stream::Addition => 1,
            };
        StreamKey(mix64(
            mix64(seed).wrapping_add(tag.wrapping_add(1).wrapping_mul(GOLDEN_GAMMA)),
        ))
    }

    /// The standard normal number of point `index` in this stream.
    ///
    /// The 128-bit generator state is two successive SplitMix64 outputs
    /// started from the key plus the index times the SplitMix64 increment,
    /// so neighbouring indices get unrelated states.
    pub fn normal(self, index: u64) -> f64 {
        let start = self.0.wrapping_add(index.wrapping_mul(GOLDEN_GAMMA));
        let hi = mix64(start);
        let lo = mix64(start.wrapping_add(GOLDEN_GAMMA));
        let mut rng = Pcg64Mcg::new((u128::from(hi) << 64) | u128::from(lo));
        StandardNormal.sample(&mut rng)
    }
}

/// The index of point `(x, y, z)` of a grid with `step` between the points
/// of level `level` (`step = (n − 1)/2^level`), on that level's own grid of
/// `2^level + 1` points per side, x fastest.
pub fn level_index(level: u32, step: usize, x: usize, y: usize, z: usize) -> u64 {
    debug_assert!(step.is_power_of_two());
    debug_assert!(x.is_multiple_of(step) && y.is_multiple_of(step) && z.is_multiple_of(step));
    let side = (1u64 << level) + 1;
    // step is a power of two: shift rather than divide (this is per point).
    let shift = step.trailing_zeros();
    let (x, y, z) = (
        (x >> shift) as u64,
        (y >> shift) as u64,
        (z >> shift) as u64,
    );
    x + side * (y + side * z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mix64_matches_splitmix64_reference_outputs() {
        // splitmix64.c seeded with 0 outputs mix64(γ), mix64(2γ), ...:
        // 0xe220a8397b1dcdaf, 0x6e789e6aa1b965f4, 0x06c45d188009454f.
        assert_eq!(mix64(GOLDEN_GAMMA), 0xe220_a839_7b1d_cdaf);
        assert_eq!(mix64(GOLDEN_GAMMA.wrapping_mul(2)), 0x6e78_9e6a_a1b9_65f4);
        assert_eq!(mix64(GOLDEN_GAMMA.wrapping_mul(3)), 0x06c4_5d18_8009_454f);
    }

    #[test]
    fn streams_are_deterministic_and_distinct() {
        let a = StreamKey::new(1, 3, Stream::Displacement);
        assert_eq!(a, StreamKey::new(1, 3, Stream::Displacement));
        assert_eq!(a.normal(17), a.normal(17));
        for other in [
            StreamKey::new(2, 3, Stream::Displacement),
            StreamKey::new(1, 4, Stream::Displacement),
            StreamKey::new(1, 3, Stream::Addition),
        ] {
            assert_ne!(a, other);
            assert_ne!(a.normal(17), other.normal(17));
        }
        assert_ne!(a.normal(17), a.normal(18));
    }

    #[test]
    fn draws_are_standard_normal_and_uncorrelated() {
        // 200 000 draws: mean, variance, fourth moment and the correlation
        // of neighbouring indices against their standard errors (about 5 of
        // them: a deterministic check, far from the edge).
        let key = StreamKey::new(7, 5, Stream::Displacement);
        let n = 200_000;
        let z: Vec<f64> = (0..n).map(|i| key.normal(i)).collect();
        let nf = n as f64;
        let mean = z.iter().sum::<f64>() / nf;
        let var = z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / nf;
        let m4 = z.iter().map(|v| v.powi(4)).sum::<f64>() / nf;
        let lag1 = z.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (nf - 1.0);
        assert!(mean.abs() < 5.0 / nf.sqrt(), "mean {mean}");
        // Var of the sample variance of N(0,1) is 2/n; of the 4th moment 96/n.
        assert!((var - 1.0).abs() < 5.0 * (2.0 / nf).sqrt(), "var {var}");
        assert!((m4 - 3.0).abs() < 5.0 * (96.0 / nf).sqrt(), "m4 {m4}");
        assert!(lag1.abs() < 5.0 / nf.sqrt(), "lag-1 correlation {lag1}");
        // Tails: P(|z| > 3) = 0.0026998.
        let tail = z.iter().filter(|v| v.abs() > 3.0).count() as f64 / nf;
        let p = 0.002_699_8;
        assert!((tail - p).abs() < 5.0 * (p / nf).sqrt(), "tail {tail}");
    }

    #[test]
    fn level_indices_are_shared_across_grid_sizes() {
        // Level 2 point (1, 2, 3) on its 5-point grid: 1 + 5·(2 + 5·3) = 86,
        // whether the full grid has spacing 4 (17³) or 8 (33³) there.
        assert_eq!(level_index(2, 4, 4, 8, 12), 86);
        assert_eq!(level_index(2, 8, 8, 16, 24), 86);
        assert_eq!(level_index(0, 16, 16, 16, 16), 7);
        assert_eq!(level_index(0, 16, 16, 0, 0), 1);
    }
}
