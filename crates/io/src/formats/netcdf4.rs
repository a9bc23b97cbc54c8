//! NetCDF-4 variables (`file.nc`, `file.nc:/variable`): HDF5 underneath,
//! read through the HDF5 layer (`hdf5.rs`, `hdf5_lazy.rs`) with the CF
//! conventions (`shared/cf.rs`, shared with NetCDF-3) giving what the
//! variable means.
//!
//! The NetCDF data model is recovered from what netCDF-C writes into the
//! HDF5 file: every dataset of the variable's group is a variable but the
//! dimension-only scales (`NAME` "This is a netCDF dimension but not a
//! netCDF variable"); a variable's dimension names come from its
//! `_Netcdf4Coordinates` (one dimension id per axis) and the scales'
//! `_Netcdf4Dimid`; without them (files of netCDF-C before 4.1, and of
//! other writers), from the `DIMENSION_LIST` object references HDF5's
//! own API attaches, which `hdf5-pure` 0.47 cannot follow and
//! `hdf5-reader` does (`shared/hdf5_index.rs`: each reference an object
//! header's address, matched to the scales' own); a coordinate variable
//! (a scale) has its own name as dimension. A variable with neither gets
//! no names, and CF places its axes by position (the last x).
//!
//! Then, through `cf.rs`: the variable is the one `file.nc:/var` or
//! `--array` names, else the only data variable of three spatial
//! dimensions (refused listing them otherwise); its dimensions' names,
//! `axis`, `standard_name`, `positive` or `units` say which is x, y, z and
//! time; the time dimension numbers the volumes (`--frame`); coordinate
//! variables give spacing, origin and the length unit (a decreasing one a
//! negative step, flipped); `scale_factor`/`add_offset` scale the stored
//! values and `_FillValue`/`missing_value`/the valid range read as NaN
//! (the volume then kept as `f32`).
//!
//! Box by box ([`open_lazy`], through `hdf5_lazy.rs`): the same axes,
//! spacing, origin and values, each box read from the chunks or rows it
//! covers. Along a coordinate that runs backward in the volume (latitude
//! from north to south; a vertical one that points down, placed at
//! z = −value by `cf.rs`, stored from the top down: pressure from 100 hPa
//! to 1000, ocean depth from the surface) each box is read from the file's
//! mirrored range and flipped, so that it is the box of the volume the
//! eager reader flips whole.
//!
//! Opening costs one open of each dataset of the variable's group (and of
//! each group above it, for the dimensions' scales): the scales' dimension
//! ids are gathered as the datasets are listed, so naming every variable's
//! dimensions is linear in the number of variables.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use hdf5_pure::{AttrValue, Dataset, Group};
use volray_core::glam::DVec3;

use super::hdf5::{Opened, read_opened};
use super::hdf5_axes::{Placement, Role};
use super::hdf5_lazy::{H5Source, from_opened};
use crate::shared::cf::{self, Packing, Value, Variable};
use crate::shared::hdf5::{
    self as h5, NumericType, check_filters, numbers, numeric_type, read_small, sorted_attrs, text,
};
use crate::shared::hdf5_index;
use crate::{FileInfo, IoError, Loaded, ReadOptions, VolumeFormat, split_hdf5_path};

/// The `NAME` netCDF-C gives a dimension that has no coordinate variable.
const DIMENSION_ONLY: &str = "This is a netCDF dimension but not a netCDF variable";

/// Attributes netCDF-C and HDF5's dimension scales keep for themselves.
const INTERNAL: [&str; 8] = [
    "CLASS",
    "NAME",
    "REFERENCE_LIST",
    "DIMENSION_LIST",
    "_Netcdf4Dimid",
    "_Netcdf4Coordinates",
    "_nc3_strict",
    "_NCProperties",
];

/// Datasets of a group looked at, at most.
const MAX_VARIABLES: usize = 10_000;

/// Coordinate values read, at most (a dimension longer than this has no
/// volume a file could hold anyway).
const MAX_COORDINATES: usize = 1 << 24;

/// A variable opened and placed, nothing of its samples read.
struct Found {
    opened: Opened,
    packing: Packing,
    /// The grid's step along x, y, z (negative along a decreasing
    /// coordinate).
    steps: [DVec3; 3],
}

#[cfg(test)]
thread_local! {
    /// Datasets opened on this thread, for the test that opening is linear.
    static OPENED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Opens dataset `name` of `group`: every dataset this module opens, so
/// that a test can count them.
fn dataset_in(group: &Group, name: &str) -> Result<Dataset, hdf5_pure::Error> {
    #[cfg(test)]
    OPENED.with(|n| n.set(n.get() + 1));
    group.dataset(name)
}

/// Reads the variable `path` names (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let Found {
        opened,
        packing,
        steps,
    } = open(path, opts)?;
    let real = |v: f64| packing.real(v);
    let real: Option<&dyn Fn(f64) -> f64> = (!packing.is_identity()).then_some(&real);
    read_opened(opened, real, steps, VolumeFormat::Netcdf, opts)
}

/// Opens the variable `path` names as a source of boxes; `None` where it
/// is read whole instead (a volume one sample thick, a grid whose steps
/// are not along x, y and z).
pub(crate) fn open_lazy(
    path: &Path,
    opts: &ReadOptions,
) -> Result<Option<(H5Source, FileInfo)>, IoError> {
    let Found {
        mut opened,
        packing,
        steps,
    } = open(path, opts)?;
    let aligned = (0..3).all(|a| (0..3).all(|w| w == a || steps[a][w] == 0.0));
    if !aligned || opened.dims.iter().any(|&n| n < 2) {
        return Ok(None);
    }
    // Along a decreasing coordinate the volume runs from the file's last
    // sample: its origin as `grid_to_volume` places the eager reader's.
    let flip: [bool; 3] = std::array::from_fn(|a| steps[a][a] < 0.0);
    for a in 0..3 {
        if flip[a] {
            opened.origin += steps[a] * (opened.dims[a].saturating_sub(1)) as f64;
        }
    }
    let real: Option<super::hdf5_lazy::RealValue> = (!packing.is_identity()).then(|| {
        let packing = packing.clone();
        Arc::new(move |v: f64| packing.real(v)) as super::hdf5_lazy::RealValue
    });
    from_opened(opened, real, flip, opts).map(Some)
}

/// The file and variable `path` names, the NetCDF data model of the
/// variable's group, the variable chosen, laid out and placed.
fn open(path: &Path, opts: &ReadOptions) -> Result<Found, IoError> {
    let (file_path, named): (PathBuf, Option<String>) = match split_hdf5_path(path) {
        Some((file, var)) => (file, Some(var)),
        None => (path.to_path_buf(), None),
    };
    let h5 = h5::open(&file_path)?;
    let fail = |reason: String| IoError::invalid(&file_path, format!("NetCDF-4: {reason}"));
    let named = named.map(|n| n.trim_start_matches('/').to_string());
    let (group_path, wanted) = match named.as_deref().or(opts.array.as_deref()) {
        Some(n) => match n.rsplit_once('/') {
            Some((g, v)) => (format!("/{g}"), Some(v.to_string())),
            None => ("/".to_string(), Some(n.to_string())),
        },
        None => ("/".to_string(), None),
    };
    let group = h5
        .file
        .group(&group_path)
        .map_err(|e| fail(format!("no group {group_path}: {e}")))?;
    let mut datasets = group.datasets().unwrap_or_default();
    datasets.sort();
    if datasets.len() > MAX_VARIABLES {
        return Err(fail(format!(
            "group {group_path} holds {} datasets, more than the {MAX_VARIABLES} looked at",
            datasets.len()
        )));
    }
    let prefix = if group_path == "/" {
        String::new()
    } else {
        group_path.clone()
    };
    // Each dataset opened once: what a variable needs kept, the scales'
    // dimension ids noted.
    let mut listed: Vec<Listed> = Vec::new();
    let mut dimensions: Vec<(String, u64, bool)> = Vec::new();
    let mut dimids: Vec<(f64, String)> = Vec::new();
    // The scales' absolute paths, for DIMENSION_LIST's references.
    let mut scale_paths: Vec<String> = Vec::new();
    let mut info_notes: Vec<String> = Vec::new();
    for name in &datasets {
        let Ok(ds) = dataset_in(&group, name) else {
            continue;
        };
        let attrs = sorted_attrs(ds.attrs());
        let attr = |k: &str| attrs.iter().find(|(n, _)| n == k).map(|(_, v)| v);
        let scale = attr("CLASS").and_then(text).as_deref() == Some("DIMENSION_SCALE");
        if scale {
            note_dimid(&mut dimids, name, attr("_Netcdf4Dimid"));
            scale_paths.push(format!("{prefix}/{name}"));
        }
        let Ok(shape) = ds.shape() else { continue };
        if scale {
            dimensions.push((name.clone(), shape.first().copied().unwrap_or(0), false));
        }
        if attr("NAME")
            .and_then(text)
            .is_some_and(|n| n.starts_with(DIMENSION_ONLY))
        {
            continue;
        }
        let Ok(sample) = numeric_type(&ds) else {
            continue;
        };
        listed.push(Listed {
            name: name.clone(),
            shape,
            scale,
            attrs,
            sample,
        });
    }
    // The scales of the groups above, nearest first (netCDF-C's
    // dimensions are visible in the groups below theirs).
    let mut above = group_path.as_str();
    while above != "/" {
        above = match above.rfind('/') {
            Some(0) | None => "/",
            Some(at) => &above[..at],
        };
        let Ok(g) = h5.file.group(above) else {
            continue;
        };
        for name in g.datasets().unwrap_or_default().iter().take(MAX_VARIABLES) {
            let Ok(ds) = dataset_in(&g, name) else {
                continue;
            };
            let Ok(attrs) = ds.attrs() else { continue };
            if attrs.get("CLASS").and_then(text).as_deref() == Some("DIMENSION_SCALE") {
                note_dimid(&mut dimids, name, attrs.get("_Netcdf4Dimid"));
                scale_paths.push(format!("{}/{name}", above.trim_end_matches('/')));
            }
        }
    }
    // Variables without _Netcdf4Coordinates (netCDF-C before 4.1 wrote
    // none): their dimensions from the DIMENSION_LIST references to the
    // scales, followed through hdf5-reader (hdf5-pure cannot), the file
    // opened once for all of them.
    let coordinates = |l: &Listed| l.attrs.iter().any(|(n, _)| n == "_Netcdf4Coordinates");
    let old_style: Vec<String> = listed
        .iter()
        .filter(|l| !(coordinates(l) || (l.scale && l.shape.len() == 1)))
        .map(|l| l.name.clone())
        .collect();
    let mut referenced: Vec<(String, Vec<String>)> = Vec::new();
    if !old_style.is_empty() && !scale_paths.is_empty() {
        let full: Vec<String> = old_style.iter().map(|n| format!("{prefix}/{n}")).collect();
        match hdf5_index::dimension_lists(&file_path, &full, &scale_paths) {
            Ok(lists) => {
                for (name, dims) in old_style.iter().zip(lists) {
                    if let Some(dims) = dims {
                        referenced.push((name.clone(), dims));
                    }
                }
            }
            Err(e) => info_notes.push(format!(
                "DIMENSION_LIST not followed ({e}): axes by position"
            )),
        }
    }
    let mut vars: Vec<Variable> = Vec::new();
    let mut unnamed = Vec::new();
    for l in listed {
        let attr = |k: &str| l.attrs.iter().find(|(n, _)| n == k).map(|(_, v)| v);
        let named = attr("_Netcdf4Coordinates")
            .and_then(numbers)
            .and_then(|ids| {
                ids.iter()
                    .map(|id| dimids.iter().find(|(i, _)| i == id).map(|(_, n)| n.clone()))
                    .collect::<Option<Vec<String>>>()
            })
            .or_else(|| {
                referenced
                    .iter()
                    .find(|(n, _)| *n == l.name)
                    .map(|(_, d)| d.clone())
            })
            .filter(|d| d.len() == l.shape.len());
        let dims = match named {
            Some(d) => d,
            None if l.scale && l.shape.len() == 1 => vec![l.name.clone()],
            None => {
                unnamed.push(l.name.clone());
                (0..l.shape.len())
                    .map(|i| format!("{}#{i}", l.name))
                    .collect()
            }
        };
        vars.push(Variable {
            name: l.name,
            dims,
            shape: l.shape,
            attrs: l
                .attrs
                .iter()
                .filter(|(k, _)| !INTERNAL.contains(&k.as_str()))
                .filter_map(|(k, v)| cf_value(v).map(|v| (k.clone(), v)))
                .collect(),
            integer: !l.sample.name.starts_with("float"),
            type_name: l.sample.name,
        });
    }
    let var = cf::choose(&file_path, &vars, wanted.as_deref())?.clone();
    let layout = cf::layout(&file_path, &var, &vars, opts.frame)?;
    let what = |reason: String| fail(format!("variable {}: {reason}", var.name));

    // The volume's axes as hdf5_axes.rs places them: x, y, z as CF says,
    // the frame dimension as time, the others (one sample long) held at 0.
    let roles: Vec<Role> = (0..var.dims.len())
        .map(|d| match layout.spatial.iter().position(|&s| s == d) {
            Some(0) => Role::X,
            Some(1) => Role::Y,
            Some(_) => Role::Z,
            None if Some(d) == layout.frame_dim => Role::Time,
            None => Role::Channel,
        })
        .collect();
    let shape = usize_shape(&var.shape).map_err(what)?;
    let placement = Placement::new(&shape, &roles, layout.frame)
        .map_err(|frames| what(format!("frame {} of {frames}", layout.frame)))?;

    let full = format!("{prefix}/{}", var.name);
    let dataset = dataset_in(&group, &var.name).map_err(|e| what(format!("cannot open: {e}")))?;
    let sample = numeric_type(&dataset).map_err(&what)?;
    check_filters(&dataset).map_err(&what)?;
    let mut info = FileInfo::new(sample.name.clone());
    let globals: Vec<(String, Value)> = sorted_attrs(h5.file.root().attrs())
        .iter()
        .filter(|(k, _)| !INTERNAL.contains(&k.as_str()))
        .filter_map(|(k, v)| cf_value(v).map(|v| (k.clone(), v)))
        .collect();
    cf::describe(&dimensions, &globals, &vars, &var, &layout, &mut info);
    info.frames = layout.frames;
    info.frame = layout.frame;
    let source = if referenced.iter().any(|(n, _)| *n == var.name) {
        "the DIMENSION_LIST references to its dimension scales (a file of netCDF-C before _Netcdf4Coordinates)"
    } else {
        "_Netcdf4Coordinates and the dimension scales' _Netcdf4Dimid"
    };
    info.notes.push(format!(
        "NetCDF-4 variable {full} read through the HDF5 layer, dimensions ({}) from {source}",
        var.dims.join(", ")
    ));
    if !unnamed.is_empty() {
        info.notes.push(format!(
            "no _Netcdf4Coordinates or DIMENSION_LIST naming its scales on {}: dimension names unknown, axes by position",
            unnamed.join(", ")
        ));
    }
    info.notes.append(&mut info_notes);
    let mut coordinate = |c: &Variable| -> Result<Vec<f64>, IoError> {
        let ds = dataset_in(&group, &c.name)
            .map_err(|e| fail(format!("coordinate variable {}: {e}", c.name)))?;
        let values = read_small(&ds, MAX_COORDINATES)
            .map_err(|e| fail(format!("coordinate variable {}: {e}", c.name)))?;
        let packing = Packing::of(&file_path, c)?;
        Ok(values.into_iter().map(|v| packing.real(v)).collect())
    };
    let placed = cf::place(&file_path, &var, &vars, &layout, &mut coordinate, &mut info)?;
    info.length_unit = placed.length_unit.clone();
    info.axis_units = placed.axis_units.clone();
    // cf.rs's steps run along the variable's spatial dimensions fastest
    // first; here along x, y, z.
    let order = layout.fastest_first();
    let steps: [DVec3; 3] = std::array::from_fn(|role| {
        let k = order
            .iter()
            .position(|&d| d == layout.spatial[role])
            .unwrap_or(role);
        placed.steps[k]
    });
    let packing = Packing::of(&file_path, &var)?;
    info.notes.extend(packing.note(&var.name));
    let spacing = DVec3::new(steps[0].x.abs(), steps[1].y.abs(), steps[2].z.abs());
    let dims = placement.dims;
    Ok(Found {
        opened: Opened {
            file_path: file_path.clone(),
            h5,
            name: full,
            dataset,
            sample,
            shape,
            placement,
            dims,
            info,
            spacing,
            origin: placed.origin,
        },
        packing,
        steps,
    })
}

/// A dataset of the variable's group, opened once, as a variable needs it.
struct Listed {
    name: String,
    shape: Vec<u64>,
    /// A dimension scale (a coordinate variable, or a dimension alone).
    scale: bool,
    attrs: Vec<(String, AttrValue)>,
    sample: NumericType,
}

/// Notes the dimension id (`_Netcdf4Dimid`) of the scale `name`, unless a
/// nearer scale has it already (h5netcdf gives its variables a
/// `_Netcdf4Dimid` too: only scales name dimensions).
fn note_dimid(dimids: &mut Vec<(f64, String)>, name: &str, id: Option<&AttrValue>) {
    if let Some(id) = id.and_then(numbers).and_then(|v| v.first().copied())
        && !dimids.iter().any(|(i, _)| *i == id)
    {
        dimids.push((id, name.to_string()));
    }
}

/// An HDF5 attribute as CF reads it: text or numbers.
fn cf_value(v: &AttrValue) -> Option<Value> {
    if let Some(t) = text(v) {
        return Some(Value::Text(t));
    }
    numbers(v).map(Value::Numbers)
}

fn usize_shape(shape: &[u64]) -> Result<Vec<usize>, String> {
    shape
        .iter()
        .map(|&n| usize::try_from(n).map_err(|_| format!("shape {shape:?} is too large")))
        .collect()
}

#[cfg(test)]
mod tests {
    //! The fixtures `tests/fixtures/netcdf4/*.nc`, written by netCDF4-python
    //! (`make_netcdf4_fixtures.py`): volume (x, y, z) = (5, 4, 3) holding
    //! v = x + 10y + 100z, stored var[z, y, x] (var[time, z, y, x]).

    use super::*;
    use volray_core::{Volume, VolumeSource};

    fn fixture(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/netcdf4")
            .join(name)
    }

    fn opts(frame: Option<usize>, array: Option<&str>) -> ReadOptions {
        ReadOptions {
            frame,
            array: array.map(str::to_string),
            ..ReadOptions::default()
        }
    }

    fn ramp(x: usize, y: usize, z: usize) -> f64 {
        (x + 10 * y + 100 * z) as f64
    }

    fn check(what: &str, v: &Volume, want: impl Fn(usize, usize, usize) -> f64) {
        assert_eq!(v.dims(), [5, 4, 3], "{what}");
        for z in 0..3 {
            for y in 0..4 {
                for x in 0..5 {
                    let (got, want) = (f64::from(v.get(x, y, z)), want(x, y, z));
                    assert!(
                        got == want || (got.is_nan() && want.is_nan()),
                        "{what} at ({x}, {y}, {z}): {got}, not {want}"
                    );
                }
            }
        }
    }

    /// Every box of 2 samples a side or more, read box by box, equals the
    /// same box of `whole`.
    fn boxes_equal_eager(what: &str, source: &dyn VolumeSource, whole: &Volume) {
        let grid = source.grid();
        assert_eq!(grid.dims, whole.dims(), "{what}");
        assert_eq!(grid.spacing, whole.spacing(), "{what}");
        assert_eq!(grid.origin, whole.origin(), "{what}");
        let d = whole.dims();
        let mut n = 0;
        for lo in
            (0..d[2]).flat_map(|z| (0..d[1]).flat_map(move |y| (0..d[0]).map(move |x| [x, y, z])))
        {
            for hi in (0..=d[2])
                .flat_map(|z| (0..=d[1]).flat_map(move |y| (0..=d[0]).map(move |x| [x, y, z])))
            {
                if (0..3).any(|a| hi[a] < lo[a] + 2) {
                    continue;
                }
                let part = source
                    .read_box(lo, hi)
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                for z in lo[2]..hi[2] {
                    for y in lo[1]..hi[1] {
                        for x in lo[0]..hi[0] {
                            let (a, b) = (
                                part.get(x - lo[0], y - lo[1], z - lo[2]),
                                whole.get(x, y, z),
                            );
                            assert!(
                                a == b || (a.is_nan() && b.is_nan()),
                                "{what} {lo:?}..{hi:?} at ({x}, {y}, {z}): {a} != {b}"
                            );
                        }
                    }
                }
                n += 1;
            }
        }
        assert_eq!(n, 10 * 6 * 3, "{what}");
    }

    #[test]
    fn a_cf_variable_gets_its_axes_spacing_origin_units_and_time_frames() {
        for spec in ["cf_tzyx.nc", "cf_tzyx.nc:/rho", "cf_tzyx.nc:rho"] {
            for t in 0..2 {
                let path = PathBuf::from(format!("{}", fixture(spec).display()));
                let l = read(&path, &opts(Some(t), None)).unwrap_or_else(|e| panic!("{e}"));
                check(spec, &l.volume, |x, y, z| ramp(x, y, z) + 1000.0 * t as f64);
                // File index [t, z=0, y=0, x=1] at volume (1, 0, 0).
                assert_eq!(f64::from(l.volume.get(1, 0, 0)), 1.0 + 1000.0 * t as f64);
                assert_eq!(l.volume.spacing(), DVec3::new(0.5, 0.25, 2.0));
                assert_eq!(l.volume.origin(), DVec3::new(10.0, -2.0, 100.0));
                assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
                assert_eq!((l.info.frames, l.info.frame), (2, t));
            }
        }
        let err = read(&fixture("cf_tzyx.nc"), &opts(Some(2), None)).unwrap_err();
        assert!(err.to_string().contains("frame 2 is out of range"), "{err}");
    }

    #[test]
    fn packed_values_are_scaled_and_fill_values_are_nan() {
        let path = fixture("cf_packed.nc");
        let err = read(&path, &opts(None, None)).unwrap_err().to_string();
        assert!(
            err.contains("2 variables hold volumes")
                && err.contains("salt(z, y, x)")
                && err.contains("temp(z, y, x)"),
            "{err}"
        );
        let l = read(&path, &opts(None, Some("temp"))).unwrap();
        check("temp", &l.volume, |x, y, z| {
            if (x, y, z) == (4, 3, 2) {
                f64::NAN
            } else {
                ramp(x, y, z)
            }
        });
        assert!(
            l.info.notes.iter().any(|n| n.contains("scale_factor")),
            "{:?}",
            l.info.notes
        );
        let l = read(
            &PathBuf::from(format!("{}:/salt", path.display())),
            &opts(None, None),
        )
        .unwrap();
        check("salt", &l.volume, ramp);
        assert_eq!(l.volume.spacing(), DVec3::ONE);
    }

    #[test]
    fn decreasing_coordinates_are_flipped_to_run_forward() {
        // lat 30, 20, 10, 0 (decreasing, flipped) and lev 1000, 850, 700
        // hPa, positive down: at z = −lev, −1000 to −700, forward.
        let l = read(&fixture("cf_latlon.nc"), &opts(None, None)).unwrap();
        check("t", &l.volume, |x, y, z| ramp(x, 3 - y, z));
        assert_eq!(l.volume.spacing(), DVec3::new(10.0, 10.0, 150.0));
        assert_eq!(l.volume.origin(), DVec3::new(0.0, 0.0, -1000.0));
        // Box by box: each box read from the mirrored range and flipped
        // (along y alone: z = −lev runs forward).
        let (source, info) = open_lazy(&fixture("cf_latlon.nc"), &opts(None, None))
            .unwrap()
            .unwrap();
        boxes_equal_eager("cf_latlon.nc", &source, &l.volume);
        assert!(
            info.notes
                .iter()
                .any(|n| n.contains("mirrored range along y (its coordinate decreases)")),
            "{:?}",
            info.notes
        );
    }

    /// A NetCDF-4 file as netCDF-C lays one out, written by `hdf5-pure`:
    /// dimensions x, y, z (4, 3, 2) as coordinate variables (dimension
    /// scales with `_Netcdf4Dimid`), and `n` variables v0, v1, ... of
    /// (z, y, x) naming them in `_Netcdf4Coordinates`.
    fn many_variables(dir: &Path, n: usize) -> PathBuf {
        use hdf5_pure::FileBuilder;
        let mut fb = FileBuilder::new();
        for (id, (name, len)) in [("x", 4), ("y", 3), ("z", 2)].into_iter().enumerate() {
            let values: Vec<f32> = (0..len).map(|i| i as f32).collect();
            fb.create_dataset(name)
                .with_f32_data(&values)
                .with_shape(&[len as u64])
                .set_attr("CLASS", AttrValue::String("DIMENSION_SCALE".into()))
                .set_attr("NAME", AttrValue::String(name.into()))
                .set_attr("_Netcdf4Dimid", AttrValue::I32(id as i32));
        }
        for v in 0..n {
            let values: Vec<f32> = (0..24).map(|i| (i + v) as f32).collect();
            fb.create_dataset(&format!("v{v}"))
                .with_f32_data(&values)
                .with_shape(&[2, 3, 4])
                .set_attr("_Netcdf4Coordinates", AttrValue::I32Array(vec![2, 1, 0]));
        }
        let path = dir.join(format!("many{n}.nc"));
        fb.write(&path).unwrap();
        path
    }

    #[test]
    fn opening_a_variable_opens_each_dataset_once_whatever_their_number() {
        let dir = tempfile::tempdir().unwrap();
        let mut opened = Vec::new();
        for n in [10, 40, 160] {
            let path = many_variables(dir.path(), n);
            OPENED.with(|c| c.set(0));
            let l = read(&path, &opts(None, Some("v3"))).unwrap_or_else(|e| panic!("{e}"));
            opened.push(OPENED.with(|c| c.get()));
            // v3 holds i + 3 at C-order index i of (z, y, x).
            assert_eq!(l.volume.dims(), [4, 3, 2]);
            assert_eq!(
                f64::from(l.volume.get(1, 2, 1)),
                (12 + 2 * 4 + 1 + 3) as f64
            );
            assert!(
                l.info
                    .notes
                    .iter()
                    .any(|n| n.contains("dimensions (z, y, x)")),
                "{:?}",
                l.info.notes
            );
        }
        // n + 3 datasets listed, each opened once; then the variable and
        // its three coordinate variables again.
        assert_eq!(opened, vec![10 + 3 + 4, 40 + 3 + 4, 160 + 3 + 4]);
    }

    #[test]
    fn every_box_read_box_by_box_equals_the_eager_read() {
        for (spec, frames, array) in [
            ("cf_tzyx.nc", 2, None),
            ("cf_packed.nc", 1, Some("temp")),
            ("cf_packed.nc", 1, Some("salt")),
        ] {
            for t in 0..frames {
                let o = opts(Some(t), array);
                let o = if frames == 1 {
                    ReadOptions { frame: None, ..o }
                } else {
                    o
                };
                let whole = read(&fixture(spec), &o).unwrap().volume;
                let (source, _) = open_lazy(&fixture(spec), &o).unwrap().unwrap();
                boxes_equal_eager(&format!("{spec} {array:?} frame {t}"), &source, &whole);
            }
        }
    }

    #[test]
    fn damaged_files_are_refused_in_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let good = std::fs::read(fixture("cf_tzyx.nc")).unwrap();
        for len in [good.len() - 100, good.len() / 2, 600, 10] {
            let path = dir.path().join(format!("cut{len}.nc"));
            std::fs::write(&path, &good[..len]).unwrap();
            let err = read(&path, &opts(None, None)).unwrap_err();
            assert!(!err.is_io_failure(), "{err}");
            let msg = err.to_string();
            assert!(
                msg.starts_with(&path.display().to_string()) && !msg.contains('\n'),
                "{msg}"
            );
            assert!(open_lazy(&path, &opts(None, None)).is_err(), "{len}");
        }
        // A variable that is not there is refused naming the candidates.
        let err = read(&fixture("cf_tzyx.nc"), &opts(None, Some("nothing"))).unwrap_err();
        assert!(err.to_string().contains("rho(time, z, y, x)"), "{err}");
    }

    #[test]
    fn netcdf_dimension_names_orient_the_hdf5_route_too() {
        // h5netcdf gives the variable a _Netcdf4Dimid of its own: only the
        // scales name dimensions.
        let path = fixture("h5netcdf_zyx.nc");
        let l = read(&path, &opts(None, None)).unwrap();
        check("w (CF)", &l.volume, ramp);
        let on_hdf5 = |spec: &str| {
            let p = PathBuf::from(format!("{}{spec}", path.display()));
            crate::formats::hdf5::read(&p, &ReadOptions::default()).unwrap()
        };
        let l = on_hdf5(":/w");
        check("w (HDF5)", &l.volume, ramp);
        assert!(
            l.info
                .header
                .iter()
                .any(|(k, v)| k == "axis order" && v.contains("a[z, y, x] from dimension scales")),
            "{:?}",
            l.info.header
        );
        let tzyx = fixture("cf_tzyx.nc");
        let p = PathBuf::from(format!("{}:/rho", tzyx.display()));
        let l = crate::formats::hdf5::read(&p, &opts(Some(1), None)).unwrap();
        check("rho (HDF5)", &l.volume, |x, y, z| ramp(x, y, z) + 1000.0);
    }
}
