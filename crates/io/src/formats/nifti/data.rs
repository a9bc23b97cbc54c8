//! What a NIfTI header says about the samples: their type (`datatype`),
//! how the frames lie in the data (`dim`, `vox_offset`), checked into a
//! [`Layout`], and the scaling of the values read (`scl_slope`,
//! `scl_inter`).

use std::path::Path;

use super::header::Header;
use crate::dtype::DType;
use crate::error::IoError;
use crate::{AxisNames, FileInfo, Picked, ReadOptions, Volumes};

/// The sample type of NIfTI datatype `code`, or why it is refused.
fn sample_type(code: i64) -> Result<(DType, &'static str), String> {
    Ok(match code {
        2 => (DType::U8, "uint8"),
        4 => (DType::I16, "int16"),
        8 => (DType::I32, "int32"),
        16 => (DType::F32, "float32"),
        64 => (DType::F64, "float64"),
        256 => (DType::I8, "int8"),
        512 => (DType::U16, "uint16"),
        768 => (DType::U32, "uint32"),
        1024 => (DType::I64, "int64"),
        1280 => (DType::U64, "uint64"),
        _ => {
            let what = match code {
                1 => "binary (1 bit per voxel)",
                32 => "complex64",
                128 => "RGB24",
                1536 => "float128",
                1792 => "complex128",
                2048 => "complex256",
                2304 => "RGBA32",
                _ => {
                    return Err(format!(
                        "NIfTI field \"datatype\" is {code}: not a NIfTI data type"
                    ));
                }
            };
            return Err(format!(
                "NIfTI field \"datatype\" is {code} ({what}): volray reads scalar volumes of integers, float32 or float64 only"
            ));
        }
    })
}

/// The data layout the header describes, checked.
pub(super) struct Layout {
    pub(super) dims: [usize; 3],
    pub(super) count: usize,
    pub(super) dtype: DType,
    pub(super) type_name: &'static str,
    /// Volumes in all: `times · components`.
    pub(super) frames: usize,
    /// `dim[4]` (time points) and `dim[5]` (components: vector or
    /// channel data, the channels) where the header uses them, else 1.
    pub(super) times: usize,
    pub(super) components: usize,
    /// The time point and component asked for (`axes.rs`).
    pub(super) picked: Picked,
    /// Its block in the file's order: `t + times·c`.
    pub(super) frame: usize,
    pub(super) frame_bytes: u64,
    pub(super) vox_offset: u64,
}

impl Layout {
    pub(super) fn of(path: &Path, header: &Header, opts: &ReadOptions) -> Result<Layout, IoError> {
        let (dtype, type_name) =
            sample_type(header.datatype).map_err(|reason| IoError::invalid(path, reason))?;
        let dim = header.dim;
        let ndim = dim[0];
        if !(1..=7).contains(&ndim) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim[0]\" is {ndim}: the number of dimensions must be 1 to 7"
                ),
            ));
        }
        let ndim = ndim as usize;
        // A 2-D image is read (its third axis one sample) and described
        // rather than rendered.
        if ndim < 2 {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim[0]\" is {ndim}: volray renders 3-D volumes, not {ndim}-D data"
                ),
            ));
        }
        for (a, &d) in dim.iter().enumerate().take(ndim + 1).skip(1) {
            if d < 1 {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "NIfTI field \"dim[{a}]\" is {d}: every used dimension must be at least 1"
                    ),
                ));
            }
        }
        if let Some(a) = (6..=ndim).find(|&a| dim[a] > 1) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim[{a}]\" is {}: {ndim}-D data (beyond a 5th dimension of components) is not supported",
                    dim[a]
                ),
            ));
        }
        let to_usize = |a: usize| usize::try_from(dim[a]).ok();
        let dims = [1, 2, 3].map(|a| {
            if a > ndim {
                1
            } else {
                to_usize(a).unwrap_or(usize::MAX)
            }
        });
        // An axis of 1 (a 2-D image) is read, and described rather than
        // rendered (`grid_to_volume`); an axis of 0 holds nothing.
        if dims.contains(&0) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim\" gives {}x{}x{} voxels: an axis of 0 holds no image",
                    dim[1], dim[2], dim[3]
                ),
            ));
        }
        // Volumes lie one after another in the file's order, time (dim[4])
        // fastest, then components (dim[5]): frame t + T·c is one block.
        let times = if ndim >= 4 {
            to_usize(4).unwrap_or(usize::MAX)
        } else {
            1
        };
        let components = if ndim >= 5 {
            to_usize(5).unwrap_or(usize::MAX)
        } else {
            1
        };
        let frames = times
            .checked_mul(components)
            .ok_or_else(|| too_big(path, header))?;
        // --frame is the time point and --channel the component.
        let picked = Volumes::new(times, components).pick(
            path,
            opts,
            AxisNames {
                holder: "the file",
                time: "dim[4]",
                channel: "dim[5]",
            },
        )?;
        let frame_index = picked.time_point + times * picked.channel;
        let count = dims[0]
            .checked_mul(dims[1])
            .and_then(|n| n.checked_mul(dims[2]))
            .ok_or_else(|| too_big(path, header))?;
        let frame_bytes = (count as u64)
            .checked_mul(dtype.size() as u64)
            .ok_or_else(|| too_big(path, header))?;
        let v = header.vox_offset;
        if !(v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v < 2f64.powi(62)) {
            return Err(IoError::invalid(
                path,
                format!("NIfTI field \"vox_offset\" is {v}: it must be a whole number of bytes"),
            ));
        }
        Ok(Layout {
            dims,
            count,
            dtype,
            type_name,
            frames,
            times,
            components,
            picked,
            frame: frame_index,
            frame_bytes,
            vox_offset: v as u64,
        })
    }

    /// Bytes from the start of the data file through the last frame.
    pub(super) fn total_bytes(&self, start: u64) -> Option<u64> {
        self.frame_bytes
            .checked_mul(self.frames as u64)?
            .checked_add(start)
    }

    /// Bytes from the start of the data file through the wanted frame.
    pub(super) fn bytes_through_frame(&self, start: u64) -> Option<u64> {
        self.frame_bytes
            .checked_mul(self.frame as u64 + 1)?
            .checked_add(start)
    }
}

/// The `dim` field as written, for messages.
pub(super) fn dim_text(header: &Header) -> String {
    header
        .ints("dim")
        .iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

pub(super) fn too_big(path: &Path, header: &Header) -> IoError {
    IoError::invalid(
        path,
        format!(
            "NIfTI field \"dim\" is {}: the data size overflows",
            dim_text(header)
        ),
    )
}

/// The `scl_slope`/`scl_inter` to apply (nifti1.h: `y = scl_slope · x +
/// scl_inter` unless `scl_slope` is 0; nibabel also treats a NaN or
/// infinite slope as "no scaling"), `None` for none, with notes on what
/// was ignored or applied.
pub(super) fn scaling(header: &Header, info: &mut FileInfo) -> Option<(f64, f64)> {
    let (slope, inter) = (header.scl_slope, header.scl_inter);
    if slope == 0.0 || !slope.is_finite() {
        if slope != 0.0 || (inter != 0.0 && !inter.is_nan()) {
            info.notes.push(format!(
                "scl_slope {slope} means no scaling; scl_inter {inter} ignored"
            ));
        }
        return None;
    }
    let inter = if inter.is_finite() {
        inter
    } else {
        info.notes
            .push(format!("scl_inter {inter} is not finite: taken as 0"));
        0.0
    };
    if slope == 1.0 && inter == 0.0 {
        return None;
    }
    info.notes.push(format!(
        "values scaled: value = {slope} * stored + {inter} (scl_slope, scl_inter)"
    ));
    Some((slope, inter))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn datatypes() {
        assert_eq!(sample_type(512).unwrap(), (DType::U16, "uint16"));
        assert_eq!(sample_type(1280).unwrap(), (DType::U64, "uint64"));
        assert!(sample_type(128).unwrap_err().contains("RGB24"));
        assert!(sample_type(1792).unwrap_err().contains("complex128"));
        assert!(
            sample_type(3)
                .unwrap_err()
                .contains("not a NIfTI data type")
        );
    }
}
