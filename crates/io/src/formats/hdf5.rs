//! HDF5 datasets (`file.h5:/group/dataset`), read with the system HDF5
//! library through `hdf5-metno` (cargo feature `hdf5`).
//!
//! Axis convention, the same as volray's `.npy` reader: a 3-D dataset of
//! shape `(n0, n1, n2)` (C order, the last index varying fastest in the
//! file) is indexed `a[x, y, z]`, so the volume has dims `[n0, n1, n2]`
//! and is transposed on reading. A 4-D dataset is a series `a[t, x, y, z]`
//! and `--frame t` picks one volume (0 by default); only that volume is read.
//!
//! Geometry from the dataset's attributes, each one value per dataset
//! axis in dataset order (so axis 0 is x), or a single value for all
//! axes; a 4-D dataset may give 4 values, the first (time) is dropped:
//! - `spacing` and `origin` (unit from a string attribute `unit` or
//!   `units`, if any);
//! - `element_size_um` (the Fiji/ilastik convention), in micrometres.
//!
//! Without a dataset path, a file with exactly one 3-D or 4-D numeric
//! dataset is read; otherwise the datasets are listed in the error. The
//! dataset's shape and storage are checked against the file's length
//! before anything is read, and samples are read in slabs of the first
//! axis, so the scratch memory beside the volume stays small.

use std::path::{Path, PathBuf};

use hdf5::types::{FixedAscii, TypeDescriptor, VarLenAscii, VarLenUnicode};
use hdf5::{Dataset, File, Group};
use hdf5_metno as hdf5;
use ndarray::Ix3;
use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::open_input;
use crate::shared::limits::{check_held, count_values, format_bytes};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat, split_hdf5_path};

/// A dataset may decode to at most this many times the file's length
/// (compressed chunks; deflate inflates at most about 1032:1), or to
/// [`SMALL_FILE_ALLOWANCE`] bytes whatever the file's length.
const MAX_INFLATION: u64 = crate::shared::compress::MAX_DEFLATE_RATIO;
const SMALL_FILE_ALLOWANCE: u64 = 64 << 20;

/// Samples read per slab.
const SLAB_SAMPLES: usize = 1 << 20;

/// The search for datasets stops after this many objects or this depth
/// (hard links can make a group its own descendant).
const MAX_OBJECTS: usize = 10_000;
const MAX_DEPTH: usize = 32;

/// Datasets listed in an error, at most.
const LISTED: usize = 10;

/// Reads the dataset `path` names (`file.h5:/dataset`, or `file.h5`
/// holding a single volume).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (file_path, dataset_path): (PathBuf, Option<String>) = match split_hdf5_path(path) {
        Some((file, dataset)) => (file, Some(dataset)),
        None => (path.to_path_buf(), None),
    };
    let (_, file_len) = open_input(&file_path)?;
    let fail = |reason: String| IoError::invalid(&file_path, reason);
    let file = File::open(&file_path).map_err(|e| fail(format!("HDF5: cannot open: {e}")))?;

    let dataset = match &dataset_path {
        Some(name) => file.dataset(name).map_err(|_| {
            let found = volumes_in(&file);
            fail(format!(
                "HDF5 file has no dataset \"{name}\"; its 3-D/4-D numeric datasets: {}",
                listing(&found)
            ))
        })?,
        None => {
            let found = volumes_in(&file);
            match found.as_slice() {
                [(only, _)] => file
                    .dataset(only)
                    .map_err(|e| fail(format!("HDF5 dataset \"{only}\": {e}")))?,
                _ => {
                    return Err(fail(format!(
                        "HDF5 file holds {} 3-D/4-D numeric datasets: name one as FILE:/path ({})",
                        found.len(),
                        listing(&found)
                    )));
                }
            }
        }
    };
    let name = dataset.name();
    let what = |reason: String| fail(format!("HDF5 dataset \"{name}\": {reason}"));

    let descriptor = dataset
        .dtype()
        .and_then(|t| t.to_descriptor())
        .map_err(|e| what(format!("unreadable type: {e}")))?;
    let sample_size = match &descriptor {
        TypeDescriptor::Integer(s) | TypeDescriptor::Unsigned(s) => *s as usize,
        TypeDescriptor::Float(s) => *s as usize,
        other => {
            return Err(what(format!(
                "type {other} is not numeric: volray reads integer and float datasets"
            )));
        }
    };
    let shape = dataset.shape();
    let (frames, dims) = match shape.as_slice() {
        &[n0, n1, n2] => (1, [n0, n1, n2]),
        &[t, n0, n1, n2] => (t, [n0, n1, n2]),
        other => {
            return Err(what(format!(
                "shape {other:?} has {} dimension(s): volray reads 3-D datasets a[x, y, z] and 4-D series a[t, x, y, z]",
                other.len()
            )));
        }
    };
    let frame = opts.frame.unwrap_or(0);
    if frame >= frames {
        return Err(IoError::frame_out_of_range(
            &file_path,
            frame,
            format!(
                "HDF5 dataset \"{name}\" holds {frames} volume(s) along its first axis, numbered from 0"
            ),
        ));
    }
    if dims.iter().any(|&n| n < 2) {
        return Err(what(format!(
            "volume of {}x{}x{} samples: every axis needs at least 2",
            dims[0], dims[1], dims[2]
        )));
    }
    let voxels = dims[0]
        .checked_mul(dims[1])
        .and_then(|n| n.checked_mul(dims[2]))
        .filter(|n| n.checked_mul(sample_size.max(4)).is_some())
        .ok_or_else(|| what(format!("shape {shape:?} is too large to address")))?;
    let budget = file_len
        .saturating_mul(MAX_INFLATION)
        .max(SMALL_FILE_ALLOWANCE);
    let bytes = (voxels as u64).saturating_mul(sample_size as u64);
    if bytes > budget {
        return Err(what(format!(
            "shape {shape:?} of {descriptor} is {bytes} bytes per volume, more than a {file_len}-byte file can hold even compressed"
        )));
    }

    // The f32 volume, and one slab of f64 values (at most a plane's worth
    // beyond SLAB_SAMPLES) while reading.
    let shape_dims: Vec<u64> = shape.iter().map(|&n| n as u64).collect();
    count_values(&file_path, "shape", &shape_dims)?;
    let slab_values = dims[1] * dims[2] * slab_planes(dims[1] * dims[2], 1).min(dims[0]);
    let peak = voxels as u128 * 4 + slab_values as u128 * 8;
    check_held(
        &file_path,
        &format!("dataset shape {shape:?}"),
        voxels as u128,
        peak,
        &format!("{} as f32 and an f64 slab", format_bytes(peak)),
        opts.max_memory,
    )?;

    let mut info = FileInfo::new(stored_type(&dataset, &descriptor));
    info.frames = frames;
    info.frame = frame;
    info.header = header_fields(&dataset, &shape, &descriptor);
    info.notes.push(format!(
        "C-order dataset of shape {shape:?} read as a[{}x, y, z] (the first axis is x; the file's fastest axis is z), transposed to x fastest",
        if frames > 1 { "t, " } else { "" }
    ));
    if frames > 1 {
        info.notes
            .push(format!("volume {frame} of {frames} read (first axis: t)"));
    }
    let (spacing, origin) = geometry(&dataset, frames > 1, &mut info).map_err(what)?;

    let data = read_volume(&dataset, dims, frames > 1, frame, voxels)
        .map_err(|e| what(format!("cannot read: {e}")))?;
    let steps = [
        DVec3::X * spacing.x,
        DVec3::Y * spacing.y,
        DVec3::Z * spacing.z,
    ];
    let volume = grid_to_volume(&file_path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Hdf5,
        info,
    })
}

/// Reads volume `frame` of `dataset` (3-D, or 4-D when `series`) into an
/// x-fastest buffer, one slab of the first axis at a time.
fn read_volume(
    dataset: &Dataset,
    dims: [usize; 3],
    series: bool,
    frame: usize,
    voxels: usize,
) -> hdf5::Result<Vec<f32>> {
    let [n0, n1, n2] = dims;
    let plane = n1 * n2;
    // Slabs follow the chunking along the first axis, so each chunk is
    // decompressed once.
    let chunk0 = dataset
        .chunk()
        .and_then(|c| c.get(usize::from(series)).copied())
        .unwrap_or(1)
        .max(1);
    let slab = slab_planes(plane, chunk0);
    let mut data = vec![0.0f32; voxels];
    let mut x0 = 0;
    while x0 < n0 {
        let x1 = (x0 + slab).min(n0);
        let part = if series {
            dataset.read_slice::<f64, _, Ix3>((frame, x0..x1, .., ..))?
        } else {
            dataset.read_slice::<f64, _, Ix3>((x0..x1, .., ..))?
        };
        // part[x - x0, y, z] goes to x + n0·(y + n1·z).
        for ((dx, y, z), &v) in part.indexed_iter() {
            data[x0 + dx + n0 * (y + n1 * z)] = v as f32;
        }
        x0 = x1;
    }
    Ok(data)
}

/// Planes of the first axis read at once: whole chunks adding up to about
/// [`SLAB_SAMPLES`], or, where one chunk is larger than that, as many
/// planes as fit [`SLAB_SAMPLES`] (at least one), so that a header's chunk
/// size cannot make the scratch buffer large.
fn slab_planes(plane: usize, chunk0: usize) -> usize {
    if plane.saturating_mul(chunk0) <= SLAB_SAMPLES {
        (SLAB_SAMPLES / plane / chunk0).max(1) * chunk0
    } else {
        (SLAB_SAMPLES / plane).max(1)
    }
}

/// Spacing and origin from the dataset's attributes (see the module docs).
fn geometry(
    dataset: &Dataset,
    series: bool,
    info: &mut FileInfo,
) -> Result<(DVec3, DVec3), String> {
    let unit = ["unit", "units"]
        .iter()
        .find_map(|name| string_attr(dataset, name));
    let mut spacing = DVec3::ONE;
    let mut origin = DVec3::ZERO;
    let mut sources = Vec::new();
    if let Some(s) = vector_attr(dataset, "element_size_um", series)? {
        spacing = s;
        sources.push("element_size_um");
        info.length_unit = Some("um".into());
    }
    if let Some(s) = vector_attr(dataset, "spacing", series)? {
        spacing = s;
        sources.push("spacing");
        info.length_unit = unit.clone();
    }
    if spacing.min_element() <= 0.0 {
        return Err(format!(
            "spacing {}, {}, {} is not positive",
            spacing.x, spacing.y, spacing.z
        ));
    }
    if let Some(o) = vector_attr(dataset, "origin", series)? {
        origin = o;
        sources.push("origin");
        if info.length_unit.is_none() {
            info.length_unit = unit.clone();
        }
    }
    if sources.is_empty() {
        info.notes.push(
            "no spacing, origin or element_size_um attribute: spacing 1, 1, 1 and origin 0".into(),
        );
    } else {
        info.notes.push(format!(
            "spacing {}, {}, {} and origin {}, {}, {}{} from attribute(s) {}",
            spacing.x,
            spacing.y,
            spacing.z,
            origin.x,
            origin.y,
            origin.z,
            info.length_unit
                .as_ref()
                .map(|u| format!(" {u}"))
                .unwrap_or_default(),
            sources.join(", ")
        ));
    }
    Ok((spacing, origin))
}

/// A numeric attribute of one value per axis (or one for all axes; a
/// series may give a leading time value, dropped), if present.
fn vector_attr(dataset: &Dataset, name: &str, series: bool) -> Result<Option<DVec3>, String> {
    let Ok(attr) = dataset.attr(name) else {
        return Ok(None);
    };
    let values = attr
        .read_raw::<f64>()
        .map_err(|_| format!("attribute \"{name}\" is not numeric"))?;
    let v: &[f64] = match values.len() {
        1 => return finite(name, DVec3::splat(values[0])).map(Some),
        3 => &values,
        4 if series => &values[1..],
        n => {
            return Err(format!(
                "attribute \"{name}\" has {n} values, needs 3 (one per axis){}",
                if series { " or 4" } else { "" }
            ));
        }
    };
    finite(name, DVec3::new(v[0], v[1], v[2])).map(Some)
}

fn finite(name: &str, v: DVec3) -> Result<DVec3, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!(
            "attribute \"{name}\" holds {}, {}, {}",
            v.x, v.y, v.z
        ))
    }
}

fn string_attr(dataset: &Dataset, name: &str) -> Option<String> {
    let attr = dataset.attr(name).ok()?;
    let s = attr
        .read_scalar::<VarLenUnicode>()
        .map(|s| s.as_str().to_string())
        .or_else(|_| {
            attr.read_scalar::<VarLenAscii>()
                .map(|s| s.as_str().to_string())
        })
        .or_else(|_| {
            attr.read_scalar::<FixedAscii<256>>()
                .map(|s| s.as_str().to_string())
        })
        .ok()?;
    let s = s.trim().to_string();
    (!s.is_empty()).then_some(s)
}

fn stored_type(dataset: &Dataset, descriptor: &TypeDescriptor) -> String {
    let order = match dataset.dtype().map(|t| t.byte_order()) {
        Ok(hdf5::datatype::ByteOrder::BigEndian) => " (big-endian)",
        Ok(hdf5::datatype::ByteOrder::LittleEndian) => " (little-endian)",
        _ => "",
    };
    format!("{descriptor}{order}")
}

/// The dataset's description and attributes, for `volray info`.
fn header_fields(
    dataset: &Dataset,
    shape: &[usize],
    descriptor: &TypeDescriptor,
) -> Vec<(String, String)> {
    let mut fields = vec![
        ("dataset".to_string(), dataset.name()),
        ("shape".to_string(), format!("{shape:?}")),
        ("type".to_string(), descriptor.to_string()),
    ];
    if let Some(chunk) = dataset.chunk() {
        fields.push(("chunks".to_string(), format!("{chunk:?}")));
    }
    let filters = dataset.filters();
    if !filters.is_empty() {
        fields.push(("filters".to_string(), format!("{filters:?}")));
    }
    for name in dataset.attr_names().unwrap_or_default() {
        let value = string_attr(dataset, &name)
            .or_else(|| {
                let v = dataset.attr(&name).ok()?.read_raw::<f64>().ok()?;
                let shown: Vec<String> = v.iter().take(16).map(|x| x.to_string()).collect();
                Some(format!("[{}]", shown.join(", ")))
            })
            .unwrap_or_else(|| "(not shown)".into());
        fields.push((format!("@{name}"), value));
    }
    fields
}

/// The 3-D and 4-D numeric datasets of `file`, with their shapes, in
/// name order (at most [`MAX_OBJECTS`] objects visited).
fn volumes_in(file: &File) -> Vec<(String, Vec<usize>)> {
    let mut found = Vec::new();
    let mut visited = 0;
    visit(file, "", 0, &mut visited, &mut found);
    found
}

fn visit(
    group: &Group,
    prefix: &str,
    depth: usize,
    visited: &mut usize,
    found: &mut Vec<(String, Vec<usize>)>,
) {
    if depth > MAX_DEPTH {
        return;
    }
    let mut names = group.member_names().unwrap_or_default();
    names.sort();
    for name in names {
        *visited += 1;
        if *visited > MAX_OBJECTS {
            return;
        }
        let path = format!("{prefix}/{name}");
        if let Ok(ds) = group.dataset(&name) {
            let numeric = ds.dtype().and_then(|t| t.to_descriptor()).is_ok_and(|d| {
                matches!(
                    d,
                    TypeDescriptor::Integer(_)
                        | TypeDescriptor::Unsigned(_)
                        | TypeDescriptor::Float(_)
                )
            });
            let shape = ds.shape();
            if numeric && matches!(shape.len(), 3 | 4) {
                found.push((path, shape));
            }
        } else if let Ok(sub) = group.group(&name) {
            visit(&sub, &path, depth + 1, visited, found);
        }
    }
}

fn listing(found: &[(String, Vec<usize>)]) -> String {
    if found.is_empty() {
        return "none".into();
    }
    let mut shown: Vec<String> = found
        .iter()
        .take(LISTED)
        .map(|(name, shape)| format!("{name} {shape:?}"))
        .collect();
    if found.len() > LISTED {
        shown.push(format!("and {} more", found.len() - LISTED));
    }
    shown.join(", ")
}
