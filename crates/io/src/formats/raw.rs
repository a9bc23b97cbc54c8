//! Headerless raw volumes: the layout comes from [`RawOptions`].
//!
//! A raw file holds `nx·ny·nz` samples of one [`DType`], x fastest
//! (`index = x + nx·(y + ny·z)`), and nothing else: its length must be
//! exactly `nx·ny·nz·size`. The volume keeps 8- and 16-bit integers and
//! `f32` in their own type ([`DType::stored`]).

use std::path::Path;

use volray_core::glam::DVec3;
use volray_core::{Volume, VolumeError};

use crate::atomic::write_atomically;
use crate::dtype::{DType, Endian, Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::input::{open_input, read_samples};
use crate::shared::limits::{check_dims, default_max_memory};
use crate::shared::mapped::{self, MapPolicy, Plan, mapped_note};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// The layout of a raw file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawOptions {
    /// Points along x, y and z.
    pub dims: [usize; 3],
    /// Type of each sample.
    pub dtype: DType,
    /// Byte order of multi-byte samples.
    pub endian: Endian,
    /// World distance between neighbouring voxels along x, y and z.
    pub spacing: DVec3,
}

impl RawOptions {
    /// Little-endian samples with unit spacing.
    pub fn new(dims: [usize; 3], dtype: DType) -> Self {
        RawOptions {
            dims,
            dtype,
            endian: Endian::Little,
            spacing: DVec3::ONE,
        }
    }

    /// Bytes a file with this layout has, or `None` if that overflows.
    pub fn byte_len(&self) -> Option<u64> {
        let [nx, ny, nz] = self.dims;
        let bytes = nx
            .checked_mul(ny)?
            .checked_mul(nz)?
            .checked_mul(self.dtype.size())?;
        u64::try_from(bytes).ok()
    }
}

/// Reads the raw volume at `path` laid out as `opts` says.
///
/// The options are checked, and the file's length compared to what they
/// need, before anything is allocated; the read never goes past that
/// length. The volume has `opts.spacing` and its origin at zero.
pub fn read_raw(path: &Path, opts: &RawOptions) -> Result<Volume, IoError> {
    read_raw_limited(path, opts, default_max_memory(), MapPolicy::IfLarger).map(|(v, _)| v)
}

/// Reads the raw file at `path` with the layout `opts.raw` gives; a file
/// without one is of unknown format (see [`crate::read`]).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let Some(raw) = &opts.raw else {
        return Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        });
    };
    let (volume, plan) = read_raw_limited(path, raw, opts.max_memory, opts.map)?;
    let mut info = FileInfo::new(format!("{} ({}-endian)", raw.dtype, raw.endian));
    if plan == Plan::Map {
        info.notes.push(mapped_note(&volume));
    }
    Ok(Loaded {
        volume,
        format: VolumeFormat::Raw,
        info,
    })
}

/// [`read_raw`] within `max_memory` bytes (`--max-memory`): a layout whose
/// volume (in the type it keeps) would take more is mapped from the file
/// where `policy` and the layout allow, refused otherwise.
fn read_raw_limited(
    path: &Path,
    opts: &RawOptions,
    max_memory: u64,
    policy: MapPolicy,
) -> Result<(Volume, Plan), IoError> {
    let [nx, ny, nz] = opts.dims;
    if nx < 2 || ny < 2 || nz < 2 {
        return Err(IoError::volume(path, VolumeError::TooThin(nx, ny, nz)));
    }
    let s = opts.spacing;
    if !(s.is_finite() && s.min_element() > 0.0) {
        return Err(IoError::volume(
            path,
            VolumeError::BadSpacing(s.x, s.y, s.z),
        ));
    }
    let expected = opts.byte_len().ok_or_else(|| IoError::DimsOverflow {
        path: path.to_path_buf(),
        dims: opts.dims,
        dtype: opts.dtype,
    })?;
    // byte_len succeeded, so the sample count fits in usize too.
    let count = nx * ny * nz;

    let (mut file, actual) = open_input(path)?;
    if actual != expected {
        return Err(IoError::RawSizeMismatch {
            path: path.to_path_buf(),
            dims: opts.dims,
            dtype: opts.dtype,
            actual,
            expected,
        });
    }
    let stored = opts.dtype.stored();
    let kept = stored.bytes() as u64;
    let (dtype, endian) = (opts.dtype, opts.endian);
    let plan = mapped::plan(
        policy,
        mapped::mappable(dtype, endian, 0),
        check_dims(path, "raw layout dims", &opts.dims, kept, max_memory),
    )?;
    if plan == Plan::Map {
        let samples = mapped::map_samples(path, 0, dtype, count)?;
        let volume = Volume::from_samples(opts.dims, samples)
            .and_then(|v| v.with_spacing(opts.spacing))
            .map_err(|e| IoError::volume(path, e))?;
        return Ok((volume, plan));
    }
    let samples = read_as_stored!(stored, |T| {
        let mut data: Vec<T> = Vec::with_capacity(count);
        read_samples(
            path,
            &mut file,
            count,
            dtype.size(),
            0,
            |bytes, out| T::extend(out, bytes, dtype, endian),
            |values| data.extend_from_slice(values),
        )
        .map(|()| data)
    })?;

    Volume::from_samples(opts.dims, samples)
        .and_then(|v| v.with_spacing(opts.spacing))
        .map(|v| (v, plan))
        .map_err(|e| IoError::volume(path, e))
}

/// Writes `volume` to `path` as raw little-endian samples of its own type,
/// x fastest, atomically: the layout `--dims NX,NY,NZ --dtype T --endian
/// little` reads back (`T` its sample type's name: `u8`, `i8`, `u16`,
/// `i16`, `f32`). Spacing and origin are not stored.
pub fn write_raw(path: &Path, volume: &Volume) -> Result<(), IoError> {
    write_atomically(path, |w| {
        volume
            .samples()
            .try_for_each_le_chunk(1 << 16, |bytes| w.write_all(bytes))?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let p = dir.join(name);
        fs::write(&p, bytes).unwrap();
        p
    }

    #[test]
    fn write_raw_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let v = Volume::new([3, 2, 2], (0..12).map(|i| i as f32 * 0.5 - 1.0).collect()).unwrap();
        let p = dir.path().join("v.raw");
        write_raw(&p, &v).unwrap();
        assert_eq!(fs::metadata(&p).unwrap().len(), 48);
        assert_eq!(
            read_raw(&p, &RawOptions::new([3, 2, 2], DType::F32)).unwrap(),
            v
        );
    }

    #[test]
    fn reads_x_fastest_with_spacing() {
        let dir = tempfile::tempdir().unwrap();
        let bytes: Vec<u8> = (0..24u16).flat_map(|v| (v * 100).to_be_bytes()).collect();
        let p = write(dir.path(), "v.raw", &bytes);
        let opts = RawOptions {
            dims: [2, 3, 4],
            dtype: DType::U16,
            endian: Endian::Big,
            spacing: DVec3::new(0.5, 1.0, 2.0),
        };
        let v = read_raw(&p, &opts).unwrap();
        assert_eq!(v.dims(), [2, 3, 4]);
        assert_eq!(v.spacing(), DVec3::new(0.5, 1.0, 2.0));
        assert_eq!(v.origin(), DVec3::ZERO);
        for z in 0..4 {
            for y in 0..3 {
                for x in 0..2 {
                    let i = x + 2 * (y + 3 * z);
                    assert_eq!(v.get(x, y, z), (i * 100) as f32);
                }
            }
        }
    }

    #[test]
    fn size_mismatch_names_file_and_both_sizes() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "data.raw", &[0u8; 1000]);
        let opts = RawOptions::new([10, 10, 10], DType::F32);
        let err = read_raw(&p, &opts).unwrap_err();
        assert!(!err.is_io_failure());
        let msg = err.to_string();
        assert!(msg.starts_with(&p.display().to_string()), "{msg}");
        assert!(msg.contains("data.raw"), "{msg}");
        assert!(msg.contains("1000 bytes"), "{msg}");
        assert!(msg.contains("4000 bytes"), "{msg}");
        assert!(msg.contains("raw layout 10x10x10 f32 needs"), "{msg}");
        assert!(matches!(
            err,
            IoError::RawSizeMismatch {
                dims: [10, 10, 10],
                dtype: DType::F32,
                actual: 1000,
                expected: 4000,
                ..
            }
        ));

        // A longer file is refused as well.
        let p = write(dir.path(), "long.raw", &[0u8; 9]);
        let err = read_raw(&p, &RawOptions::new([2, 2, 2], DType::U8)).unwrap_err();
        assert!(matches!(
            err,
            IoError::RawSizeMismatch {
                actual: 9,
                expected: 8,
                ..
            }
        ));
    }

    #[test]
    fn overflowing_dims_are_refused_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "small.raw", &[0u8; 8]);
        let huge = usize::MAX / 2 + 1;
        for (dims, dtype) in [
            ([huge, 2, 2], DType::U8),
            ([1 << 22, 1 << 22, 1 << 22], DType::U8),
            ([usize::MAX / 4 + 1, 2, 2], DType::U8),
            ([1 << 21, 1 << 21, 1 << 21], DType::F64),
        ] {
            let err = read_raw(&p, &RawOptions::new(dims, dtype)).unwrap_err();
            assert!(matches!(err, IoError::DimsOverflow { .. }), "{err}");
            let msg = err.to_string();
            assert!(
                msg.contains(&format!("{}x{}x{}", dims[0], dims[1], dims[2])),
                "{msg}"
            );
        }
        // Large but representable: refused by the size check, not by allocating.
        let err =
            read_raw(&p, &RawOptions::new([1 << 20, 1 << 20, 1 << 10], DType::U8)).unwrap_err();
        assert!(matches!(err, IoError::RawSizeMismatch { actual: 8, .. }));
    }

    #[test]
    fn bad_layouts_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "thin.raw", &[0u8; 4]);
        let err = read_raw(&p, &RawOptions::new([1, 2, 2], DType::U8)).unwrap_err();
        assert!(matches!(
            err,
            IoError::Volume {
                error: VolumeError::TooThin(1, 2, 2),
                ..
            }
        ));
        assert!(err.to_string().contains("thin.raw"));
        assert!(!err.is_io_failure());

        let p = write(dir.path(), "ok.raw", &[0u8; 8]);
        let mut opts = RawOptions::new([2, 2, 2], DType::U8);
        opts.spacing = DVec3::new(1.0, -1.0, 1.0);
        let err = read_raw(&p, &opts).unwrap_err();
        assert!(matches!(
            err,
            IoError::Volume {
                error: VolumeError::BadSpacing(..),
                ..
            }
        ));
        assert!(err.to_string().starts_with(&p.display().to_string()));
    }

    #[test]
    fn missing_file_and_directory_are_io_failures() {
        let dir = tempfile::tempdir().unwrap();
        let opts = RawOptions::new([2, 2, 2], DType::U8);
        let missing = dir.path().join("nope.raw");
        let err = read_raw(&missing, &opts).unwrap_err();
        assert!(err.is_io_failure());
        assert!(err.to_string().contains("nope.raw: cannot open"), "{err}");

        let err = read_raw(dir.path(), &opts).unwrap_err();
        assert!(matches!(err, IoError::NotAFile { .. }), "{err}");
        assert!(err.is_io_failure());
    }

    #[test]
    fn reads_more_than_one_chunk() {
        let dir = tempfile::tempdir().unwrap();
        let dims = [64, 64, 20]; // 81920 samples: more than one chunk
        let n = dims[0] * dims[1] * dims[2];
        let bytes: Vec<u8> = (0..n).flat_map(|i| (i as f32).to_le_bytes()).collect();
        let p = write(dir.path(), "big.raw", &bytes);
        let v = read_raw(&p, &RawOptions::new(dims, DType::F32)).unwrap();
        assert!(v.values().iter().enumerate().all(|(i, &x)| x == i as f32));
    }
}
