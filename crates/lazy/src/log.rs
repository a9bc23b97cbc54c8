//! `--log` of a level rendered in pieces: the level as a source of boxes
//! of the log10 of its values, with the floor a whole volume's log scale
//! takes ([`Volume::to_log10`]: values `<= 0` at the log of the smallest
//! positive value) found over the whole level first, in one pass of slabs
//! under a byte budget, so that every piece is on the whole's scale.

use std::sync::Arc;

use volray_core::sampling::grid::GridFrame;
use volray_core::{SampleType, SourceError, Volume, VolumeSource};

/// A level's boxes as the log10 of its values, values `<= 0` at the log
/// of the level's smallest positive value.
pub struct Log10Source {
    inner: Arc<dyn VolumeSource>,
    smallest: f32,
}

impl Log10Source {
    /// `inner` on a log scale, its smallest positive value found in slabs
    /// of z whose samples, read and converted, take at most `budget`
    /// bytes. An error if a slab cannot be read (the slab's error), or if
    /// no value is positive (bad data, as a volume read whole would be
    /// refused).
    pub fn over(inner: Arc<dyn VolumeSource>, budget: u64) -> Result<Log10Source, SourceError> {
        let [nx, ny, nz] = inner.grid().dims;
        // A slab read holds its samples and their f32 copy.
        let per_z = (nx * ny * (inner.voxel_bytes() + 4)) as u64;
        let depth = usize::try_from(budget / per_z.max(1))
            .unwrap_or(usize::MAX)
            .clamp(2, nz.max(2));
        let mut smallest = f32::INFINITY;
        let mut z = 0;
        while z < nz {
            // Boxes are at least 2 voxels deep: the last slab may overlap.
            let hi = (z + depth).min(nz);
            let lo = hi.saturating_sub(depth.max(2)).min(z);
            let slab = inner.read_box([0, 0, lo], [nx, ny, hi])?;
            if let Some(s) = slab.smallest_positive() {
                smallest = smallest.min(s);
            }
            z = hi;
        }
        if smallest == f32::INFINITY {
            return Err(SourceError::bad_data(
                "a log scale needs a positive value, and the volume has none",
            ));
        }
        Ok(Log10Source { inner, smallest })
    }

    /// The floor of the scale: the level's smallest positive value.
    pub fn smallest_positive(&self) -> f32 {
        self.smallest
    }
}

impl VolumeSource for Log10Source {
    fn grid(&self) -> GridFrame {
        self.inner.grid()
    }

    fn sample_type(&self) -> SampleType {
        SampleType::F32
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        Ok(self.inner.read_box(lo, hi)?.to_log10_above(self.smallest))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_box_is_the_same_box_of_the_whole_volume_on_a_log_scale() {
        // Values from -3 to 12 000 over 9 x 7 x 11: the smallest positive
        // value (0.5) lies in one slab only, and non-positive values in
        // others.
        let dims = [9, 7, 11];
        let values: Vec<f32> = (0..9 * 7 * 11)
            .map(|i| match i {
                500 => 0.5,
                _ => (i as f32) * 18.0 - 3.0,
            })
            .collect();
        let whole = Volume::new(dims, values).unwrap();
        let log_whole = whole.to_log10().unwrap();
        // Slabs of 2 and 3 z-planes, and one slab.
        for budget in [9 * 7 * 8 * 2, 9 * 7 * 8 * 3, u64::MAX as usize] {
            let source = Log10Source::over(Arc::new(whole.clone()), budget as u64).unwrap();
            assert_eq!(source.smallest_positive(), 0.5);
            for (lo, hi) in [
                ([0, 0, 0], [9, 7, 11]),
                ([2, 1, 6], [7, 5, 11]),
                ([0, 3, 0], [4, 7, 2]),
            ] {
                let piece = source.read_box(lo, hi).unwrap();
                assert_eq!(piece.values(), log_whole.sub_box(lo, hi).values());
            }
        }
    }

    #[test]
    fn a_level_without_a_positive_value_is_refused() {
        let whole = Volume::new([4, 4, 4], vec![-1.0; 64]).unwrap();
        let refused = Log10Source::over(Arc::new(whole), 1 << 20).err();
        assert!(refused.is_some_and(|e| e.message.contains("the volume has none")));
    }
}
