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
//! Before the choice, the histogram is made **robust to outliers**
//! ([`robust_histogram`]): when the values between the [`ROBUST`] and
//! `1 − ROBUST` points of the finite voxels lie within fewer than
//! [`ZOOM_BINS`] of the bins (a few hot pixels stretch the range: the
//! bulk of the data sits in a bin or two), the data is histogrammed again
//! over the bins that hold them, narrowed to the values found there,
//! while that still zooms (at most [`MAX_PASSES`] more passes). The
//! transfer function is then chosen on the last histogram and spans its
//! window: the outliers above it take the top colour at full opacity.
//!
//! When the values **span decades** ([`spans_decades`]: those above the
//! background all positive, the top [`DECADES`] decades above the edge or
//! more, and half of them in the lowest [`LOG_MEDIAN`] of the ramp), the
//! front ends that hold the whole volume render its log10 instead, as
//! `--log` does, and say so.
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
use std::convert::Infallible;

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
/// The share of the finite voxels left out at each end of the robust
/// range: its ends are the 0.1 % and 99.9 % points. Hot and dead pixels
/// (cosmic rays on a detector, a saturated voxel) are typically well under
/// a thousandth of an image; at 0.01 % a 32³ grid would leave out only
/// three voxels at each end. A feature smaller than this is not hidden:
/// above the window it takes the top colour at full opacity.
pub const ROBUST: f64 = 1e-3;
/// The histogram is refined when the robust range lies within fewer than
/// this many of its [`BINS`] bins: the bulk of the data would then have
/// less than a sixteenth of the colour map. Every test fixture, the
/// built-in sources and the peers' volumes span more (their images are
/// unchanged: `scripts/same-images.sh`), while a few hot pixels put the
/// bulk in one bin or two.
pub const ZOOM_BINS: usize = 16;
/// At most this many passes after the first. Each pass narrows the window
/// to the values the robust bins hold, so that one outlier at 1e30 over
/// values 0..100 takes two (to the window 0..3.9e27, whose values are
/// 0..100; then 0..100).
pub const MAX_PASSES: usize = 4;
/// [`spans_decades`]: the share of the shown range (background edge to
/// top) below which half of the shown voxels lie.
pub const LOG_MEDIAN: f64 = 0.01;
/// [`spans_decades`]: the decades from the background edge to the top.
pub const DECADES: f64 = 2.0;

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

/// A histogram made robust to outliers by [`robust_histogram`]: the one
/// to choose from, and its window where it is narrower than the data's
/// range (the transfer function's domain, when none is given).
#[derive(Debug, Clone, PartialEq)]
pub struct Robust {
    pub histogram: Histogram,
    pub window: Option<(f32, f32)>,
}

/// The bins of the [`ROBUST`] and `1 − ROBUST` points of `histogram`'s
/// voxels (the bins holding the voxels of those ranks), or `None` for
/// an empty one.
pub fn robust_bins(histogram: &Histogram) -> Option<(usize, usize)> {
    let n: u64 = histogram.counts.iter().sum();
    if n == 0 {
        return None;
    }
    let k = (ROBUST * n as f64).floor() as u64;
    // The bin of the voxel of rank `r` (from 0) in increasing order.
    let bin_of = |r: u64| {
        let mut seen = 0;
        for (b, &c) in histogram.counts.iter().enumerate() {
            seen += c;
            if seen > r {
                return b;
            }
        }
        histogram.counts.len() - 1
    };
    Some((bin_of(k), bin_of(n - 1 - k)))
}

/// The window to histogram again when `histogram`'s robust range lies in
/// fewer than [`ZOOM_BINS`] bins: those bins, narrowed to the values the
/// histogram's range holds; `None` when it needs no refining or cannot
/// be refined (a window under `BINS` steps of f32 wide).
pub fn zoom(histogram: &Histogram) -> Option<(f32, f32)> {
    let (b0, b1) = robust_bins(histogram)?;
    if b1 + 1 - b0 >= ZOOM_BINS {
        return None;
    }
    let (within_lo, within_hi) = histogram.within?;
    // The bin edges rounded outwards to f32, then narrowed to the values.
    let (e0, e1) = (histogram.edge(b0), histogram.edge(b1 + 1));
    let lo = match e0 as f32 {
        lo if f64::from(lo) > e0 => lo.next_down(),
        lo => lo,
    };
    let hi = match e1 as f32 {
        hi if f64::from(hi) < e1 => hi.next_up(),
        hi => hi,
    };
    let (lo, hi) = (lo.max(within_lo), hi.min(within_hi));
    let resolution = BINS as f32 * f32::EPSILON * lo.abs().max(hi.abs());
    if hi - lo <= resolution || (lo, hi) == (histogram.min, histogram.max) {
        return None;
    }
    Some((lo, hi))
}

/// `first` (the histogram over the data's range, in [`BINS`] bins) made
/// robust to outliers: while its robust range lies in fewer than
/// [`ZOOM_BINS`] bins, the data histogrammed again over those bins
/// ([`zoom`]) by `pass` (the histogram in [`BINS`] bins of this window of
/// the data, values outside it counted in the end bins:
/// [`Histogram::of_box`] over a volume, its pieces merged, the ranks'
/// summed; `None` when the data has no finite value), at most
/// [`MAX_PASSES`] times. A pass whose window holds a single value (the
/// bulk is one value: nothing to spread over the colours) is not kept,
/// and ends the refining. When `first` needs no refining, `pass` is not
/// called and `first` is returned with no window: the choice is exactly
/// the one made on it. Every path calls this one loop with its own
/// `pass` (a distributed one must call it on every rank together: the
/// windows depend only on the summed counts, so every rank makes the same
/// passes).
pub fn robust_histogram<E>(
    first: Histogram,
    mut pass: impl FnMut((f32, f32)) -> Result<Option<Histogram>, E>,
) -> Result<Robust, E> {
    let mut robust = Robust {
        histogram: first,
        window: None,
    };
    for _ in 0..MAX_PASSES {
        let Some(window) = zoom(&robust.histogram) else {
            break;
        };
        let Some(next) = pass(window)? else {
            break;
        };
        match next.within {
            Some((lo, hi)) if hi > lo => {}
            _ => break,
        }
        robust = Robust {
            window: Some((next.min, next.max)),
            histogram: next,
        };
    }
    Ok(robust)
}

/// [`robust_histogram`] over a volume in memory.
pub fn robust_histogram_of(volume: &crate::Volume) -> Option<Robust> {
    let first = Histogram::of(volume, BINS)?;
    let whole = ([0; 3], volume.dims());
    let pass = |window| Ok::<_, Infallible>(Some(Histogram::of_box(volume, whole, window, BINS)));
    match robust_histogram(first, pass) {
        Ok(robust) => Some(robust),
        Err(never) => match never {},
    }
}

/// The transfer function chosen from `robust`, over `domain` (given) or
/// else its window (`None`: the data's range).
pub fn robust_transfer_function(robust: &Robust, domain: Option<(f64, f64)>) -> TransferFunction {
    let window = robust.window.map(|(lo, hi)| (f64::from(lo), f64::from(hi)));
    transfer_function(&robust.histogram, domain.or(window))
}

/// Whether values whose [`robust_histogram`] is `histogram` span
/// decades, so that `--tf auto` renders their log10 (as `--log` does):
/// the values shown (above the background edge) are all positive, their
/// top is at least [`DECADES`] decades above the edge, and a linear ramp
/// from the edge to the top would put half of them in its lowest
/// [`LOG_MEDIAN`] (their median under a hundredth of the way up: under
/// 10⁻⁴ of the opacity, the ramp being squared). The median is found on
/// one more histogram, over the shown window (`pass`: the histogram of
/// the data in [`BINS`] bins over a window, as for [`robust_histogram`]),
/// so that a hundredth of it is two and a half bins, and placed within
/// its bin by linear interpolation.
///
/// Why these numbers: above an edge `e`, a density falling as r⁻³ about
/// a point has as many voxels above `v` as `1/v`: its median is `2e` and
/// the 99.5 % top `200e`, the median 0.5 % of the way up. r⁻² gives
/// 1.8 %, a Gaussian blob (`e` at a twentieth of its peak) about 10 %, a
/// hydrogen orbital's exponential 5 %: these stay linear.
pub fn spans_decades<E>(
    histogram: &Histogram,
    pass: impl FnOnce((f32, f32)) -> Result<Option<Histogram>, E>,
) -> Result<bool, E> {
    let edge = background_edge(histogram).unwrap_or(f64::from(histogram.min));
    let top = top(histogram, edge);
    if edge <= 0.0 || top < 10f64.powf(DECADES) * edge {
        return Ok(false);
    }
    // The voxels below the edge, counted in the shown window's bin 0.
    let counts = &histogram.counts;
    let first = (0..counts.len())
        .find(|&b| histogram.edge(b + 1) > edge)
        .unwrap_or(counts.len());
    let below: u64 = counts[..first].iter().sum();
    let above: u64 = counts[first..].iter().sum();
    let Some(shown) = pass((edge as f32, top as f32))? else {
        return Ok(false);
    };
    // The median's rank among all voxels, placed within its bin by linear
    // interpolation (as a percentile from a histogram is).
    let target = below as f64 + above as f64 / 2.0;
    let mut seen = 0.0;
    for (b, &c) in shown.counts.iter().enumerate() {
        let c = c as f64;
        if c > 0.0 && seen + c >= target {
            let (lo, hi) = (shown.edge(b), shown.edge(b + 1));
            let median = lo + (hi - lo) * ((target - seen) / c).clamp(0.0, 1.0);
            return Ok(median - edge <= LOG_MEDIAN * (top - edge));
        }
        seen += c;
    }
    Ok(false)
}

/// [`spans_decades`] of a volume in memory: on its histogram over its
/// range or, where outliers refine it, on its [`robust_histogram`]. The
/// first asked first: on a fine grid the peak of a density falling over
/// decades is under a thousandth of the voxels, so that the refining
/// takes it for outliers (r⁻³ on 128³: its 99.9 % point is 0.4 % of its
/// peak), while its values do span decades; the second for decades that
/// a few hot pixels hide.
pub fn volume_spans_decades(volume: &crate::Volume) -> bool {
    let Some(first) = Histogram::of(volume, BINS) else {
        return false;
    };
    let whole = ([0; 3], volume.dims());
    let pass = |window| Ok::<_, Infallible>(Some(Histogram::of_box(volume, whole, window, BINS)));
    let spans = |h: &Histogram| match spans_decades(h, pass) {
        Ok(spans) => spans,
        Err(never) => match never {},
    };
    if spans(&first) {
        return true;
    }
    match robust_histogram(first, pass) {
        Ok(robust) => robust.window.is_some() && spans(&robust.histogram),
        Err(never) => match never {},
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Volume;

    fn histogram(counts: Vec<u64>, min: f32, max: f32) -> Histogram {
        Histogram {
            min,
            max,
            mean: 0.0,
            counts,
            non_finite: 0,
            within: Some((min, max)),
        }
    }

    /// Values 0..100 (i mod 101, in a 32×32×16 grid) with `hot` in its
    /// first `n` voxels.
    fn hot_pixels(hot: f32, n: usize) -> Volume {
        let data = (0..32 * 32 * 16)
            .map(|i| if i < n { hot } else { (i % 101) as f32 })
            .collect();
        Volume::new([32, 32, 16], data).unwrap()
    }

    #[test]
    fn hot_pixels_are_histogrammed_away_and_the_window_covers_the_values() {
        for hot in [1e6, 1e30] {
            let v = hot_pixels(hot, 5);
            // Today's histogram: everything in bin 0.
            let plain = Histogram::of(&v, BINS).unwrap();
            assert_eq!(plain.counts[0], 32 * 32 * 16 - 5, "{hot}");
            let robust = robust_histogram_of(&v).unwrap();
            assert_eq!(robust.window, Some((0.0, 100.0)), "{hot}");
            // Two passes: to 0..3906 (0..3.9e27), whose values are
            // 0..100, then 0..100 (a third is not needed).
            let mut windows = vec![];
            let whole = ([0; 3], v.dims());
            let counted = robust_histogram(plain.clone(), |w| {
                windows.push(w);
                Ok::<_, ()>(Some(Histogram::of_box(&v, whole, w, BINS)))
            })
            .unwrap();
            assert_eq!(counted, robust);
            assert_eq!(windows.len(), 2, "{windows:?}");
            assert_eq!(windows[0], (0.0, (hot as f64 / 256.0) as f32), "{hot}");
            let h = &robust.histogram;
            assert_eq!((h.min, h.max), (0.0, 100.0));
            // The hot pixels in the last bin, with the 100s.
            assert!(h.counts[BINS - 1] >= 5, "{hot}");
            let tf = robust_transfer_function(&robust, None);
            assert_eq!(tf.domain, Some((0.0, 100.0)));
            // No background peak (the values are uniform): the opacity
            // rises from 0 over the whole window, the hot pixels clamp
            // to the top at full opacity.
            let opacity = tf.opacity.unwrap();
            for t in [0.1, 0.5, 0.9] {
                assert!(opacity.eval(t)[0] > 0.0, "{hot} {t}");
            }
            assert_eq!(opacity.eval(1.0), [MAX_OPACITY]);
        }
    }

    #[test]
    fn ordinary_data_is_not_refined_and_chooses_as_before() {
        // A ramp, and a ball of 1 in zeros (most voxels in bin 0, but
        // the 99.9 % point in the top bin).
        let ramp = Volume::new([8, 8, 8], (0..512).map(|i| i as f32).collect()).unwrap();
        let ball = Volume::from_fn([16, 16, 16], glam::DVec3::ONE, glam::DVec3::ZERO, |p| {
            if (p - glam::DVec3::splat(7.5)).length() < 5.0 {
                1.0
            } else {
                0.0
            }
        })
        .unwrap();
        for v in [ramp, ball] {
            let plain = Histogram::of(&v, BINS).unwrap();
            let calls = std::cell::Cell::new(0);
            let robust = robust_histogram(plain.clone(), |_| {
                calls.set(calls.get() + 1);
                Ok::<_, ()>(None)
            })
            .unwrap();
            assert_eq!(calls.get(), 0);
            assert_eq!(
                robust,
                Robust {
                    histogram: plain.clone(),
                    window: None
                }
            );
            assert_eq!(
                robust_transfer_function(&robust, None),
                transfer_function(&plain, None)
            );
        }
    }

    #[test]
    fn a_bulk_of_one_value_is_not_zoomed_into() {
        // 99.95 % zeros and a few ones: the robust range is the zeros'
        // bin; its window holds one value, so the first histogram stays.
        let data = (0..32 * 32 * 16)
            .map(|i| if i < 8 { 1.0 } else { 0.0 })
            .collect();
        let v = Volume::new([32, 32, 16], data).unwrap();
        let robust = robust_histogram_of(&v).unwrap();
        assert_eq!(robust.window, None);
        assert_eq!(robust.histogram, Histogram::of(&v, BINS).unwrap());
    }

    #[test]
    fn the_passes_are_bounded_and_stop_at_the_f32_resolution() {
        // A pass that always puts everything in bin 0 of a window of
        // values: four passes, then the last histogram is kept.
        let bin_0 = |lo, hi| {
            let mut counts = vec![0; BINS];
            counts[0] = 1000;
            histogram(counts, lo, hi)
        };
        let mut windows = vec![];
        let robust = robust_histogram(bin_0(0.0, 1e30), |(lo, hi)| {
            windows.push((lo, hi));
            Ok::<_, ()>(Some(bin_0(lo, hi)))
        })
        .unwrap();
        assert_eq!(windows.len(), MAX_PASSES);
        // Each a 256th of the one before.
        assert_eq!(windows[0].1, 1e30 / 256.0);
        assert_eq!(robust.window, windows.last().copied());
        // A window of a few f32 steps: not refined.
        let one = 1.0f32;
        assert_eq!(zoom(&bin_0(one, one + 8.0 * f32::EPSILON)), None);
        assert!(zoom(&bin_0(one, 2.0)).is_some());
    }

    #[test]
    fn a_density_falling_as_the_cube_of_the_distance_spans_decades() {
        // r⁻³ about the centre of a 32³ grid: 1.5 down to 5e-5.
        let at = |p: glam::DVec3| (p - glam::DVec3::splat(15.5)).length();
        let power = |k: i32| {
            Volume::from_fn([32, 32, 32], glam::DVec3::ONE, glam::DVec3::ZERO, |p| {
                at(p).powi(-k) as f32
            })
            .unwrap()
        };
        let spans = volume_spans_decades;
        assert!(spans(&power(3)));
        // On 64³ its peak is refined away as outliers (its 99.9 % point is
        // 1 % of its peak), but its histogram over its range spans decades.
        let fine = Volume::from_fn([64, 64, 64], glam::DVec3::ONE, glam::DVec3::ZERO, |p| {
            (p - glam::DVec3::splat(31.5)).length().powi(-3) as f32
        })
        .unwrap();
        assert!(robust_histogram_of(&fine).unwrap().window.is_some());
        assert!(spans(&fine));
        // r⁻²: the median is 1.8 % of the way up.
        assert!(!spans(&power(2)));
        // A Gaussian blob in zeros, a ramp and the hot pixels do not.
        let blob = Volume::from_fn([32, 32, 32], glam::DVec3::ONE, glam::DVec3::ZERO, |p| {
            (-at(p).powi(2) / 50.0).exp() as f32
        })
        .unwrap();
        assert!(!spans(&blob));
        let ramp = Volume::new([8, 8, 8], (1..513).map(|i| i as f32).collect()).unwrap();
        assert!(!spans(&ramp));
        assert!(!spans(&hot_pixels(1e6, 5)));
        // Shown values that are not all positive: not a log scale.
        let shifted = power(3).values().iter().map(|v| v - 0.1).collect();
        assert!(!spans(&Volume::new([32, 32, 32], shifted).unwrap()));
    }
}
