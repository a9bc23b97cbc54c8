//! VTKHDF image data: VTK's own HDF5 format (`vtkHDFWriter`, ParaView's
//! "VTKHDF" writer; `.vtkhdf`, `.hdf`, `.h5`), whose `/VTKHDF` group
//! holds, as attributes, `Type = "ImageData"`, `WholeExtent` (i0 i1 j0 j1
//! k0 k1), `Origin`, `Spacing` and `Direction`, and the arrays in
//! `PointData/NAME` and `CellData/NAME`, each stored with the axes
//! reversed, `(nz, ny, nx)` (x fastest, as VTK keeps them), or
//! `(nz, ny, nx, components)`.
//!
//! - The array: `--array NAME` (a point array, else a cell array of that
//!   name; `PointData/NAME` or `CellData/NAME` to say which), else the
//!   point array marked as the active scalars (its `Attribute` attribute
//!   `"Scalars"`), else the first point array, else the first cell array;
//!   a note names the others.
//! - Where it lies: the point of index (i, j, k) of the extent at
//!   Origin + (i, j, k)·Spacing (what VTK's
//!   `TransformIndexToPhysicalPoint` gives with the identity direction),
//!   so the array's first sample, extent index (i0, j0, k0), is there; a
//!   cell array's samples are the cells' centres, half a step further,
//!   one fewer along each axis.
//! - Several components: `--channel` picks one (0 by default).
//!
//! A `Direction` other than the identity, time steps (`/VTKHDF/Steps`)
//! and the other dataset types (unstructured grids, poly data,
//! overlapping AMR) are refused, each naming what it is. The dataset is
//! then read as any HDF5 dataset is (`hdf5.rs`, or box by box by
//! `hdf5_lazy.rs`), in the axis order above.

use std::path::{Path, PathBuf};

use hdf5_pure::Group;
use volray_core::glam::DVec3;

use super::hdf5::{Opened, read_opened};
use super::hdf5_axes::{self, Placement, Role};
use crate::error::IoError;
use crate::shared::hdf5::{self as h5, numbers, numeric_type, shown, sorted_attrs, text};
use crate::{AxisNames, FileInfo, Loaded, ReadOptions, VolumeFormat};

/// The group every VTKHDF file keeps its data in.
pub(crate) const ROOT: &str = "VTKHDF";

/// Arrays listed in a note or an error, at most.
const LISTED: usize = 10;

/// Whether the HDF5 file at `path` is a VTKHDF file (has a `/VTKHDF`
/// group); false where it cannot be opened (its reader then says why).
pub(crate) fn is_vtkhdf(path: &Path) -> bool {
    h5::open(path).is_ok_and(|h5| h5.file.group(ROOT).is_ok())
}

/// Reads the VTKHDF image data at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let h5 = h5::open(path)?;
    let o = open(path.to_path_buf(), h5, opts)?;
    let steps = o.axis_steps();
    read_opened(o, None, steps, VolumeFormat::Vtkhdf, opts)
}

/// The VTKHDF image data at `path` as a source of boxes (`hdf5_lazy.rs`),
/// as `hdf5.rs`'s `lazy_opened` takes a dataset.
pub(crate) fn open_lazy(
    path: &Path,
    opts: &ReadOptions,
) -> Result<Option<(super::hdf5_lazy::H5Source, FileInfo)>, IoError> {
    let h5 = h5::open(path)?;
    let o = open(path.to_path_buf(), h5, opts)?;
    super::hdf5::lazy_opened(o, None, opts)
}

/// The VTKHDF file `file_path`, open as `h5`, with its array picked and
/// placed: what the eager reader and the box-by-box one read.
pub(crate) fn open(
    file_path: PathBuf,
    h5: h5::H5File,
    opts: &ReadOptions,
) -> Result<Opened, IoError> {
    let fail = |reason: String| IoError::invalid(&file_path, format!("VTKHDF: {reason}"));
    let root = h5
        .file
        .group(ROOT)
        .map_err(|e| fail(format!("no /{ROOT} group ({e})")))?;
    let attrs = sorted_attrs(root.attrs());
    let attr = |name: &str| attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v);
    let kind = attr("Type").and_then(text).unwrap_or_default();
    if kind != "ImageData" {
        return Err(fail(format!(
            "Type \"{kind}\" is not read: volray reads VTKHDF ImageData (volumes on a regular grid)"
        )));
    }
    if root.group("Steps").is_ok() {
        return Err(fail(
            "time steps (/VTKHDF/Steps) are not read yet: write one step per file".into(),
        ));
    }
    let extent = attr("WholeExtent")
        .and_then(numbers)
        .filter(|e| e.len() == 6 && e.iter().all(|v| v.fract() == 0.0 && v.abs() < 1e15))
        .ok_or_else(|| fail("WholeExtent is not six whole numbers".into()))?;
    let vector = |name: &str, default: DVec3| -> Result<DVec3, IoError> {
        match attr(name).map(numbers) {
            None => Ok(default),
            Some(Some(v)) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
                Ok(DVec3::new(v[0], v[1], v[2]))
            }
            Some(_) => Err(fail(format!("{name} is not three finite numbers"))),
        }
    };
    let spacing = vector("Spacing", DVec3::ONE)?;
    if spacing.min_element() <= 0.0 {
        return Err(fail(format!(
            "Spacing {}, {}, {} is not positive",
            spacing.x, spacing.y, spacing.z
        )));
    }
    let origin = vector("Origin", DVec3::ZERO)?;
    if let Some(d) = attr("Direction") {
        let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let same = numbers(d).is_some_and(|d| {
            d.len() == 9 && d.iter().zip(identity).all(|(a, b)| (a - b).abs() < 1e-7)
        });
        if !same {
            return Err(fail(format!(
                "Direction {} is not the identity: rotated or flipped image data is not read yet",
                shown(d)
            )));
        }
    }
    let points = [0, 1, 2].map(|a| extent[2 * a + 1] - extent[2 * a] + 1.0);
    if points.iter().any(|&n| n < 1.0) {
        return Err(fail(format!("WholeExtent {extent:?} is empty")));
    }

    let (name, cells, others) = pick(&root, opts).map_err(fail)?;
    let group = if cells { "CellData" } else { "PointData" };
    let full = format!("/{ROOT}/{group}/{name}");
    let what = |reason: String| fail(format!("array \"{group}/{name}\": {reason}"));
    let dataset = h5.file.dataset(&full).map_err(|e| what(e.to_string()))?;
    let sample = numeric_type(&dataset).map_err(what)?;
    h5::check_filters(&dataset).map_err(what)?;
    let shape = h5::shape(&dataset).map_err(what)?;
    // Cells are one fewer than points along an axis of more than one point.
    let want: Vec<usize> = [2, 1, 0]
        .map(|a| {
            let n = points[a] as usize;
            if cells && n > 1 { n - 1 } else { n }
        })
        .to_vec();
    let roles = match shape.len() {
        3 => vec![Role::Z, Role::Y, Role::X],
        4 => vec![Role::Z, Role::Y, Role::X, Role::Channel],
        _ => vec![],
    };
    if roles.is_empty() || shape[..3] != want[..] {
        return Err(what(format!(
            "shape {shape:?}, but WholeExtent {extent:?} makes {} of (z, y, x) = {want:?}[, components]",
            if cells { "cells" } else { "points" }
        )));
    }
    let volumes = hdf5_axes::volumes(&shape, &roles);
    let holder = format!("VTKHDF array \"{name}\"");
    let picked = volumes.pick(
        &file_path,
        opts,
        AxisNames {
            holder: &holder,
            time: "time",
            channel: "its components",
        },
    )?;
    let frame = hdf5_axes::frame_of(&shape, &roles, picked);
    let placement = Placement::new(&shape, &roles, frame)
        .map_err(|frames| what(format!("component {frame} of {frames}")))?;
    let dims = placement.dims;

    let mut info = FileInfo::new(sample.name.clone());
    info.set_volumes(volumes, picked);
    info.header = attrs
        .iter()
        .map(|(n, v)| (format!("VTKHDF {n}"), shown(v)))
        .collect();
    info.header.push((
        "array".into(),
        format!("{group}/{name} {shape:?} {}", sample.name),
    ));
    let first = DVec3::new(extent[0], extent[2], extent[4]);
    let centre = if cells {
        DVec3::splat(0.5)
    } else {
        DVec3::ZERO
    };
    let origin = origin + (first + centre) * spacing;
    info.notes.push(format!(
        "VTKHDF ImageData: {} array \"{name}\" stored (z, y, x{}), x fastest as VTK keeps it; extent {extent:?} from Origin {}, {}, {} by Spacing {}, {}, {}{}",
        if cells { "cell" } else { "point" },
        if shape.len() == 4 { ", component" } else { "" },
        origin.x - (first.x + centre.x) * spacing.x,
        origin.y - (first.y + centre.y) * spacing.y,
        origin.z - (first.z + centre.z) * spacing.z,
        spacing.x,
        spacing.y,
        spacing.z,
        if cells { "; samples at the cells' centres" } else { "" }
    ));
    if let Some(all) = others {
        info.notes
            .push(format!("its arrays: {all} (--array picks one)"));
    }
    if shape.len() == 4 {
        info.notes.push(format!(
            "component {} of {} read (--channel picks another)",
            picked.channel, shape[3]
        ));
    }
    Ok(Opened {
        file_path,
        h5,
        name: full,
        dataset,
        sample,
        shape,
        placement,
        dims,
        info,
        spacing,
        origin,
    })
}

/// The array to read and whether it is a cell array (see the module
/// docs), or why none can be.
fn pick(root: &Group, opts: &ReadOptions) -> Result<(String, bool, Option<String>), String> {
    let names = |group: &str| -> Vec<String> {
        let mut v = root
            .group(group)
            .and_then(|g| g.datasets())
            .unwrap_or_default();
        v.sort();
        v
    };
    let (point, cell) = (names("PointData"), names("CellData"));
    let all = || {
        let mut v: Vec<String> = point.iter().map(|n| format!("PointData/{n}")).collect();
        v.extend(cell.iter().map(|n| format!("CellData/{n}")));
        if v.len() > LISTED {
            let more = v.len() - LISTED;
            v.truncate(LISTED);
            v.push(format!("and {more} more"));
        }
        if v.is_empty() {
            "none".into()
        } else {
            v.join(", ")
        }
    };
    if let Some(asked) = &opts.array {
        let (in_point, in_cell) = match asked.split_once('/') {
            Some(("PointData", n)) => (point.iter().any(|p| p == n).then_some(n), None),
            Some(("CellData", n)) => (None, cell.iter().any(|c| c == n).then_some(n)),
            _ => (
                point.iter().any(|p| p == asked).then_some(asked.as_str()),
                cell.iter().any(|c| c == asked).then_some(asked.as_str()),
            ),
        };
        return match (in_point, in_cell) {
            (Some(n), _) => Ok((n.to_string(), false, None)),
            (None, Some(n)) => Ok((n.to_string(), true, None)),
            (None, None) => Err(format!("no array \"{asked}\"; its arrays: {}", all())),
        };
    }
    let active = point.iter().find(|n| {
        root.dataset(&format!("PointData/{n}")).is_ok_and(|d| {
            sorted_attrs(d.attrs())
                .iter()
                .any(|(k, v)| k == "Attribute" && text(v).as_deref() == Some("Scalars"))
        })
    });
    let others = (point.len() + cell.len() > 1).then(all);
    match (active, point.first(), cell.first()) {
        (Some(n), _, _) | (None, Some(n), _) => Ok((n.clone(), false, others)),
        (None, None, Some(n)) => Ok((n.clone(), true, others)),
        (None, None, None) => Err("no PointData or CellData array".into()),
    }
}
