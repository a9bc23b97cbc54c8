//! A transfer function chosen from a volume's histogram (`volray render
//! --tf auto`, and what the CLI uses when no `--tf`, `--preset` or
//! `--colormap` is given): the background transparent, what stands above
//! it shown in a perceptual colour map.
//!
//! Still the paper's model (pre-classified opacity and colour, Phong
//! shading); only the two functions are chosen:
//!
//! 1. **The background**: the histogram's highest bin, when it lies in the
//!    lower half of the value range (air around a CT, the zeros around a
//!    molecule's density, the empty space of a simulation). Its upper edge
//!    is where the counts, going up from the peak, first fall below
//!    [`TAIL`] of the peak's or stop falling (the valley after it). A
//!    volume whose most common value is in the upper half has no
//!    background: nothing is cut.
//! 2. **The top**: the value below which [`TOP`] of the voxels above the
//!    background lie (so that a few outliers do not squeeze the rest into
//!    the bottom of the scale).
//! 3. **Opacity**: zero up to the background's edge, then rising as the
//!    square of the distance from it to [`MAX_OPACITY`] at the top
//!    (in [`RAMP_POINTS`] linear pieces), constant above. Linear, the many
//!    low values around a feature (a blob's halo) veil its core in their
//!    dark colours; squared, the core shows through in its own.
//!    Opacity is per unit of voxel distance, as everywhere.
//! 4. **Colour**: [`COLORMAP`] (viridis: perceptually uniform, readable
//!    by the colour-blind, light at the top) from the background's edge to
//!    the top, so that what is shown spans the whole map.
//!
//! Like VTK's and ParaView's "reset to data range" with a ramp, and yt's
//! default of a colour map over the data's range, but with the background
//! peak cut, which is what a user does first in 3D Slicer's or napari's
//! transfer-function editor.
//!
//! ```
//! use volray_core::{Histogram, Volume};
//! use volray_core::transfer::auto;
//! use volray_core::glam::DVec3;
//!
//! // A ball of value 1 in a background of zeros.
//! let v = Volume::from_fn([16, 16, 16], DVec3::ONE, DVec3::ZERO, |p| {
//!     if (p - DVec3::splat(7.5)).length() < 5.0 { 1.0 } else { 0.0 }
//! })
//! .unwrap();
//! let h = Histogram::of(&v, auto::BINS).unwrap();
//! let tf = auto::transfer_function(&h, None);
//! let opacity = tf.opacity.unwrap();
//! assert_eq!(opacity.eval(0.0), [0.0]); // the background is transparent
//! assert_eq!(opacity.eval(1.0), [auto::MAX_OPACITY]);
//! ```

use crate::transfer::colormap;
use crate::transfer::function::{PiecewiseLinear, TransferFunction};
use crate::volume::histogram::Histogram;

/// Bins of the histogram the choice is made on.
pub const BINS: usize = 256;
/// The background ends where the counts fall below this share of its
/// peak's.
pub const TAIL: f64 = 0.05;
/// The opacity at the top of the range.
pub const MAX_OPACITY: f32 = 1.0;
/// The colour map over the range.
pub const COLORMAP: &str = "viridis";
/// The highest the background's edge may be, as a share of the range:
/// the top tenth is always shown.
pub const MAX_EDGE: f64 = 0.9;
/// The share of the voxels above the background that lie below the top.
pub const TOP: f64 = 0.995;
/// Linear pieces of the opacity's quadratic ramp.
pub const RAMP_POINTS: usize = 8;

/// The upper edge of the background peak of `histogram`, in the data's
/// units, or `None` when its most common values are in the upper half of
/// the range (see the module documentation).
pub fn background_edge(histogram: &Histogram) -> Option<f64> {
    let counts = &histogram.counts;
    let bins = counts.len();
    if bins < 2 || histogram.max <= histogram.min {
        return None;
    }
    // The first highest bin.
    let peak = (0..bins).fold(0, |best, b| if counts[b] > counts[best] { b } else { best });
    if 2 * peak >= bins {
        return None;
    }
    let floor = counts[peak] as f64 * TAIL;
    let mut b = peak;
    while b + 1 < bins && counts[b + 1] as f64 >= floor && counts[b + 1] <= counts[b] {
        b += 1;
    }
    let lo = f64::from(histogram.min);
    let top = lo + MAX_EDGE * (f64::from(histogram.max) - lo);
    Some(histogram.edge(b + 1).min(top))
}

/// The value below which [`TOP`] of the voxels above `edge` lie (the
/// upper edge of the bin where that share is reached), in the data's
/// units; the range's top when nothing lies above `edge`.
pub fn top(histogram: &Histogram, edge: f64) -> f64 {
    let counts = &histogram.counts;
    // The first bin wholly above the edge (a bin the edge cuts counts
    // as above: the edge is a bin edge, or the range's tenth).
    let first = (0..counts.len())
        .find(|&b| histogram.edge(b + 1) > edge)
        .unwrap_or(counts.len());
    let above: u64 = counts[first..].iter().sum();
    let mut seen = 0u64;
    for (b, &c) in counts.iter().enumerate().skip(first) {
        seen += c;
        if seen as f64 >= TOP * above as f64 && seen > 0 {
            return histogram.edge(b + 1);
        }
    }
    f64::from(histogram.max)
}

/// The transfer function chosen for values whose statistics are
/// `histogram`, over `domain` (the window `t = 0..1` spans, in the data's
/// units; `None`: the histogram's range).
pub fn transfer_function(histogram: &Histogram, domain: Option<(f64, f64)>) -> TransferFunction {
    let (lo, hi) = domain.unwrap_or((f64::from(histogram.min), f64::from(histogram.max)));
    let edge_value = background_edge(histogram).unwrap_or(f64::from(histogram.min));
    let top_value = top(histogram, edge_value);
    let to_t = |v: f64| {
        if hi > lo {
            ((v - lo) / (hi - lo)).clamp(0.0, 1.0) as f32
        } else {
            0.0
        }
    };
    let edge = to_t(edge_value).min(MAX_EDGE as f32);
    let top = to_t(top_value).max(edge);
    let mut points = vec![(0.0, [0.0])];
    if edge > 0.0 {
        points.push((edge, [0.0]));
    }
    // The ramp, quadratic in [`RAMP_POINTS`] linear pieces.
    for i in 1..=RAMP_POINTS {
        let s = i as f32 / RAMP_POINTS as f32;
        points.push((edge + s * (top - edge), [MAX_OPACITY * s * s]));
    }
    if top < 1.0 {
        points.push((1.0, [MAX_OPACITY]));
    }
    // The map's points moved onto [edge, top]; constant beyond.
    let map = colormap::colormap(COLORMAP).expect("a named colour map");
    let colours = (map.points().iter())
        .map(|&(t, rgb)| (edge + t * (top - edge), rgb))
        .collect();
    TransferFunction {
        domain,
        opacity: Some(PiecewiseLinear::new("opacity", points).expect("sorted points in [0, 1]")),
        color: Some(PiecewiseLinear::new("color", colours).expect("sorted points in [0, 1]")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn histogram(counts: Vec<u64>, min: f32, max: f32) -> Histogram {
        Histogram {
            min,
            max,
            mean: 0.0,
            counts,
            non_finite: 0,
        }
    }

    #[test]
    fn a_narrow_background_peak_ends_where_its_counts_fall_below_a_twentieth() {
        // Ten bins over 0..10: a peak of 1000 in bin 1, falling to 100
        // (still above 50) and then to 40: the edge is bin 3's lower edge.
        let h = histogram(vec![10, 1000, 100, 40, 60, 80, 60, 20, 10, 5], 0.0, 10.0);
        assert_eq!(background_edge(&h), Some(3.0));
    }

    #[test]
    fn the_background_ends_at_the_valley_after_its_peak() {
        // Falling from 1000 to 300, then rising again (the tissue's own
        // peak): the valley's bin is the last of the background.
        let h = histogram(
            vec![1000, 500, 300, 400, 900, 10, 10, 10, 10, 10],
            -5.0,
            5.0,
        );
        assert_eq!(background_edge(&h), Some(-2.0));
    }

    #[test]
    fn a_most_common_value_in_the_upper_half_is_no_background() {
        let h = histogram(vec![1, 2, 3, 4, 5, 60, 5, 4, 3, 2], 0.0, 1.0);
        assert_eq!(background_edge(&h), None);
        let tf = transfer_function(&h, None);
        // The whole range ramps up from 0 to the top: 99.5 % of the 89
        // voxels is reached only in the last bin.
        let opacity = tf.opacity.unwrap();
        assert_eq!(opacity.points().len(), 1 + RAMP_POINTS);
        assert_eq!(opacity.eval(0.0), [0.0]);
        assert_eq!(opacity.eval(0.5), [MAX_OPACITY / 4.0]);
        assert_eq!(opacity.eval(1.0), [MAX_OPACITY]);
    }

    #[test]
    fn a_background_spanning_the_range_still_leaves_the_top_tenth() {
        let h = histogram(vec![100, 99, 98, 97, 96, 95, 94, 93, 92, 91], 0.0, 1.0);
        assert_eq!(background_edge(&h), Some(0.9));
    }

    #[test]
    fn the_top_leaves_out_the_last_half_percent_above_the_background() {
        // 1000 voxels above the background edge (3): 995 of them lie below
        // 8, the upper edge of bin 7.
        let h = histogram(vec![10, 5000, 500, 0, 400, 300, 200, 95, 4, 1], 0.0, 10.0);
        assert_eq!(background_edge(&h), Some(3.0));
        assert_eq!(top(&h, 3.0), 8.0);
        // Nothing above the edge: the range's top.
        assert_eq!(top(&histogram(vec![9, 0, 0, 0], 0.0, 4.0), 1.0), 4.0);
    }

    #[test]
    fn opacity_ramps_and_colours_span_from_the_edge_to_the_top_in_the_window_given() {
        // Edge 3, top 8; the window 2..12 puts them at t = 0.1 and 0.6.
        let h = histogram(vec![10, 5000, 500, 0, 400, 300, 200, 95, 4, 1], 0.0, 10.0);
        let tf = transfer_function(&h, Some((2.0, 12.0)));
        assert_eq!(tf.domain, Some((2.0, 12.0)));
        let opacity = tf.opacity.unwrap();
        let points = opacity.points();
        assert_eq!(points[..2], [(0.0, [0.0]), (0.1, [0.0])]);
        assert_eq!(
            points[points.len() - 2..],
            [(0.6, [MAX_OPACITY]), (1.0, [MAX_OPACITY])]
        );
        // Half way from the edge to the top: a quarter of the opacity.
        let [a] = opacity.eval(0.35);
        assert!((a - MAX_OPACITY / 4.0).abs() < 1e-6, "{a}");
        assert_eq!(opacity.eval(0.05), [0.0]);
        assert_eq!(opacity.eval(0.8), [MAX_OPACITY]);
        // Viridis from the edge (dark purple) to the top (yellow).
        let viridis = colormap::colormap(COLORMAP).unwrap();
        let color = tf.color.unwrap();
        assert_eq!(color.eval(0.0), viridis.eval(0.0));
        assert_eq!(color.eval(0.1), viridis.eval(0.0));
        assert_eq!(color.eval(0.6), viridis.eval(1.0));
        assert_eq!(color.eval(1.0), viridis.eval(1.0));
        let [r, g, b] = color.eval(0.1);
        assert!(b > r && b > g, "{r} {g} {b}");
        let [r, g, b] = color.eval(0.6);
        assert!(r > b && g > b, "{r} {g} {b}");
    }
}
