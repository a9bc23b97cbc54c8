//! MINC2 (`.mnc`): HDF5 files in the layout libminc writes, read in pure
//! Rust (`shared/hdf5.rs`), matching nibabel's `Minc2Image`.
//!
//! - The image is `/minc-2.0/image/0/image`; its `dimorder` attribute
//!   names its axes, slowest first (`zspace,yspace,xspace`, or any order
//!   of the three, after an optional leading `time`, whose volumes are
//!   frames).
//! - Each dimension, `/minc-2.0/dimensions/<name>`, gives `step`, `start`
//!   and `direction_cosines` (default: the name's own axis). The world
//!   position of file index `i` is `Σ cosines_a · (start_a + step_a ·
//!   i_a)` over the three spatial axes, nibabel's affine: a negative step
//!   flips the axis (exactly, by [`grid_to_volume`]); cosines away from
//!   the world axes are noted and the grid kept in its own axes, as other
//!   readers do with rotations.
//! - Integer images hold normalised values: the real value is the stored
//!   one clipped to `valid_range` (default: the type's range), mapped
//!   linearly from that range onto `[image-min, image-max]`, datasets
//!   over the first one or two axes (one value per slice) or scalars.
//!   Float images are real values already.
//!
//! The file's fastest axis is volray's x, so the samples need no
//! transposing. A `.mnc` file whose magic is NetCDF's (`CDF`) is MINC1,
//! read by `formats/minc1.rs`; the geometry and scaling both read are
//! `formats/minc_common.rs`.

use std::path::Path;

use hdf5_pure::{AttrValue, Dataset, Group};
use volray_core::SampleType;

use crate::error::IoError;
use crate::formats::minc_common::{Scaling, geometry, scale_slices, spatial_split, valid_range_of};
use crate::shared::cf::Value;
use crate::shared::geometry::grid_to_volume;
use crate::shared::hdf5::{
    self as h5, Slabs, numbers, numeric_type, read_small, shown, sorted_attrs, text,
};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

const IMAGE: &str = "minc-2.0/image/0";

/// Reads the MINC2 file at `path`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let fail = |reason: String| IoError::invalid(path, format!("MINC2: {reason}"));
    if let Ok(mut f) = std::fs::File::open(path) {
        use std::io::Read;
        let mut magic = [0u8; 3];
        if f.read_exact(&mut magic).is_ok() && &magic == b"CDF" {
            // MINC1: NetCDF-3 underneath.
            return super::minc1::read(path, opts);
        }
    }
    let h5 = h5::open(path)?;
    let group = h5
        .file
        .group(IMAGE)
        .map_err(|_| fail(format!("no group /{IMAGE}: not a MINC2 file")))?;
    let image = group
        .dataset("image")
        .map_err(|_| fail(format!("no dataset /{IMAGE}/image")))?;
    let what = |reason: String| fail(format!("/{IMAGE}/image: {reason}"));
    let sample = numeric_type(&image).map_err(what)?;
    let shape = h5::shape(&image).map_err(what)?;
    let attrs = sorted_attrs(image.attrs());
    let attr = |name: &str| attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v);
    let order = dimorder(attr("dimorder"), shape.len()).map_err(what)?;

    let (frames, spatial) = spatial_split(&order, &shape).map_err(what)?;
    let names = &order[spatial..];
    let frame = opts.frame.unwrap_or(0);
    if frame >= frames {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the MINC2 image holds {frames} volume(s) along \"{}\", numbered from 0",
                order[0]
            ),
        ));
    }
    let n = [shape[spatial], shape[spatial + 1], shape[spatial + 2]];
    let slabs = Slabs::new(
        &image,
        &shape,
        frames,
        (spatial == 1).then_some(frame),
        sample.size,
    );
    // Scaled per slice by image-min/image-max: kept as f32.
    let voxels = slabs.check(
        path,
        &format!("image shape {shape:?}"),
        h5.len,
        SampleType::F32,
        opts.max_memory,
    )?;

    let mut info = FileInfo::new(sample.name.clone());
    info.frames = frames;
    info.frame = frame;
    info.header = vec![
        ("image".into(), format!("/{IMAGE}/image")),
        ("shape".into(), format!("{shape:?}")),
        ("type".into(), sample.name.clone()),
    ];
    info.header
        .extend(attrs.iter().map(|(k, v)| (format!("@{k}"), shown(v))));

    let root = h5.file.root();
    let attrs_of = |name: &str| -> Vec<(String, Value)> {
        root.dataset(&format!("minc-2.0/dimensions/{name}"))
            .map(|d| {
                sorted_attrs(d.attrs())
                    .into_iter()
                    .filter_map(|(k, v)| neutral(&v).map(|v| (k, v)))
                    .collect()
            })
            .unwrap_or_default()
    };
    let (steps, origin) =
        geometry(names, &attrs_of, "/minc-2.0/dimensions", &mut info).map_err(fail)?;
    let scaling = if sample.name.starts_with("float") {
        info.notes
            .push("float image: real values as stored (no image-min/image-max scaling)".into());
        None
    } else {
        read_scaling(
            &group,
            &image,
            &order,
            &shape,
            attr("valid_range"),
            &mut info,
        )
        .map_err(what)?
    };
    if frames > 1 {
        info.notes.push(format!(
            "volume {frame} of {frames} read (first axis: {})",
            order[0]
        ));
    }

    // C order, fastest axis last: index axis 0 of the volume is the
    // file's last axis, so the samples keep their order.
    let mut data = vec![0.0f32; voxels];
    let base = frame * voxels;
    slabs
        .read(|at, part| {
            for (i, &v) in part.iter().enumerate() {
                let value = match &scaling {
                    Some(s) => s.real(base + at + i, v),
                    None => v,
                };
                data[at + i] = value as f32;
            }
        })
        .map_err(what)?;
    let dims = [n[2], n[1], n[0]];
    let steps = [steps[2], steps[1], steps[0]];
    let volume = grid_to_volume(path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Minc,
        info,
    })
}

/// The axis names of `dimorder` (`"zspace,yspace,xspace"`), one per axis
/// of a `rank`-axis dataset.
fn dimorder(value: Option<&AttrValue>, rank: usize) -> Result<Vec<String>, String> {
    let value = value.ok_or("no \"dimorder\" attribute naming its dimensions")?;
    let text = text(value).ok_or("attribute \"dimorder\" is not a string")?;
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_string()).collect();
    if names.len() < rank || names.iter().any(String::is_empty) {
        return Err(format!(
            "dimorder \"{text}\" does not name its {rank} dimensions"
        ));
    }
    Ok(names[..rank].to_vec())
}

/// An HDF5 attribute as a format-neutral value (text, else numbers).
fn neutral(v: &AttrValue) -> Option<Value> {
    text(v)
        .map(Value::Text)
        .or_else(|| numbers(v).map(Value::Numbers))
}

/// The [`Scaling`] of `image`, from `valid_range` (else the type's range)
/// and the image-min and image-max datasets beside it; none where
/// they are missing (noted).
fn read_scaling(
    group: &Group,
    image: &Dataset,
    order: &[String],
    shape: &[usize],
    valid_range: Option<&AttrValue>,
    info: &mut FileInfo,
) -> Result<Option<Scaling>, String> {
    let (Ok(min_ds), Ok(max_ds)) = (group.dataset("image-min"), group.dataset("image-max")) else {
        info.notes
            .push("no image-min/image-max datasets: the stored values are read as they are".into());
        return Ok(None);
    };
    let (lo, hi) = valid_range_of(valid_range.map(numbers), type_range(image)?)?;
    let scale_order = |ds: &Dataset| -> Result<Vec<String>, String> {
        let rank = h5::shape(ds)?.len();
        match sorted_attrs(ds.attrs())
            .iter()
            .find(|(n, _)| n == "dimorder")
        {
            Some((_, v)) if rank > 0 => dimorder(Some(v), rank),
            _ => Ok(order[..rank].to_vec()),
        }
    };
    let (min_order, max_order) = (scale_order(&min_ds)?, scale_order(&max_ds)?);
    let slices = scale_slices(&min_order, &max_order, order, shape)?;
    let min = read_small(&min_ds, slices).map_err(|e| format!("image-min {e}"))?;
    let max = read_small(&max_ds, slices).map_err(|e| format!("image-max {e}"))?;
    Scaling::new(
        (lo, hi),
        min,
        max,
        shape,
        &min_order,
        valid_range.is_some(),
        info,
    )
    .map(Some)
}

/// The range of the image's integer type.
fn type_range(image: &Dataset) -> Result<(f64, f64), String> {
    use hdf5_pure::DType as T;
    Ok(match image.dtype().map_err(|e| e.to_string())? {
        T::I8 => (i8::MIN.into(), i8::MAX.into()),
        T::U8 => (0.0, u8::MAX.into()),
        T::I16 => (i16::MIN.into(), i16::MAX.into()),
        T::U16 => (0.0, u16::MAX.into()),
        T::I32 => (i32::MIN.into(), i32::MAX.into()),
        T::U32 => (0.0, u32::MAX.into()),
        T::I64 => (i64::MIN as f64, i64::MAX as f64),
        T::U64 => (0.0, u64::MAX as f64),
        other => return Err(format!("type {other} has no integer range")),
    })
}
