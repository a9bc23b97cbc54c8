//! One level of a Zarr or OME-Zarr image (one time point and channel) as a
//! source of boxes ([`VolumeSource`]): opened from its metadata alone, and
//! read box by box, each box decoded from the chunks it touches and from
//! nothing else (`zarrs` decodes a sharded array's inner chunks through
//! the shard index, so a box reads only the inner chunks it needs). The
//! eager reader reads the whole level as one box; an out-of-core render
//! (volray-distributed's `streamed`) and each rank of an MPI render read
//! their pieces.

use std::path::{Path, PathBuf};

use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{SampleType, SourceError, Volume, VolumeSource, check_box};

use super::chunks::{ZarrArray, ZarrType, read_box};
use crate::{IoError, LevelInfo};

/// One level's array, the time point and channel chosen, as a source.
pub(crate) struct ZarrLevel {
    /// The image's path, for messages.
    path: PathBuf,
    /// The level array's directory.
    dir: PathBuf,
    array: ZarrArray,
    ty: ZarrType,
    /// The first index of every axis: the time point and channel chosen,
    /// 0 on the space axes (the last three: z, y, x).
    start: Vec<u64>,
    grid: GridFrame,
    max_memory: u64,
}

impl ZarrLevel {
    /// The level `info` describes, of the array at `dir`, at the time point
    /// and channel that `start` picks.
    pub(crate) fn new(
        path: &Path,
        dir: &Path,
        array: ZarrArray,
        ty: ZarrType,
        start: Vec<u64>,
        info: &LevelInfo,
        max_memory: u64,
    ) -> Result<Self, IoError> {
        let spacing = DVec3::from(info.spacing);
        let origin = DVec3::from(info.origin);
        // The checks a volume makes of its geometry, made before any read.
        if !(spacing.is_finite() && spacing.min_element() > 0.0) {
            let e = volray_core::VolumeError::BadSpacing(spacing.x, spacing.y, spacing.z);
            return Err(IoError::volume(path, e));
        }
        if !origin.is_finite() {
            let e = volray_core::VolumeError::BadOrigin(origin.x, origin.y, origin.z);
            return Err(IoError::volume(path, e));
        }
        Ok(ZarrLevel {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
            array,
            ty,
            start,
            grid: GridFrame {
                dims: info.dims,
                origin,
                spacing,
            },
            max_memory,
        })
    }

    /// The whole level as one volume.
    pub(crate) fn read_whole(&self) -> Result<Volume, IoError> {
        self.read(self.start.clone(), [0; 3], self.grid.dims)
    }

    /// The box `lo..hi` (x, y, z) of the level.
    fn read(&self, mut start: Vec<u64>, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, IoError> {
        let n = start.len();
        let mut shape = vec![1u64; n];
        for a in 0..3 {
            // Axis x is the array's last, z its third from last.
            start[n - 1 - a] = lo[a] as u64;
            shape[n - 1 - a] = (hi[a] - lo[a]) as u64;
        }
        let samples = read_box(
            &self.dir,
            &self.array,
            self.ty,
            &start,
            &shape,
            self.max_memory,
        )?;
        let dims = std::array::from_fn(|a| hi[a] - lo[a]);
        let origin = self.grid.origin
            + DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64) * self.grid.spacing;
        Volume::from_samples(dims, samples)
            .and_then(|v| v.with_spacing(self.grid.spacing))
            .and_then(|v| v.with_origin(origin))
            .map_err(|e| IoError::volume(&self.path, e))
    }
}

impl VolumeSource for ZarrLevel {
    fn grid(&self) -> GridFrame {
        self.grid
    }

    fn sample_type(&self) -> SampleType {
        match self.ty {
            ZarrType::U8 => SampleType::U8,
            ZarrType::I8 => SampleType::I8,
            ZarrType::U16 => SampleType::U16,
            ZarrType::I16 => SampleType::I16,
            _ => SampleType::F32,
        }
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        check_box(self.grid.dims, lo, hi).map_err(|e| e.prefixed(self.path.display()))?;
        Ok(self.read(self.start.clone(), lo, hi)?)
    }
}
