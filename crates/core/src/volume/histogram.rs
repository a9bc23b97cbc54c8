//! Value statistics of a volume: the range, mean and a histogram, for
//! `volray info` and for choosing transfer functions.

use crate::volume::Sample;
use crate::{Volume, with_samples};

/// Summary statistics over a volume's finite values.
#[derive(Debug, Clone, PartialEq)]
pub struct Histogram {
    /// Smallest and largest finite value (equal for a constant volume).
    pub min: f32,
    pub max: f32,
    /// Mean of the finite values, accumulated in f64.
    pub mean: f64,
    /// Counts per bin: bin `b` holds values in
    /// `[min + b·w, min + (b+1)·w)` with `w = (max − min)/bins`; the last
    /// bin also holds `max`. A constant volume puts everything in bin 0.
    pub counts: Vec<u64>,
    /// Number of NaN and infinite values (not in any bin).
    pub non_finite: u64,
    /// The smallest and largest finite value within `min..=max`; `None`
    /// when none lies there. Over the data's own range these are `min`
    /// and `max`; over a narrower window ([`Histogram::of_box`]) the
    /// values outside are counted in the end bins but not here, so that
    /// the window can be narrowed to the values it holds
    /// ([`crate::transfer::auto::robust_histogram`]).
    pub within: Option<(f32, f32)>,
}

impl Histogram {
    /// The statistics of `volume` with `bins` bins (at least 1), or `None`
    /// if it has no finite value.
    pub fn of(volume: &Volume, bins: usize) -> Option<Self> {
        let bins = bins.max(1);
        let (min, max) = volume.value_range()?;
        let mut counts = vec![0u64; bins];
        let width = (f64::from(max) - f64::from(min)) / bins as f64;
        // Read in the volume's own type (no f32 copy of a 16-bit volume).
        let (sum, non_finite, _) = with_samples!(volume.samples(), |data| {
            accumulate(data, (min, max), width, &mut counts)
        });
        let finite = volume.len() as u64 - non_finite;
        Some(Histogram {
            min,
            max,
            mean: sum / finite as f64,
            counts,
            non_finite,
            within: Some((min, max)),
        })
    }

    /// The histogram of the voxels `lo..hi` (half-open) of `volume` in
    /// `bins` bins over `(min, max)` (a larger volume's range, of which
    /// this box is a part): the parts of a volume's voxels, each counted
    /// so and [`merge`](Self::merge)d, give [`Histogram::of`] the whole.
    /// Over a narrower window, the values below `min` are counted in the
    /// first bin and those above `max` in the last.
    pub fn of_box(
        volume: &Volume,
        (lo, hi): ([usize; 3], [usize; 3]),
        (min, max): (f32, f32),
        bins: usize,
    ) -> Self {
        let bins = bins.max(1);
        let mut counts = vec![0u64; bins];
        let width = (f64::from(max) - f64::from(min)) / bins as f64;
        let [nx, ny, _] = volume.dims();
        let (mut sum, mut non_finite, mut within) = (0.0, 0, None);
        with_samples!(volume.samples(), |data| {
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    let row = (z * ny + y) * nx;
                    let row = &data[row + lo[0]..row + hi[0]];
                    let (s, n, w) = accumulate(row, (min, max), width, &mut counts);
                    sum += s;
                    non_finite += n;
                    within = join(within, w);
                }
            }
        });
        let finite: u64 = counts.iter().sum();
        Histogram {
            min,
            max,
            mean: if finite > 0 { sum / finite as f64 } else { 0.0 },
            counts,
            non_finite,
            within,
        }
    }

    /// The histogram of two parts' voxels together (the same bins).
    pub fn merge(&mut self, other: &Histogram) {
        let (a, b) = (
            self.counts.iter().sum::<u64>(),
            other.counts.iter().sum::<u64>(),
        );
        if a + b > 0 {
            self.mean = (self.mean * a as f64 + other.mean * b as f64) / (a + b) as f64;
        }
        for (x, y) in self.counts.iter_mut().zip(&other.counts) {
            *x += y;
        }
        self.non_finite += other.non_finite;
        self.within = join(self.within, other.within);
    }

    /// The lower edge of bin `b` (`b == bins` gives `max`).
    pub fn edge(&self, b: usize) -> f64 {
        let bins = self.counts.len();
        if b >= bins {
            return f64::from(self.max);
        }
        f64::from(self.min) + (f64::from(self.max) - f64::from(self.min)) * b as f64 / bins as f64
    }
}

/// The smallest and largest of two ranges' values together.
fn join(a: Option<(f32, f32)>, b: Option<(f32, f32)>) -> Option<(f32, f32)> {
    match (a, b) {
        (Some((a0, a1)), Some((b0, b1))) => Some((a0.min(b0), a1.max(b1))),
        (a, b) => a.or(b),
    }
}

/// Adds `data`'s finite values to `counts` (bins of `width` from `min`,
/// values outside `min..=max` in the end bins); returns their sum, the
/// number of values that are not finite, and the smallest and largest
/// value within `min..=max`.
fn accumulate<T: Sample>(
    data: &[T],
    (min, max): (f32, f32),
    width: f64,
    counts: &mut [u64],
) -> (f64, u64, Option<(f32, f32)>) {
    let last = counts.len() - 1;
    let (mut sum, mut non_finite) = (0.0f64, 0u64);
    let (mut low, mut high) = (f32::INFINITY, f32::NEG_INFINITY);
    for v in data.iter().map(|v| v.to_f32()) {
        if !v.is_finite() {
            non_finite += 1;
            continue;
        }
        sum += f64::from(v);
        if v >= min && v <= max {
            low = low.min(v);
            high = high.max(v);
        }
        let b = if width > 0.0 {
            ((f64::from(v) - f64::from(min)) / width) as usize
        } else {
            0
        };
        // Below `min` the quotient is negative, and `as` saturates to 0.
        counts[b.min(last)] += 1;
    }
    (sum, non_finite, (low <= high).then_some((low, high)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_edges_and_mean_of_a_ramp() {
        // 0..=7 over 8 points: 4 bins of width 1.75.
        let v = Volume::new([2, 2, 2], (0..8).map(|i| i as f32).collect()).unwrap();
        let h = Histogram::of(&v, 4).unwrap();
        assert_eq!((h.min, h.max), (0.0, 7.0));
        assert_eq!(h.mean, 3.5);
        // [0,1.75): 0 1; [1.75,3.5): 2 3; [3.5,5.25): 4 5; [5.25,7]: 6 7.
        assert_eq!(h.counts, [2, 2, 2, 2]);
        assert_eq!(h.edge(1), 1.75);
        assert_eq!(h.edge(4), 7.0);
        assert_eq!(h.non_finite, 0);
    }

    #[test]
    fn non_finite_values_are_counted_apart_and_constant_volumes_fill_bin_zero() {
        let mut data = vec![2.0f32; 8];
        data[3] = f32::NAN;
        data[5] = f32::NEG_INFINITY;
        let v = Volume::new([2, 2, 2], data).unwrap();
        let h = Histogram::of(&v, 3).unwrap();
        assert_eq!(h.counts, [6, 0, 0]);
        assert_eq!(h.non_finite, 2);
        assert_eq!(h.mean, 2.0);
        let nan = Volume::new([2, 2, 2], vec![f32::NAN; 8]).unwrap();
        assert!(Histogram::of(&nan, 3).is_none());
    }

    #[test]
    fn a_window_counts_the_values_outside_it_in_its_end_bins_and_keeps_those_inside() {
        // 0..=7 over the window 2..6 in 4 bins of width 1: 0 1 2 | 3 | 4 | 5 6 7.
        let v = Volume::new([2, 2, 2], (0..8).map(|i| i as f32).collect()).unwrap();
        let h = Histogram::of_box(&v, ([0; 3], [2; 3]), (2.0, 6.0), 4);
        assert_eq!(h.counts, [3, 1, 1, 3]);
        assert_eq!(h.within, Some((2.0, 6.0)));
        assert_eq!(h.mean, 3.5);
        let h = Histogram::of_box(&v, ([0; 3], [2; 3]), (2.5, 2.9), 4);
        assert_eq!(h.within, None);
        // The halves of the grid, merged: the whole's window.
        let mut low = Histogram::of_box(&v, ([0; 3], [2, 2, 1]), (2.0, 6.5), 4);
        let high = Histogram::of_box(&v, ([0, 0, 1], [2; 3]), (2.0, 6.5), 4);
        assert_eq!(low.within, Some((2.0, 3.0)));
        low.merge(&high);
        assert_eq!(low.within, Some((2.0, 6.0)));
        assert_eq!(low.counts.iter().sum::<u64>(), 8);
    }
}
