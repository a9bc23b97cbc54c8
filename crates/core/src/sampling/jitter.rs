//! Jittered ray starts: a per-pixel offset of the sample planes against
//! wood-grain artifacts.
//!
//! Without jitter every ray samples at `t = k·step` (see [`crate::sampling::grid`]):
//! neighbouring rays sample the same depths, so the error of a coarse step
//! shows as bands that follow the sample planes ("wood grain"). Jitter moves
//! pixel (col, row)'s samples to `t = (k + u)·step` with `u` in [0, 1), which
//! turns the bands into fine noise (Engel et al., *Real-Time Volume
//! Graphics*, 2006, §9.1 "stochastic jittering").
//!
//! `u` is a hash of the pixel alone, not a random number: the same frame is
//! the same image every time and for any thread count, and both paths use
//! the same offsets.

/// The sample offset `u` in [0, 1) of pixel (`col`, `row`).
///
/// SplitMix64's finaliser (Steele, Lea & Flood, "Fast splittable
/// pseudorandom number generators", OOPSLA 2014) of the packed pixel
/// coordinates; its top 53 bits make a double in [0, 1).
#[inline]
pub fn offset(col: usize, row: usize) -> f64 {
    let mut z = (col as u64) << 32 ^ (row as u64 & 0xffff_ffff);
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_lie_in_the_unit_interval_and_spread_evenly() {
        // 64 × 64 pixels: the offsets fill [0, 1) evenly (each tenth holds
        // about a tenth of them) and neighbouring pixels differ.
        let mut bins = [0usize; 10];
        let mut same_as_left = 0;
        for row in 0..64 {
            for col in 0..64 {
                let u = offset(col, row);
                assert!((0.0..1.0).contains(&u), "{u}");
                bins[(u * 10.0) as usize] += 1;
                if col > 0 && offset(col - 1, row) == u {
                    same_as_left += 1;
                }
            }
        }
        for (i, &n) in bins.iter().enumerate() {
            assert!((330..=490).contains(&n), "tenth {i} holds {n} of 4096");
        }
        assert_eq!(same_as_left, 0);
    }

    #[test]
    fn offsets_depend_on_the_pixel_alone() {
        assert_eq!(offset(17, 3), offset(17, 3));
        assert_ne!(offset(17, 3), offset(3, 17));
    }
}
