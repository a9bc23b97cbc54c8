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
        let (sum, non_finite) = with_samples!(volume.samples(), |data| {
            accumulate(data, min, width, &mut counts)
        });
        let finite = volume.len() as u64 - non_finite;
        Some(Histogram {
            min,
            max,
            mean: sum / finite as f64,
            counts,
            non_finite,
        })
    }

    /// The lower edge of bin `b` (`b == bins` gives `max`).
    /// The histogram of the voxels `lo..hi` (half-open) of `volume` in
    /// `bins` bins over `(min, max)` (a larger volume's range, of which
    /// this box is a part): the parts of a volume's voxels, each counted
    /// so and [`merge`](Self::merge)d, give [`Histogram::of`] the whole.
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
        let (mut sum, mut non_finite) = (0.0, 0);
        with_samples!(volume.samples(), |data| {
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    let row = (z * ny + y) * nx;
                    let (s, n) =
                        accumulate(&data[row + lo[0]..row + hi[0]], min, width, &mut counts);
                    sum += s;
                    non_finite += n;
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
    }

    pub fn edge(&self, b: usize) -> f64 {
        let bins = self.counts.len();
        if b >= bins {
            return f64::from(self.max);
        }
        f64::from(self.min) + (f64::from(self.max) - f64::from(self.min)) * b as f64 / bins as f64
    }
}

/// Adds `data`'s finite values to `counts` (bins of `width` from `min`);
/// returns their sum and the number of values that are not finite.
fn accumulate<T: Sample>(data: &[T], min: f32, width: f64, counts: &mut [u64]) -> (f64, u64) {
    let last = counts.len() - 1;
    let (mut sum, mut non_finite) = (0.0f64, 0u64);
    for v in data.iter().map(|v| v.to_f32()) {
        if !v.is_finite() {
            non_finite += 1;
            continue;
        }
        sum += f64::from(v);
        let b = if width > 0.0 {
            ((f64::from(v) - f64::from(min)) / width) as usize
        } else {
            0
        };
        counts[b.min(last)] += 1;
    }
    (sum, non_finite)
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
}
