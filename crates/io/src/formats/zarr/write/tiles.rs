//! An OME-Zarr image's samples, tile by tile in bounded memory: level 0
//! read from the source a box at a time, each lower level made from the
//! level above read back from the store (a voxel the mean, or for labels
//! the mode, of the block it covers: [`reduce`]), each tile stored as one
//! shard (v3) or as the chunks it holds (v2).

use zarrs::array::{Array, ArraySubset, Element, ElementOwned};
use zarrs::filesystem::FilesystemStore;

use std::path::Path;

use volray_core::{Samples, VolumeSource};

use super::{Image, Level, ZarrVersion};
use crate::IoError;
use crate::formats::zarr::chunks::zarr_error;

/// A sample type written as stored.
pub(super) trait Sample:
    Element + ElementOwned + Copy + Default + Send + Sync + 'static
{
    /// The samples, if they are of this type.
    fn of(samples: &Samples) -> Option<&[Self]>;
    fn to_f64(self) -> f64;
    /// A block's mean in this type: rounded to the nearest integer
    /// (halves away from zero) for integer types.
    fn from_mean(mean: f64) -> Self;
}

macro_rules! integer_value {
    ($t:ty, $variant:ident) => {
        impl Sample for $t {
            fn of(samples: &Samples) -> Option<&[Self]> {
                match samples {
                    Samples::$variant(v) => Some(&**v),
                    _ => None,
                }
            }
            fn to_f64(self) -> f64 {
                f64::from(self)
            }
            fn from_mean(mean: f64) -> Self {
                // The mean of values of the type is within its range.
                mean.round() as $t
            }
        }
    };
}
integer_value!(u8, U8);
integer_value!(i8, I8);
integer_value!(u16, U16);
integer_value!(i16, I16);

impl Sample for f32 {
    fn of(samples: &Samples) -> Option<&[Self]> {
        match samples {
            Samples::F32(v) => Some(&**v),
            _ => None,
        }
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn from_mean(mean: f64) -> Self {
        mean as f32
    }
}

/// The value a block of a lower level gets: the mean of `block`, or for
/// labels its most common value (the smallest of those tied).
fn reduce<T: Sample>(block: &mut [T], labels: bool) -> T {
    if !labels {
        let sum: f64 = block.iter().map(|v| v.to_f64()).sum();
        return T::from_mean(sum / block.len() as f64);
    }
    block.sort_by(|a, b| a.to_f64().total_cmp(&b.to_f64()));
    let (mut best, mut best_count) = (block[0], 0);
    let mut i = 0;
    while i < block.len() {
        let v = block[i].to_f64();
        let run = block[i..]
            .iter()
            .take_while(|w| w.to_f64().total_cmp(&v).is_eq())
            .count();
        // Strictly more: a tie keeps the smaller value, found first.
        if run > best_count {
            best = block[i];
            best_count = run;
        }
        i += run;
    }
    best
}

/// A box `lo..hi` of a level, x, y, z.
#[derive(Debug, Clone, Copy)]
struct Box3 {
    lo: [usize; 3],
    hi: [usize; 3],
}

impl Box3 {
    fn dims(&self) -> [usize; 3] {
        std::array::from_fn(|a| self.hi[a] - self.lo[a])
    }

    /// As a zarrs subset, in the array's (z, y, x) order.
    fn subset(&self) -> ArraySubset {
        let d = self.dims();
        ArraySubset::new_with_start_shape(
            vec![self.lo[2] as u64, self.lo[1] as u64, self.lo[0] as u64],
            vec![d[2] as u64, d[1] as u64, d[0] as u64],
        )
        .expect("three axes")
    }
}

impl Image<'_> {
    /// Writes every level: level 0 from `source`, each next one from the
    /// one before, read back.
    pub(super) fn write_levels<T: Sample>(
        &self,
        root: &Path,
        source: &dyn VolumeSource,
    ) -> Result<(), IoError> {
        let mut above: Option<Array<FilesystemStore>> = None;
        for (k, level) in self.levels.iter().enumerate() {
            let array = self.create_array(root, k)?;
            for tile in tiles(level) {
                let values = match &above {
                    None => self.read_source::<T>(source, level, tile)?,
                    Some(a) => self.downsample::<T>(a, &self.levels[k - 1], level, tile)?,
                };
                self.store_tile(&array, level, tile, values)?;
            }
            above = Some(array);
        }
        Ok(())
    }

    /// Level 0's tile `tile` (its box clipped to the volume) read from
    /// the source, padded with zeros to the whole tile, (z, y, x) order.
    fn read_source<T: Sample>(
        &self,
        source: &dyn VolumeSource,
        level: &Level,
        tile: Box3,
    ) -> Result<Vec<T>, IoError> {
        // The source gives boxes of at least 2 voxels a side: a thinner
        // last tile is read with the voxel before it, then skipped.
        let lo: [usize; 3] = std::array::from_fn(|a| tile.lo[a].min(tile.hi[a] - 2));
        let piece = source
            .read_box(lo, tile.hi)
            .map_err(|e| IoError::invalid(self.path, format!("cannot read the input: {e}")))?;
        let values = T::of(piece.samples()).ok_or_else(|| {
            IoError::invalid(
                self.path,
                format!(
                    "the input gave {} samples for a box of a {} volume",
                    piece.sample_type().name(),
                    self.ty.name()
                ),
            )
        })?;
        let got: [usize; 3] = std::array::from_fn(|a| tile.hi[a] - lo[a]);
        if piece.dims() != got {
            return Err(IoError::invalid(
                self.path,
                format!(
                    "the input gave a box of {:?} voxels for {got:?}",
                    piece.dims()
                ),
            ));
        }
        let [tx, ty, _] = level.tile;
        let mut out = vec![T::default(); level.tile.iter().product()];
        let d = tile.dims();
        for z in 0..d[2] {
            for y in 0..d[1] {
                let from = ((z + tile.lo[2] - lo[2]) * got[1] + (y + tile.lo[1] - lo[1])) * got[0]
                    + (tile.lo[0] - lo[0]);
                let to = (z * ty + y) * tx;
                out[to..to + d[0]].copy_from_slice(&values[from..from + d[0]]);
            }
        }
        Ok(out)
    }

    /// Tile `tile` of `level` made from the level above (`above`, read
    /// back from `array`), padded with zeros to the whole tile: read one
    /// output chunk's thickness at a time.
    fn downsample<T: Sample>(
        &self,
        array: &Array<FilesystemStore>,
        above: &Level,
        level: &Level,
        tile: Box3,
    ) -> Result<Vec<T>, IoError> {
        let f = level.factor;
        let [tx, ty, _] = level.tile;
        let mut out = vec![T::default(); level.tile.iter().product()];
        let mut block = Vec::with_capacity(8);
        let step = level.chunk[2];
        let mut z0 = tile.lo[2];
        while z0 < tile.hi[2] {
            let z1 = (z0 + step).min(tile.hi[2]);
            let part = Box3 {
                lo: [tile.lo[0], tile.lo[1], z0],
                hi: [tile.hi[0], tile.hi[1], z1],
            };
            let input = Box3 {
                lo: std::array::from_fn(|a| part.lo[a] * f[a]),
                hi: std::array::from_fn(|a| (part.hi[a] * f[a]).min(above.dims[a])),
            };
            let values: Vec<T> = array
                .retrieve_array_subset::<Vec<T>>(&input.subset())
                .map_err(|e| zarr_error(self.path, "cannot read back the level above", e))?;
            let [ix, iy, _] = input.dims();
            for z in z0..z1 {
                let zs = z * f[2]..((z + 1) * f[2]).min(above.dims[2]);
                for y in part.lo[1]..part.hi[1] {
                    let ys = y * f[1]..((y + 1) * f[1]).min(above.dims[1]);
                    let row = ((z - tile.lo[2]) * ty + (y - tile.lo[1])) * tx;
                    for x in part.lo[0]..part.hi[0] {
                        let xs = x * f[0]..((x + 1) * f[0]).min(above.dims[0]);
                        block.clear();
                        for zz in zs.clone() {
                            for yy in ys.clone() {
                                let r = ((zz - input.lo[2]) * iy + (yy - input.lo[1])) * ix;
                                for xx in xs.clone() {
                                    block.push(values[r + xx - input.lo[0]]);
                                }
                            }
                        }
                        out[row + x - tile.lo[0]] = reduce(&mut block, self.labels);
                    }
                }
            }
            z0 = z1;
        }
        Ok(out)
    }

    /// Stores a whole tile (z, y, x order): one shard (v3), or each of
    /// the chunks it holds that the array has (v2).
    fn store_tile<T: Sample>(
        &self,
        array: &Array<FilesystemStore>,
        level: &Level,
        tile: Box3,
        values: Vec<T>,
    ) -> Result<(), IoError> {
        let failed = |e| zarr_error(self.path, "cannot write a Zarr chunk", e);
        let index: [u64; 3] = std::array::from_fn(|a| (tile.lo[2 - a] / level.tile[2 - a]) as u64);
        if self.version == ZarrVersion::V3 {
            return self
                .out
                .while_live(|_| array.store_chunk(&index, values))
                .map_err(failed);
        }
        let c = level.chunk;
        let [tx, ty, tz] = level.tile;
        let mut chunk = Vec::with_capacity(c.iter().product());
        for cz in (0..tz).step_by(c[2]) {
            for cy in (0..ty).step_by(c[1]) {
                for cx in (0..tx).step_by(c[0]) {
                    let at = [tile.lo[0] + cx, tile.lo[1] + cy, tile.lo[2] + cz];
                    if (0..3).any(|a| at[a] >= level.dims[a]) {
                        continue;
                    }
                    chunk.clear();
                    for z in cz..cz + c[2] {
                        for y in cy..cy + c[1] {
                            let from = (z * ty + y) * tx + cx;
                            chunk.extend_from_slice(&values[from..from + c[0]]);
                        }
                    }
                    let index = [
                        (at[2] / c[2]) as u64,
                        (at[1] / c[1]) as u64,
                        (at[0] / c[0]) as u64,
                    ];
                    self.out
                        .while_live(|_| array.store_chunk(&index, &chunk[..]))
                        .map_err(failed)?;
                }
            }
        }
        Ok(())
    }
}

/// The tiles of a level, z slowest, each its box clipped to the level.
fn tiles(level: &Level) -> impl Iterator<Item = Box3> + '_ {
    let n: [usize; 3] = std::array::from_fn(|a| level.dims[a].div_ceil(level.tile[a]));
    (0..n[2]).flat_map(move |z| {
        (0..n[1]).flat_map(move |y| {
            (0..n[0]).map(move |x| {
                let lo = [x * level.tile[0], y * level.tile[1], z * level.tile[2]];
                Box3 {
                    lo,
                    hi: std::array::from_fn(|a| (lo[a] + level.tile[a]).min(level.dims[a])),
                }
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_take_the_smallest_of_those_tied_and_means_round() {
        assert_eq!(reduce(&mut [3u8, 1, 3, 1], true), 1);
        assert_eq!(reduce(&mut [3u8, 1, 3, 2], true), 3);
        assert_eq!(reduce(&mut [7i16], true), 7);
        assert_eq!(reduce(&mut [-5i8, 2, 9, 9, 2, -5], true), -5);
        assert_eq!(reduce(&mut [1u8, 2], false), 2);
        assert_eq!(reduce(&mut [-1i8, -2], false), -2);
        assert_eq!(reduce(&mut [1u16, 2, 2], false), 2);
        assert_eq!(reduce(&mut [0.5f32, 0.25], false), 0.375);
    }
}
