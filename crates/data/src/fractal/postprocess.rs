//! The paper's post-processing of a fractal field into a cloud: "the data
//! were modulated by a decreasing ramp before thresholding", then "a
//! suitable threshold value was subtracted uniformly from the values at
//! every point and among the resulting values the negative ones were
//! replaced by zeros".
//!
//! volray's shape, in place, per point:
//!
//! ```text
//! f̂ = (f − min f)/(max f − min f)            ∈ [0, 1]  (0 if f is constant)
//! r = |p|,  p the point's position on [−1, 1]³   (0 at the centre, 1 at the face centres)
//! w = clamp((1 − r)/ramp, 0, 1)              1 inside r ≤ 1 − ramp, falling linearly to 0 at r = 1
//! v = max(f̂·w − threshold, 0)
//! ```
//!
//! Scaling to `[0, 1]` first gives `threshold` the same meaning for every
//! σ, D and seed: the fraction of the field's range cut away. The ramp
//! fades the cloud out before the inscribed sphere, so every point with
//! `r ≥ 1` (all of the grid's faces) is empty and no cloud is cut by the
//! cube; `ramp = 1` is the peers' `clip(1 − r, 0, 1)`, a cone from the
//! centre.

use rayon::prelude::*;

use crate::grid::coordinate;

/// Ramps and thresholds the field in `data` (`n³` values, x fastest).
pub(super) fn apply(data: &mut [f32], n: usize, ramp: f64, threshold: f64) {
    let (lo, hi) = data
        .par_chunks(n * n)
        .map(|plane| {
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for &v in plane {
                lo = if v < lo { v } else { lo };
                hi = if v > hi { v } else { hi };
            }
            (lo, hi)
        })
        .reduce(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let (lo, range) = (f64::from(lo), f64::from(hi) - f64::from(lo));
    // Inside r ≤ 1 − ramp the weight is exactly 1, outside r ≥ 1 exactly 0:
    // compare squared radii there and take the square root only between.
    let flat = (1.0 - ramp).powi(2);
    let coords: Vec<f64> = (0..n).map(|i| coordinate(i, n)).collect();
    data.par_chunks_mut(n * n)
        .zip(coords.par_iter())
        .for_each(|(plane, &z)| {
            for (row, &y) in plane.chunks_mut(n).zip(&coords) {
                let yz = y * y + z * z;
                for (v, &x) in row.iter_mut().zip(&coords) {
                    let r2 = x * x + yz;
                    if r2 >= 1.0 {
                        *v = 0.0;
                        continue;
                    }
                    let w = if r2 <= flat {
                        1.0
                    } else {
                        ((1.0 - r2.sqrt()) / ramp).clamp(0.0, 1.0)
                    };
                    let scaled = if range > 0.0 {
                        (f64::from(*v) - lo) / range
                    } else {
                        0.0
                    };
                    *v = (scaled * w - threshold).max(0.0) as f32;
                }
            }
        });
}
