//! HDF5 datasets (`file.h5:/group/dataset`), read in pure Rust through
//! `hdf5-pure` (`shared/hdf5.rs`): no system library, in every build.
//!
//! Axis order: a dataset that names its axes (an `axes` attribute such as
//! `"zyx"` or `"tczyx"`, ilastik's `axistags`, h5py's `DIMENSION_LABELS`,
//! netCDF-C's dimension scales) is read in the order its names say, its
//! time axis holding the time points (`--frame`) and its channel axis the
//! channels (`--channel`); see
//! `hdf5_axes.rs`, which both this reader and the box-by-box one use.
//! Without names, the convention of volray's `.npy` reader: a 3-D dataset
//! of shape `(n0, n1, n2)` (C order, the last index varying fastest in the
//! file) is indexed `a[x, y, z]`, so the volume has dims `[n0, n1, n2]`
//! and is transposed on reading. A 4-D dataset is a series `a[t, x, y, z]`
//! and `--frame t` picks one volume (0 by default); only that volume is read.
//! A 2-D dataset `a[x, y]` is an image: read, and refused as a volume with
//! what it holds ([`IoError::FlatImage`]).
//!
//! Geometry from the dataset's attributes, each one value per dataset
//! axis in dataset order (those of time and channel dropped), one per
//! spatial axis in dataset order, or a single value for all axes:
//! - `spacing` and `origin` (unit from a string attribute `unit` or
//!   `units`, if any);
//! - `element_size_um` (the Fiji/ilastik convention), in micrometres.
//!
//! Without a dataset path, a file with exactly one 3-D or 4-D numeric
//! dataset is read; otherwise the datasets are listed in the error. The
//! dataset's shape and storage are checked against the file's length
//! before anything is read, and samples are read in slabs of the first
//! axis, so the scratch memory beside the volume stays small. A file
//! holding MINC2's layout (`/minc-2.0`) is MINC2's (`formats/minc.rs`);
//! one holding a `/VTKHDF` group is told apart before (`read.rs`) and read
//! by `formats/vtkhdf.rs` through [`read_opened`].

use std::path::{Path, PathBuf};

use hdf5_pure::{AttrValue, Dataset, Group};
use volray_core::SampleType;
use volray_core::glam::DVec3;

pub(crate) use super::hdf5_axes::Opened;
use super::hdf5_axes::{self, Placement, Role, axis_order};
use crate::dtype::{Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::hdf5::{self as h5, Slabs, numbers, numeric_type, sorted_attrs, text};
use crate::{AxisNames, FileInfo, Loaded, ReadOptions, VolumeFormat, split_hdf5_path};

/// The search for datasets stops after this many objects or this depth
/// (hard links can make a group its own descendant).
const MAX_OBJECTS: usize = 10_000;
const MAX_DEPTH: usize = 32;

/// Datasets listed in an error, at most.
const LISTED: usize = 10;

/// What a path opens as: a dataset, or a MINC2 file (read by `minc.rs`).
pub(crate) enum Found {
    Dataset(Box<Opened>),
    Minc(PathBuf),
}

/// Reads the dataset `path` names (`file.h5:/dataset`, or `file.h5`
/// holding a single volume).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let o = match open(path, opts)? {
        Found::Minc(file_path) => return super::minc::read(&file_path, opts),
        Found::Dataset(o) => *o,
    };
    let steps = o.axis_steps();
    read_opened(o, None, steps, VolumeFormat::Hdf5, opts)
}

/// Opens the dataset `path` names as a source of boxes (`hdf5_lazy.rs`),
/// with what the eager reader would say of it; `None` for what the eager
/// reader reads otherwise (a MINC2 file, a 2-D image or a volume one
/// sample thick).
pub(crate) fn open_lazy(
    path: &Path,
    opts: &ReadOptions,
) -> Result<Option<(super::hdf5_lazy::H5Source, FileInfo)>, IoError> {
    match open(path, opts)? {
        Found::Minc(_) => Ok(None),
        Found::Dataset(o) => lazy_opened(*o, None, opts),
    }
}

/// A dataset opened and placed (by [`open`], `vtkhdf.rs` or `bdv/`) as a
/// source of boxes, each stored value through `real` where given; `None`
/// for a 2-D image or a volume one sample thick, which the eager reader
/// reads (or refuses as an image).
pub(crate) fn lazy_opened(
    o: Opened,
    real: Option<super::hdf5_lazy::RealValue>,
    opts: &ReadOptions,
) -> Result<Option<(super::hdf5_lazy::H5Source, FileInfo)>, IoError> {
    if o.dims.iter().any(|&n| n < 2) {
        return Ok(None);
    }
    super::hdf5_lazy::from_opened(o, real, [false; 3], opts).map(Some)
}

/// Reads the volume of a dataset opened and placed (by [`open`], or a
/// NetCDF-4 variable's by `netcdf4.rs`): each stored value through `real`
/// where given (the volume then kept as `f32`), the grid's steps along x,
/// y, z `steps` (negative along a decreasing coordinate: flipped by
/// `grid_to_volume`).
pub(crate) fn read_opened(
    o: Opened,
    real: Option<&dyn Fn(f64) -> f64>,
    steps: [DVec3; 3],
    format: VolumeFormat,
    opts: &ReadOptions,
) -> Result<Loaded, IoError> {
    if super::hdf5_lazy::beyond_pure(&o.dataset) {
        // Samples hdf5-pure cannot read: the whole volume read as one box
        // through the chunk index hdf5-reader lists (hdf5_lazy.rs).
        let (file_path, dims, origin) = (o.file_path.clone(), o.dims, o.origin);
        let (source, mut info) = super::hdf5_lazy::from_opened(o, None, [false; 3], opts)?;
        let data = source.whole(real)?;
        info.notes.retain(|n| !n.starts_with("read box by box"));
        let volume = grid_to_volume(&file_path, dims, data, steps, origin, &mut info)?;
        return Ok(Loaded {
            volume,
            format,
            info,
        });
    }
    let Opened {
        file_path,
        h5,
        name,
        dataset,
        sample,
        shape,
        placement,
        dims,
        mut info,
        origin,
        ..
    } = o;
    let what =
        |reason: String| IoError::invalid(&file_path, format!("HDF5 dataset \"{name}\": {reason}"));
    let slabs = Slabs::new(
        &dataset,
        &shape,
        placement.frames,
        placement.first_fixed(),
        sample.size,
    );
    let kept = if real.is_some() {
        SampleType::F32
    } else {
        sample.stored
    };
    let voxels = slabs.check(
        &file_path,
        &format!("dataset shape {shape:?}"),
        h5.len,
        kept,
        opts.max_memory,
    )?;
    let data = read_as_stored!(kept, |T| read_volume::<T>(&slabs, &placement, voxels, real))
        .map_err(what)?;
    let volume = grid_to_volume(&file_path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format,
        info,
    })
}

/// Opens the dataset `path` names (see [`read`]) and reads its metadata:
/// type, shape, the frame asked for, geometry and what `volray info`
/// shows. A file holding MINC2's layout, named without a dataset, is
/// MINC2's.
pub(crate) fn open(path: &Path, opts: &ReadOptions) -> Result<Found, IoError> {
    let (file_path, dataset_path): (PathBuf, Option<String>) = match split_hdf5_path(path) {
        Some((file, dataset)) => (file, Some(dataset)),
        None => (path.to_path_buf(), None),
    };
    let h5 = h5::open(&file_path)?;
    let fail = |reason: String| IoError::invalid(&file_path, reason);
    let root = h5.file.root();
    if dataset_path.is_none() && h5.file.group("minc-2.0").is_ok() {
        return Ok(Found::Minc(file_path));
    }

    let (name, dataset) = match &dataset_path {
        Some(name) => {
            let dataset = h5.file.dataset(name).map_err(|_| {
                let found = volumes_in(&root);
                fail(format!(
                    "HDF5 file has no dataset \"{name}\"; its 3-D to 5-D numeric datasets: {}",
                    listing(&found)
                ))
            })?;
            let absolute = if name.starts_with('/') {
                name.clone()
            } else {
                format!("/{name}")
            };
            (absolute, dataset)
        }
        None => {
            let found = volumes_in(&root);
            match found.as_slice() {
                [(only, _)] => (
                    only.clone(),
                    h5.file
                        .dataset(only)
                        .map_err(|e| fail(format!("HDF5 dataset \"{only}\": {e}")))?,
                ),
                _ => {
                    return Err(fail(format!(
                        "HDF5 file holds {} 3-D to 5-D numeric datasets: name one as FILE:/path ({})",
                        found.len(),
                        listing(&found)
                    )));
                }
            }
        }
    };
    let what = |reason: String| fail(format!("HDF5 dataset \"{name}\": {reason}"));

    let sample = numeric_type(&dataset).map_err(what)?;
    h5::check_filters(&dataset).map_err(what)?;
    let shape = h5::shape(&dataset).map_err(what)?;
    let attrs = sorted_attrs(dataset.attrs());
    let order = if (2..=5).contains(&shape.len()) {
        axis_order(&h5.file, &name, &attrs, &dataset, &shape)
            .map_err(|e| format!("shape {shape:?}: {e}"))
    } else {
        Err(format!(
            "shape {shape:?} has {} dimension(s): volray reads 3-D datasets a[x, y, z], 4-D series a[t, x, y, z], and datasets of up to 5 named axes (an axes attribute such as \"tczyx\")",
            shape.len()
        ))
    }
    .map_err(what)?;
    // The time point and channel asked for (`axes.rs`), found in the
    // dataset's order of its axes (`hdf5_axes.rs`).
    let volumes = hdf5_axes::volumes(&shape, &order.roles);
    let holder = format!("HDF5 dataset \"{name}\"");
    let picked = volumes.pick(
        &file_path,
        opts,
        AxisNames {
            holder: &holder,
            time: if order.is_default() {
                "its first axis"
            } else {
                "axis t"
            },
            channel: "axis c",
        },
    )?;
    let frame = hdf5_axes::frame_of(&shape, &order.roles, picked);
    let placement = Placement::new(&shape, &order.roles, frame)
        .map_err(|frames| what(format!("volume {frame} of {frames}")))?;
    let dims = placement.dims;

    let mut info = FileInfo::new(sample.name.clone());
    info.set_volumes(volumes, picked);
    info.header = header_fields(&dataset, &name, &shape, &sample.name, &attrs);
    info.header.push((
        "axis order".into(),
        format!("{} from {}", order.shown(), order.source),
    ));
    info.notes.push(if order.is_default() {
        format!(
            "C-order dataset of shape {shape:?} read as {} (the first axis is x; the file's fastest axis is z), transposed to x fastest; axis order from {}",
            order.shown(),
            order.source
        )
    } else {
        format!(
            "C-order dataset of shape {shape:?} read as {}, axis order from {}, transposed to x fastest",
            order.shown(),
            order.source
        )
    });
    if let Some(why) = &order.ignored {
        info.notes.push(format!("axis names not used: {why}"));
    }
    if volumes.count() > 1 {
        info.notes.push(format!(
            "time point {} of {}, channel {} of {} read",
            picked.time_point, volumes.time_points, picked.channel, volumes.channels
        ));
    }
    let (spacing, origin) = geometry(&attrs, &order.roles, &mut info).map_err(what)?;
    Ok(Found::Dataset(Box::new(Opened {
        file_path,
        h5,
        name,
        dataset,
        sample,
        shape,
        placement,
        dims,
        info,
        spacing,
        origin,
    })))
}

/// Reads one volume into an x-fastest buffer, each sample placed as the
/// dataset's axis order says (`hdf5_axes.rs`).
fn read_volume<T: Stored>(
    slabs: &Slabs,
    placement: &Placement,
    voxels: usize,
    real: Option<&dyn Fn(f64) -> f64>,
) -> Result<Vec<T>, String> {
    let mut data = vec![T::default(); voxels];
    // The first row read: the frame's, for a series read a row at a time.
    let row: usize = placement.shape[1..].iter().product();
    let start = placement.first_fixed().unwrap_or(0) * row;
    slabs.read(|first, part| {
        placement.place(start + first, part, |at, v| {
            let v = real.map_or(v, |f| f(v));
            // Exact for the integer types kept; `as f32` for the rest.
            data[at] = T::from_f64(f64::from(v as f32));
        });
    })?;
    Ok(data)
}

/// Spacing and origin from the dataset's attributes (see the module docs).
fn geometry(
    attrs: &[(String, AttrValue)],
    roles: &[Role],
    info: &mut FileInfo,
) -> Result<(DVec3, DVec3), String> {
    let attr = |name: &str| attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v);
    let unit = ["unit", "units"]
        .iter()
        .find_map(|name| attr(name).and_then(text));
    let mut spacing = DVec3::ONE;
    let mut origin = DVec3::ZERO;
    let mut sources = Vec::new();
    if let Some(s) = vector_attr(attr("element_size_um"), "element_size_um", roles, 1.0)? {
        spacing = s;
        sources.push("element_size_um");
        info.length_unit = Some("um".into());
    }
    if let Some(s) = vector_attr(attr("spacing"), "spacing", roles, 1.0)? {
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
    if let Some(o) = vector_attr(attr("origin"), "origin", roles, 0.0)? {
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

/// A numeric attribute, if present: one value per dataset axis (those of
/// time and channel dropped), one per spatial axis in the dataset's order,
/// or one for all axes. A dataset of the default order `a[x, y]` may give
/// x, y, z. An axis given no value (z of an image) gets `unset`.
fn vector_attr(
    value: Option<&AttrValue>,
    name: &str,
    roles: &[Role],
    unset: f64,
) -> Result<Option<DVec3>, String> {
    let Some(value) = value else {
        return Ok(None);
    };
    let values = numbers(value).ok_or_else(|| format!("attribute \"{name}\" is not numeric"))?;
    let spatial: Vec<Role> = roles
        .iter()
        .copied()
        .filter(|r| !matches!(r, Role::Time | Role::Channel))
        .collect();
    let per_axis: Vec<(Role, f64)> = match values.len() {
        1 => return finite(name, DVec3::splat(values[0])).map(Some),
        n if n == roles.len() => roles.iter().copied().zip(values).collect(),
        n if n == spatial.len() => spatial.iter().copied().zip(values).collect(),
        3 if roles == [Role::X, Role::Y] => [Role::X, Role::Y, Role::Z]
            .into_iter()
            .zip(values)
            .collect(),
        n => {
            return Err(format!(
                "attribute \"{name}\" has {n} values, needs {} (one per axis){}",
                spatial.len(),
                if roles.len() != spatial.len() {
                    format!(" or {}", roles.len())
                } else {
                    String::new()
                }
            ));
        }
    };
    let mut v = DVec3::splat(unset);
    for (role, x) in per_axis {
        match role {
            Role::X => v.x = x,
            Role::Y => v.y = x,
            Role::Z => v.z = x,
            Role::Time | Role::Channel => {}
        }
    }
    finite(name, v).map(Some)
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

/// The dataset's description and attributes, for `volray info`.
fn header_fields(
    dataset: &Dataset,
    name: &str,
    shape: &[usize],
    type_name: &str,
    attrs: &[(String, AttrValue)],
) -> Vec<(String, String)> {
    let mut fields = vec![
        ("dataset".to_string(), name.to_string()),
        ("shape".to_string(), format!("{shape:?}")),
        ("type".to_string(), type_name.to_string()),
    ];
    if let Ok(Some(chunk)) = dataset.chunk_shape() {
        fields.push(("chunks".to_string(), format!("{chunk:?}")));
    }
    let filters: Vec<&str> = dataset
        .filters()
        .iter()
        .map(|&id| filter_name(id))
        .collect();
    if !filters.is_empty() {
        fields.push(("filters".to_string(), filters.join(", ")));
    }
    for (name, value) in attrs {
        fields.push((format!("@{name}"), h5::shown(value)));
    }
    fields
}

/// The registered name of an HDF5 filter.
fn filter_name(id: u16) -> &'static str {
    match id {
        1 => "deflate",
        2 => "shuffle",
        3 => "fletcher32",
        4 => "szip",
        5 => "nbit",
        6 => "scaleoffset",
        32000 => "lzf",
        _ => "other",
    }
}

/// The 3-D and 4-D numeric datasets under `root`, with their shapes, in
/// name order (at most [`MAX_OBJECTS`] objects visited).
fn volumes_in(root: &Group) -> Vec<(String, Vec<usize>)> {
    let mut found = Vec::new();
    let mut visited = 0;
    visit(root, "", 0, &mut visited, &mut found);
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
    let mut datasets = group.datasets().unwrap_or_default();
    datasets.sort();
    for name in datasets {
        *visited += 1;
        if *visited > MAX_OBJECTS {
            return;
        }
        let Ok(ds) = group.dataset(&name) else {
            continue;
        };
        if let Ok(shape) = h5::shape(&ds)
            && matches!(shape.len(), 3..=5)
            && h5::is_numeric(&ds)
        {
            found.push((format!("{prefix}/{name}"), shape));
        }
    }
    let mut groups = group.groups().unwrap_or_default();
    groups.sort();
    for name in groups {
        *visited += 1;
        if *visited > MAX_OBJECTS {
            return;
        }
        if let Ok(sub) = group.group(&name) {
            visit(&sub, &format!("{prefix}/{name}"), depth + 1, visited, found);
        }
    }
    found.sort();
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
