//! The CF conventions (<https://cfconventions.org>, version 1.11), format
//! neutral: what a NetCDF variable's dimensions and attributes say about
//! the volume it holds, for any container that stores NetCDF's data model
//! (NetCDF-3 in `formats/netcdf/`, NetCDF-4 over HDF5).
//!
//! A container describes its variables as [`Variable`]s (name, dimension
//! names and lengths, attributes as [`Value`]s) and lends a way to read a
//! 1-D coordinate variable's values; this module then
//!
//! 1. [`choose`]s the data variable: the one [`ReadOptions::array`]
//!    names, else the only one with three spatial dimensions (refused
//!    listing the candidates where there are several);
//! 2. finds its [`Layout`]: which dimension is x, y, z and time (CF §4:
//!    a coordinate variable's `axis` attribute, else its `standard_name`,
//!    `positive` or `units`, else the dimension's name; dimensions none of
//!    these names are spatial from the last backwards, as NetCDF stores
//!    slowest first: `(time, z, y, x)`, `(time, lev, lat, lon)`); one
//!    other dimension longer than 1 (time, preferably) holds the frames
//!    [`ReadOptions::frame`] picks;
//! 3. [`place`]s the grid from the coordinate variables (CF §5: the 1-D
//!    variable named as its dimension): spacing and origin where the
//!    values are evenly spaced within [`EVEN_TOLERANCE`] of the step
//!    (a decreasing coordinate gives a negative step, which
//!    `grid_to_volume` flips exactly); unevenly spaced coordinates are
//!    **refused** naming the axis (a grid drawn at index spacing would
//!    misplace every sample, and volray has no rectilinear grids); a
//!    dimension without a coordinate variable has spacing 1 from 0, with
//!    a note. A vertical coordinate that points down ([`points_down`]:
//!    `positive = "down"`, or a pressure or depth without `positive`) is
//!    placed at z = −value, so that up in the world is up in the
//!    atmosphere or ocean: 1000 hPa below 500 hPa, the seabed below the
//!    surface. Units go through `units.rs`: lengths (m, mm, km, µm, ...)
//!    are brought to the finest of them, which is the volume's; other
//!    units (degrees_north, degrees_east, hPa) are kept as they are, with
//!    a note;
//! 4. maps stored values to real ones ([`Packing`], CF §2.5 and §8.1):
//!    `_FillValue`, `missing_value` and values outside `valid_min`,
//!    `valid_max` or `valid_range` (compared with the stored values, as
//!    the NetCDF User Guide and netCDF4-python do) become NaN, which
//!    volray renders as empty space; the others are `stored ·
//!    scale_factor + add_offset`.
//!
//! [`describe`] fills [`FileInfo`] with the dimensions, variables and
//! attributes, for `volray info`.
//!
//! [`ReadOptions::array`]: crate::ReadOptions::array
//! [`ReadOptions::frame`]: crate::ReadOptions::frame

use std::path::Path;

use volray_core::glam::DVec3;

use crate::FileInfo;
use crate::error::IoError;
use crate::shared::units::{AxisUnit, is_pressure, one_length_unit};

/// An attribute's value: text (NetCDF `char`, a string) or numbers (any
/// numeric type, widened to `f64`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    Text(String),
    Numbers(Vec<f64>),
}

impl Value {
    /// The value as `volray info` shows it.
    pub(crate) fn shown(&self) -> String {
        match self {
            Value::Text(t) => format!("\"{t}\""),
            Value::Numbers(v) if v.len() == 1 => v[0].to_string(),
            Value::Numbers(v) => {
                let parts: Vec<String> = v.iter().take(16).map(f64::to_string).collect();
                let more = if v.len() > 16 { ", ..." } else { "" };
                format!("[{}{more}]", parts.join(", "))
            }
        }
    }
}

/// One variable of a NetCDF data model, as the container describes it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Variable {
    pub name: String,
    /// Its dimensions' names, slowest first.
    pub dims: Vec<String>,
    /// Their lengths (for the record dimension: the number of records).
    pub shape: Vec<u64>,
    /// Its attributes, in file order.
    pub attrs: Vec<(String, Value)>,
    /// The stored type as the container names it (`"int16"`, `"float32"`).
    pub type_name: String,
    /// Whether the stored type is an integer type (fill and valid range
    /// compare exactly; `scale_factor` makes real values of it).
    pub integer: bool,
}

impl Variable {
    /// The attribute `name`, if the variable has it.
    pub(crate) fn attr(&self, name: &str) -> Option<&Value> {
        self.attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    /// The text attribute `name`, trimmed.
    pub(crate) fn text(&self, name: &str) -> Option<&str> {
        match self.attr(name)? {
            Value::Text(t) => Some(t.trim_matches(|c: char| c == '\0' || c.is_whitespace())),
            Value::Numbers(_) => None,
        }
    }

    /// The numeric attribute `name`.
    pub(crate) fn numbers(&self, name: &str) -> Option<&[f64]> {
        match self.attr(name)? {
            Value::Numbers(v) => Some(v),
            Value::Text(_) => None,
        }
    }

    /// Whether it is a coordinate variable (CF §5): 1-D, named as its
    /// dimension.
    pub(crate) fn is_coordinate(&self) -> bool {
        self.dims.len() == 1 && self.dims[0] == self.name
    }
}

/// The role of a dimension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    X,
    Y,
    Z,
    Time,
}

impl Role {
    fn letter(self) -> &'static str {
        match self {
            Role::X => "x",
            Role::Y => "y",
            Role::Z => "z",
            Role::Time => "time",
        }
    }
}

/// Which of a variable's dimensions (indices into [`Variable::dims`]) is
/// x, y and z, and which holds its frames.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Layout {
    /// The dimensions of x, y and z.
    pub spatial: [usize; 3],
    /// The dimension whose index [`frame`](Self::frame) is read, if one
    /// is longer than 1; every other dimension is read at index 0.
    pub frame_dim: Option<usize>,
    /// Its length (1 without one).
    pub frames: usize,
    /// The frame read.
    pub frame: usize,
    /// Why each dimension was given its role, for the notes.
    pub reasons: Vec<String>,
}

impl Layout {
    /// The spatial dimensions in the variable's order, fastest first:
    /// index axes 0, 1 and 2 of a slab read in C order.
    pub(crate) fn fastest_first(&self) -> [usize; 3] {
        let mut s = self.spatial;
        s.sort_unstable_by(|a, b| b.cmp(a));
        s
    }
}

/// The relative tolerance on evenly spaced coordinates: every value within
/// this fraction of the step of `first + step · i` (single precision
/// coordinates of a few thousand points stay well inside).
pub(crate) const EVEN_TOLERANCE: f64 = 1e-3;

/// The role a dimension's coordinate variable (if any) or its name gives
/// it (CF §4.1–4.4), and why.
fn role_of(dim: &str, coord: Option<&Variable>) -> Option<(Role, String)> {
    if let Some(c) = coord {
        if let Some(axis) = c.text("axis") {
            let role = match axis.to_ascii_uppercase().as_str() {
                "X" => Some(Role::X),
                "Y" => Some(Role::Y),
                "Z" => Some(Role::Z),
                "T" => Some(Role::Time),
                _ => None,
            };
            if let Some(r) = role {
                return Some((r, format!("axis = \"{axis}\"")));
            }
        }
        if let Some(name) = c.text("standard_name") {
            let role = match name {
                "longitude" | "grid_longitude" | "projection_x_coordinate" => Some(Role::X),
                "latitude" | "grid_latitude" | "projection_y_coordinate" => Some(Role::Y),
                "altitude"
                | "height"
                | "height_above_geopotential_datum"
                | "depth"
                | "air_pressure"
                | "model_level_number"
                | "projection_z_coordinate" => Some(Role::Z),
                n if n.starts_with("atmosphere_") || n.starts_with("ocean_") => Some(Role::Z),
                "time" => Some(Role::Time),
                _ => None,
            };
            if let Some(r) = role {
                return Some((r, format!("standard_name = \"{name}\"")));
            }
        }
        if let Some(p) = c.text("positive")
            && matches!(p.to_ascii_lowercase().as_str(), "up" | "down")
        {
            return Some((Role::Z, format!("positive = \"{p}\"")));
        }
        if let Some(u) = c.text("units") {
            let l = u.to_ascii_lowercase();
            let role = if matches!(
                l.as_str(),
                "degrees_east" | "degree_east" | "degree_e" | "degrees_e" | "degreee" | "degreese"
            ) {
                Some(Role::X)
            } else if matches!(
                l.as_str(),
                "degrees_north"
                    | "degree_north"
                    | "degree_n"
                    | "degrees_n"
                    | "degreen"
                    | "degreesn"
            ) {
                Some(Role::Y)
            } else if l.contains(" since ") {
                Some(Role::Time)
            } else {
                None
            };
            if let Some(r) = role {
                return Some((r, format!("units = \"{u}\"")));
            }
        }
    }
    let role = match dim.to_ascii_lowercase().as_str() {
        "x" | "lon" | "long" | "longitude" | "xc" | "nx" | "ni" | "xspace" | "rlon"
        | "west_east" => Role::X,
        "y" | "lat" | "latitude" | "yc" | "ny" | "nj" | "yspace" | "rlat" | "south_north" => {
            Role::Y
        }
        "z" | "lev" | "level" | "levels" | "plev" | "depth" | "height" | "altitude" | "zc"
        | "nz" | "zspace" | "bottom_top" | "pressure" => Role::Z,
        "t" | "time" | "times" => Role::Time,
        _ => return None,
    };
    Some((role, "its name".into()))
}

/// The coordinate variable of dimension `dim`, if the file has one.
pub(crate) fn coordinate<'a>(vars: &'a [Variable], dim: &str) -> Option<&'a Variable> {
    vars.iter().find(|v| v.is_coordinate() && v.name == dim)
}

/// Which dimensions of `var` are x, y, z and frames (see the module doc),
/// and the frame read (`frame`, default 0, checked against their number).
pub(crate) fn layout(
    path: &Path,
    var: &Variable,
    vars: &[Variable],
    frame: Option<usize>,
) -> Result<Layout, IoError> {
    let fail = |reason: String| IoError::invalid(path, format!("variable {}: {reason}", var.name));
    let mut roles: Vec<Option<Role>> = vec![None; var.dims.len()];
    let mut reasons = vec![String::new(); var.dims.len()];
    for (d, dim) in var.dims.iter().enumerate() {
        if let Some((role, why)) = role_of(dim, coordinate(vars, dim)) {
            if let Some(other) = roles.iter().position(|r| *r == Some(role)) {
                return Err(fail(format!(
                    "dimensions \"{}\" and \"{dim}\" both are {}",
                    var.dims[other],
                    role.letter()
                )));
            }
            roles[d] = Some(role);
            reasons[d] = format!("{dim} is {} ({why})", role.letter());
        }
    }
    // Spatial axes no dimension names: the unnamed dimensions from the
    // last backwards (NetCDF stores x fastest).
    for role in [Role::X, Role::Y, Role::Z] {
        if roles.contains(&Some(role)) {
            continue;
        }
        let Some(d) = (0..var.dims.len()).rev().find(|&d| roles[d].is_none()) else {
            return Err(fail(format!(
                "dimensions ({}): no dimension for {}: volray reads variables of three spatial dimensions (x, y, z), and optionally time",
                var.dims.join(", "),
                role.letter()
            )));
        };
        roles[d] = Some(role);
        reasons[d] = format!("{} is {} (its place)", var.dims[d], role.letter());
    }
    let find = |role: Role| roles.iter().position(|r| *r == Some(role)).unwrap_or(0);
    let spatial = [find(Role::X), find(Role::Y), find(Role::Z)];
    // The other dimensions: at most one longer than 1, the frames.
    let long: Vec<usize> = (0..var.dims.len())
        .filter(|d| !spatial.contains(d) && var.shape[*d] > 1)
        .collect();
    let frame_dim = match long.as_slice() {
        [] => None,
        [d] => Some(*d),
        _ => {
            return Err(fail(format!(
                "dimensions {} are all longer than 1 besides x, y and z: volray reads one more (time, as frames)",
                long.iter()
                    .map(|&d| format!("\"{}\" ({})", var.dims[d], var.shape[d]))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
    };
    let frames = frame_dim.map_or(1, |d| var.shape[d]);
    let frames = usize::try_from(frames)
        .map_err(|_| fail(format!("{frames} frames: more than this machine addresses")))?;
    let frame = frame.unwrap_or(0);
    if frame >= frames {
        let held = match frame_dim {
            Some(d) => format!(
                "variable {} holds {frames} volume(s) along \"{}\", numbered from 0",
                var.name, var.dims[d]
            ),
            None => format!("variable {} holds one volume", var.name),
        };
        return Err(IoError::frame_out_of_range(path, frame, held));
    }
    if let Some(d) = frame_dim {
        reasons.retain(|r| !r.is_empty());
        if !reasons
            .iter()
            .any(|r| r.starts_with(&format!("{} ", var.dims[d])))
        {
            reasons.push(format!("{} holds the frames", var.dims[d]));
        }
    }
    reasons.retain(|r| !r.is_empty());
    Ok(Layout {
        spatial,
        frame_dim,
        frames,
        frame,
        reasons,
    })
}

/// The variables [`choose`] picks from: not coordinate variables, with
/// three spatial dimensions or more beside a time dimension.
fn candidates(vars: &[Variable]) -> Vec<&Variable> {
    vars.iter()
        .filter(|v| {
            if v.is_coordinate() {
                return false;
            }
            let non_time = v
                .dims
                .iter()
                .filter(|d| !matches!(role_of(d, coordinate(vars, d)), Some((Role::Time, _))))
                .count();
            non_time >= 3
        })
        .collect()
}

/// The data variable to read: `wanted` (the `--array` option) if given,
/// else the only candidate (a non-coordinate variable of three spatial
/// dimensions or more); refused listing the candidates otherwise.
pub(crate) fn choose<'a>(
    path: &Path,
    vars: &'a [Variable],
    wanted: Option<&str>,
) -> Result<&'a Variable, IoError> {
    let found = candidates(vars);
    let names = |vs: &[&Variable]| {
        vs.iter()
            .map(|v| format!("{}({})", v.name, v.dims.join(", ")))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(name) = wanted {
        return vars.iter().find(|v| v.name == name).ok_or_else(|| {
            IoError::no_such_array(
                path,
                name,
                if found.is_empty() {
                    "no variable of three dimensions or more".to_string()
                } else {
                    format!("variables {}", names(&found))
                },
            )
        });
    }
    match found.as_slice() {
        [one] => Ok(one),
        [] => Err(IoError::invalid(
            path,
            format!(
                "no variable of three spatial dimensions: the file holds {}",
                if vars.is_empty() {
                    "no variables".to_string()
                } else {
                    vars.iter()
                        .map(|v| format!("{}({})", v.name, v.dims.join(", ")))
                        .collect::<Vec<_>>()
                        .join(", ")
                }
            ),
        )),
        several => Err(IoError::invalid(
            path,
            format!(
                "{} variables hold volumes, {}: name one with --array",
                several.len(),
                names(several)
            ),
        )),
    }
}

/// A grid placed in the world: what `grid_to_volume` takes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Placement {
    /// Samples along index axes 0, 1, 2 of the slab (fastest first).
    pub dims: [usize; 3],
    /// The world step along each index axis (negative along a decreasing
    /// coordinate).
    pub steps: [DVec3; 3],
    /// The world position of the slab's first sample.
    pub origin: DVec3,
    /// The unit of spacing and origin, where all three axes have one.
    pub length_unit: Option<String>,
    /// Each world axis's name and unit where they are kept apart
    /// ([`FileInfo::axis_units`](crate::FileInfo)).
    pub axis_units: Option<[crate::AxisUnitName; 3]>,
}

/// Places the slab of `var` that `layout` reads: spacing, origin and unit
/// from the coordinate variables (see the module doc), whose values
/// `values` reads (already unpacked by the container, or through
/// [`Packing`]). Notes go to `info`.
pub(crate) fn place(
    path: &Path,
    var: &Variable,
    vars: &[Variable],
    layout: &Layout,
    values: &mut dyn FnMut(&Variable) -> Result<Vec<f64>, IoError>,
    info: &mut FileInfo,
) -> Result<Placement, IoError> {
    // Per spatial role x, y, z: (start, step, unit).
    let mut axes: Vec<(f64, f64, Option<String>)> = Vec::new();
    let mut described = Vec::new();
    let mut down = Vec::new();
    for (role, &d) in ["x", "y", "z"].iter().zip(&layout.spatial) {
        let dim = &var.dims[d];
        let n = var.shape[d];
        let Some(c) = coordinate(vars, dim) else {
            described.push(format!(
                "{role} ({dim}): no coordinate variable, spacing 1 from 0"
            ));
            axes.push((0.0, 1.0, None));
            continue;
        };
        let v = values(c)?;
        if v.len() as u64 != n {
            return Err(IoError::invalid(
                path,
                format!(
                    "coordinate variable {dim} holds {} values for dimension {dim} of length {n}",
                    v.len()
                ),
            ));
        }
        let (start, step) = even_spacing(&v).map_err(|why| {
            IoError::invalid(
                path,
                format!("coordinate variable {dim} ({role} axis) {why}: volray reads evenly spaced grids"),
            )
        })?;
        let unit = c
            .text("units")
            .filter(|u| !u.is_empty())
            .map(str::to_string);
        described.push(format!(
            "{role} ({dim}): start {start} step {step}{}",
            unit.as_ref().map(|u| format!(" {u}")).unwrap_or_default()
        ));
        if *role == "z"
            && let Some(why) = points_down(c)
        {
            let (low, high) = (
                start.min(start + step * (n - 1) as f64),
                start.max(start + step * (n - 1) as f64),
            );
            down.push(format!(
                "z ({dim}) points down ({why}): placed at z = −{dim}, so that up in the world is up in the atmosphere or ocean ({dim} {high} lowest, {low} highest)"
            ));
            // 0 − v: depth 0 is z = 0, not −0.
            axes.push((0.0 - start, 0.0 - step, unit));
        } else {
            axes.push((start, step, unit));
        }
    }
    info.notes.push(format!(
        "CF axes of {}: {}; geometry from the coordinate variables: {}",
        var.name,
        layout.reasons.join(", "),
        described.join("; ")
    ));

    info.notes.extend(down);

    // One length unit: the finest; other units kept apart (units.rs).
    let names: Vec<String> = layout
        .spatial
        .iter()
        .zip(["x", "y", "z"])
        .map(|(&d, role)| format!("{role} ({})", var.dims[d]))
        .collect();
    let axis_units: Vec<AxisUnit> = axes
        .iter()
        .zip(&names)
        .map(|(a, name)| AxisUnit {
            name,
            unit: a.2.as_deref(),
        })
        .collect();
    let one = one_length_unit(&axis_units);
    for (a, f) in one.factors.iter().enumerate() {
        axes[a].0 *= f;
        axes[a].1 *= f;
    }
    info.notes.extend(one.notes);
    let length_unit_name = one.length_unit;
    // Named by the coordinate's dimension, for the display scale's note.
    let axis_units = (one.apart.len() == 3).then(|| {
        std::array::from_fn(|a| crate::AxisUnitName {
            name: var.dims[layout.spatial[a]].clone(),
            unit: one.apart[a].clone(),
        })
    });

    let world = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut origin = DVec3::ZERO;
    for (a, (start, _, _)) in axes.iter().enumerate() {
        origin += world[a] * *start;
    }
    let order = layout.fastest_first();
    let mut dims = [0usize; 3];
    let mut steps = [DVec3::ZERO; 3];
    for (k, &d) in order.iter().enumerate() {
        let role = layout.spatial.iter().position(|&s| s == d).unwrap_or(0);
        dims[k] = usize::try_from(var.shape[d]).map_err(|_| {
            IoError::invalid(
                path,
                format!("dimension {} of length {}", var.dims[d], var.shape[d]),
            )
        })?;
        steps[k] = world[role] * axes[role].1;
    }
    Ok(Placement {
        dims,
        steps,
        origin,
        length_unit: length_unit_name,
        axis_units,
    })
}

/// Why the vertical coordinate `c` grows downward, if it does (CF §4.3):
/// its `positive` attribute is `"down"`; or, without one, it is a
/// pressure (`standard_name = "air_pressure"`, or units of pressure,
/// which CF lets stand without `positive`) or a depth (`standard_name =
/// "depth"`, positive down by its definition in the standard name
/// table). `positive = "up"` is taken at its word.
pub(crate) fn points_down(c: &Variable) -> Option<String> {
    match c.text("positive").map(str::to_ascii_lowercase).as_deref() {
        Some("down") => return Some("positive = \"down\"".into()),
        Some("up") => return None,
        _ => {}
    }
    if let Some(name) = c.text("standard_name")
        && matches!(name, "air_pressure" | "depth")
    {
        return Some(format!("standard_name = \"{name}\""));
    }
    let unit = c.text("units").filter(|u| is_pressure(u))?;
    Some(format!("units = \"{unit}\", a pressure"))
}

/// The first value and the step of evenly spaced `values` (within
/// [`EVEN_TOLERANCE`] of the step), or why they are not.
pub(crate) fn even_spacing(values: &[f64]) -> Result<(f64, f64), String> {
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!("value {i} is {}", values[i]));
    }
    let Some((&first, &last)) = values.first().zip(values.last()) else {
        return Err("is empty".into());
    };
    if values.len() == 1 {
        return Ok((first, 1.0));
    }
    let step = (last - first) / (values.len() - 1) as f64;
    if step == 0.0 || !step.is_finite() {
        return Err(format!("runs from {first} to {last}, not a step"));
    }
    for (i, &v) in values.iter().enumerate() {
        let want = first + step * i as f64;
        if (v - want).abs() > EVEN_TOLERANCE * step.abs() {
            return Err(format!(
                "is unevenly spaced: value {i} is {v}, {want} at the mean step {step} (tolerance {} % of the step)",
                EVEN_TOLERANCE * 100.0
            ));
        }
    }
    Ok((first, step))
}

/// Stored values to real ones (CF §2.5.1 and §8.1).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Packing {
    pub scale: f64,
    pub offset: f64,
    /// `_FillValue` and `missing_value`: stored values that are no data.
    pub missing: Vec<f64>,
    /// The valid stored range (`valid_range`, else `valid_min` and
    /// `valid_max`); outside it, no data.
    pub lo: Option<f64>,
    pub hi: Option<f64>,
}

impl Packing {
    /// The packing `var`'s attributes describe.
    pub(crate) fn of(path: &Path, var: &Variable) -> Result<Packing, IoError> {
        let fail =
            |what: &str| IoError::invalid(path, format!("variable {}: attribute {what}", var.name));
        let one = |name: &str| -> Result<Option<f64>, IoError> {
            match (var.attr(name), var.numbers(name)) {
                (None, _) => Ok(None),
                (_, Some([v])) => Ok(Some(*v)),
                _ => Err(fail(&format!("{name} is not one number"))),
            }
        };
        let scale = one("scale_factor")?.unwrap_or(1.0);
        let offset = one("add_offset")?.unwrap_or(0.0);
        if !scale.is_finite() || !offset.is_finite() {
            return Err(fail(&format!(
                "scale_factor {scale} or add_offset {offset} is not finite"
            )));
        }
        let mut missing = Vec::new();
        for name in ["_FillValue", "missing_value"] {
            match var.attr(name) {
                None => {}
                Some(Value::Numbers(v)) => missing.extend(v.iter().copied()),
                Some(Value::Text(_)) => return Err(fail(&format!("{name} is text"))),
            }
        }
        let (mut lo, mut hi) = (one("valid_min")?, one("valid_max")?);
        match var.attr("valid_range") {
            None => {}
            Some(Value::Numbers(v)) if v.len() == 2 => {
                lo = Some(v[0]);
                hi = Some(v[1]);
            }
            Some(_) => return Err(fail("valid_range is not two numbers")),
        }
        Ok(Packing {
            scale,
            offset,
            missing,
            lo,
            hi,
        })
    }

    /// Whether every stored value is its real value.
    pub(crate) fn is_identity(&self) -> bool {
        self.scale == 1.0
            && self.offset == 0.0
            && self.missing.is_empty()
            && self.lo.is_none()
            && self.hi.is_none()
    }

    /// The real value of stored value `v`: NaN where it is missing or
    /// outside the valid range.
    pub(crate) fn real(&self, v: f64) -> f64 {
        if v.is_nan()
            || self.missing.contains(&v)
            || self.lo.is_some_and(|lo| v < lo)
            || self.hi.is_some_and(|hi| v > hi)
        {
            return f64::NAN;
        }
        v * self.scale + self.offset
    }

    /// A note saying what was done, for `volray info`.
    pub(crate) fn note(&self, var: &str) -> Option<String> {
        if self.is_identity() {
            return None;
        }
        let mut parts = Vec::new();
        if self.scale != 1.0 || self.offset != 0.0 {
            parts.push(format!(
                "real = stored · {} + {} (scale_factor, add_offset)",
                self.scale, self.offset
            ));
        }
        if !self.missing.is_empty() {
            parts.push(format!(
                "stored {} (_FillValue/missing_value) read as NaN, empty space",
                self.missing
                    .iter()
                    .map(f64::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        if self.lo.is_some() || self.hi.is_some() {
            parts.push(format!(
                "stored values outside [{}, {}] (valid range) read as NaN",
                self.lo.map_or("-inf".into(), |v| v.to_string()),
                self.hi.map_or("inf".into(), |v| v.to_string())
            ));
        }
        Some(format!("{var}: {}", parts.join("; ")))
    }
}

/// Fills `info` for `volray info`: the dimensions (`dims` as `(name,
/// length, is the record/unlimited dimension)`), the global attributes,
/// every variable with its dimensions, the chosen variable's attributes;
/// the candidates as [`FileInfo::arrays`], the chosen one as
/// [`FileInfo::array`]; the frames.
pub(crate) fn describe(
    dims: &[(String, u64, bool)],
    globals: &[(String, Value)],
    vars: &[Variable],
    var: &Variable,
    layout: &Layout,
    info: &mut FileInfo,
) {
    info.header.push((
        "dimensions".into(),
        dims.iter()
            .map(|(n, len, unlimited)| {
                if *unlimited {
                    format!("{n} = {len} (unlimited)")
                } else {
                    format!("{n} = {len}")
                }
            })
            .collect::<Vec<_>>()
            .join(", "),
    ));
    for (k, v) in globals {
        info.header.push((format!(":{k}"), v.shown()));
    }
    for v in vars {
        let units = v
            .text("units")
            .map(|u| format!(" [{u}]"))
            .unwrap_or_default();
        info.header.push((
            format!("variable {}", v.name),
            format!("{} ({}){units}", v.type_name, v.dims.join(", ")),
        ));
    }
    for (k, value) in &var.attrs {
        info.header
            .push((format!("{}:{k}", var.name), value.shown()));
    }
    info.arrays = candidates(vars).iter().map(|v| v.name.clone()).collect();
    info.array = Some(var.name.clone());
    info.frames = layout.frames;
    info.frame = layout.frame;
    if let Some(d) = layout.frame_dim {
        info.notes.push(format!(
            "volume {} of {} read along \"{}\"",
            layout.frame, layout.frames, var.dims[d]
        ));
    }
}

#[cfg(test)]
#[path = "cf_tests.rs"]
mod tests;
