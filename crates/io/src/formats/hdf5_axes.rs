//! Which axis of an HDF5 dataset is x, y, z, time or channel: the names a
//! dataset gives its axes, and where each of its samples lands in the
//! volume. Used by the eager reader (`hdf5.rs`) and the box-by-box reader
//! (`hdf5_lazy.rs`), so that both read a dataset the same way round.
//!
//! The names are looked for in this order, the first found giving the
//! order (`volray info` says which):
//! 1. an `axes` attribute, one letter per dataset axis, slowest first
//!    (`"zyx"`, `"tzyx"`, `"zyxc"`; the OME-NGFF / vigra / Fiji habit), or
//!    an array of one name per axis;
//! 2. ilastik's `axistags` attribute, JSON `{"axes": [{"key": "z", ...},
//!    ...]}`, the keys in dataset axis order;
//! 3. `DIMENSION_LABELS` (h5py's `dset.dims[i].label`, HDF5's `H5DSset_label`),
//!    an array of variable-length strings, one per axis, none empty;
//! 4. dimension scales, as netCDF-C writes them (NetCDF-4 files): the
//!    dataset's `_Netcdf4Coordinates` attribute (one dimension id per axis)
//!    and the scale datasets of its group and the groups above carrying
//!    `_Netcdf4Dimid` (their link names are the dimension names).
//!
//! What `hdf5-pure` 0.47 cannot read: attributes holding object references.
//! `DIMENSION_LIST` (a variable-length array of object references, which
//! is how HDF5's dimension-scale API attaches a scale to an axis) and a
//! scale's `REFERENCE_LIST` (compound of a reference and an index) are
//! left out of `Dataset::attrs()`, so a scale attached with h5py's
//! `dims[i].attach_scale` and no netCDF attribute cannot be followed to
//! its `NAME`; such a dataset keeps the default order and `volray info`
//! says that its `DIMENSION_LIST` was not followed. Fixed and
//! variable-length strings and arrays of them, UTF-8 or ASCII, are read.
//!
//! Names `x`, `y`, `z`, `t`, `c` (any case; also `time`, `channel`) name
//! the axes directly. Other names go by the CF conventions' rule for
//! dimension names (`shared/cf.rs`, NetCDF's: `lon`, `lat`, `depth`,
//! `level`, `time`...; the names it does not know spatial from the last
//! backwards) where that rule names one spatial axis at least; a dataset
//! whose names it cannot read keeps the default order, with a note. Without names, the default: `a[x, y]` (an
//! image), `a[x, y, z]`, `a[t, x, y, z]`, the first axis being x; existing
//! files read as they always have.
//!
//! The time axis holds the time points (`--frame`) and the channel axis
//! the channels (`--channel`), kept apart as everywhere in volray
//! ([`Volumes`]: [`volumes`] counts them, [`frame_of`] finds the volume
//! of a time point and channel); inside the dataset the volumes lie in C
//! order over those axes as it holds them, so `a[c, t, z, y, x]` reads
//! as well as `a[t, c, z, y, x]`.

use std::path::Path;

use hdf5_pure::{AttrValue, Dataset, File};

use crate::shared::cf;
use crate::shared::hdf5::text;
use crate::{Picked, Volumes};

/// What one dataset axis holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    X,
    Y,
    Z,
    Time,
    Channel,
}

impl Role {
    fn of(name: &str) -> Option<Role> {
        Some(match name.trim().to_ascii_lowercase().as_str() {
            "x" => Role::X,
            "y" => Role::Y,
            "z" => Role::Z,
            "t" | "time" => Role::Time,
            "c" | "channel" | "channels" => Role::Channel,
            _ => return None,
        })
    }

    /// The volume axis (0, 1, 2) of a spatial role.
    fn spatial(self) -> Option<usize> {
        match self {
            Role::X => Some(0),
            Role::Y => Some(1),
            Role::Z => Some(2),
            _ => None,
        }
    }

    fn letter(self) -> char {
        match self {
            Role::X => 'x',
            Role::Y => 'y',
            Role::Z => 'z',
            Role::Time => 't',
            Role::Channel => 'c',
        }
    }
}

/// The roles of a dataset's axes and where they came from.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AxisOrder {
    pub roles: Vec<Role>,
    /// `"attribute axes"`, `"the default a[x, y, z]"`, ...
    pub source: String,
    /// Why a name found was not used, if one was not.
    pub ignored: Option<String>,
}

impl AxisOrder {
    /// `a[z, y, x]`.
    pub fn shown(&self) -> String {
        let letters: Vec<String> = self.roles.iter().map(|r| r.letter().to_string()).collect();
        format!("a[{}]", letters.join(", "))
    }

    /// Whether this is the default order for its rank (the names, if
    /// any, said what the default says).
    pub fn is_default(&self) -> bool {
        default_roles(self.roles.len()).as_deref() == Some(&self.roles[..])
    }
}

/// The default roles of a dataset of `rank` axes without names.
fn default_roles(rank: usize) -> Option<Vec<Role>> {
    use Role::*;
    Some(match rank {
        2 => vec![X, Y],
        3 => vec![X, Y, Z],
        4 => vec![Time, X, Y, Z],
        _ => return None,
    })
}

/// The axis order of `dataset` (of `rank` axes, attributes `attrs`, at
/// `name` in `file`): from its names, or the default. An error for names
/// that are axis letters but do not make an order (a letter twice, no x
/// or y, one per axis missing) and for a rank with no default.
pub(crate) fn axis_order(
    file: &File,
    name: &str,
    attrs: &[(String, AttrValue)],
    dataset: &Dataset,
    shape: &[usize],
) -> Result<AxisOrder, String> {
    let rank = shape.len();
    let attr = |n: &str| attrs.iter().find(|(k, _)| k == n).map(|(_, v)| v);
    let mut found: Vec<(String, Vec<String>)> = Vec::new();
    if let Some(v) = attr("axes") {
        found.push(("attribute axes".into(), names_of(v).unwrap_or_default()));
    }
    if let Some(v) = attr("axistags") {
        found.push((
            "attribute axistags".into(),
            text(v).and_then(|t| axistags(&t)).unwrap_or_default(),
        ));
    }
    if let Some(v) = attr("DIMENSION_LABELS") {
        found.push((
            "attribute DIMENSION_LABELS".into(),
            names_of(v).unwrap_or_default(),
        ));
    }
    if let Some(v) = attr("_Netcdf4Coordinates") {
        found.push((
            "dimension scales (_Netcdf4Coordinates)".into(),
            netcdf_dimensions(file, name, v).unwrap_or_default(),
        ));
    }
    let mut ignored = Vec::new();
    for (source, names) in found {
        if names.is_empty() || names.iter().all(|n| n.is_empty()) {
            ignored.push(format!("{source} holds no axis names"));
            continue;
        }
        if names.len() != rank {
            return Err(format!(
                "{source} names {} axes ({}), but the dataset has {rank}",
                names.len(),
                names.join(", ")
            ));
        }
        let roles: Option<Vec<Role>> = names.iter().map(|n| Role::of(n)).collect();
        let Some(roles) = roles else {
            if let Some((roles, why)) = cf_roles(&names, shape) {
                return Ok(AxisOrder {
                    roles,
                    source: format!("{source} read by the CF conventions ({why})"),
                    ignored: (!ignored.is_empty()).then(|| ignored.join("; ")),
                });
            }
            ignored.push(format!(
                "{source} names axes {} that are not x, y, z, t, c, nor CF names",
                names.join(", ")
            ));
            continue;
        };
        check_roles(&roles).map_err(|e| format!("{source} ({}): {e}", names.join(", ")))?;
        return Ok(AxisOrder {
            roles,
            source,
            ignored: (!ignored.is_empty()).then(|| ignored.join("; ")),
        });
    }
    if dataset
        .attr_datatypes()
        .is_ok_and(|t| t.contains_key("DIMENSION_LIST"))
    {
        ignored.push(
            "attached dimension scales (DIMENSION_LIST) not followed: hdf5-pure 0.47 cannot read object references".into(),
        );
    }
    let roles = default_roles(rank).ok_or_else(|| {
        format!(
            "{rank} dimension(s) and no axis names: volray reads 3-D datasets a[x, y, z] and 4-D series a[t, x, y, z], or datasets whose axes are named (an axes attribute such as \"tczyx\")"
        )
    })?;
    Ok(AxisOrder {
        source: format!(
            "the default {} (no axis names)",
            AxisOrder {
                roles: roles.clone(),
                source: String::new(),
                ignored: None
            }
            .shown()
        ),
        roles,
        ignored: (!ignored.is_empty()).then(|| ignored.join("; ")),
    })
}

/// The roles CF's rule for dimension names (`shared/cf.rs`: `lon`,
/// `latitude`, `depth`, `level`, `time`, ...) gives axes named `names`,
/// the unnamed ones spatial from the last backwards, and why; `None`
/// where it names no spatial axis itself or finds no order (two names for
/// x, two long axes beside x, y, z).
fn cf_roles(names: &[String], shape: &[usize]) -> Option<(Vec<Role>, String)> {
    let var = cf::Variable {
        name: String::new(),
        dims: names.to_vec(),
        shape: shape.iter().map(|&n| n as u64).collect(),
        attrs: Vec::new(),
        type_name: String::new(),
        integer: false,
    };
    let layout = cf::layout(Path::new(""), &var, std::slice::from_ref(&var), None).ok()?;
    let by_place = layout
        .reasons
        .iter()
        .filter(|r| r.ends_with("(its place)"))
        .count();
    if by_place >= 3 {
        return None;
    }
    let roles = (0..names.len())
        .map(|d| match layout.spatial.iter().position(|&s| s == d) {
            Some(0) => Role::X,
            Some(1) => Role::Y,
            Some(_) => Role::Z,
            None if Some(d) == layout.frame_dim => Role::Time,
            // One sample long: held at 0.
            None => Role::Channel,
        })
        .collect();
    Some((roles, layout.reasons.join(", ")))
}

/// Each role at most once; x and y present.
fn check_roles(roles: &[Role]) -> Result<(), String> {
    for (i, r) in roles.iter().enumerate() {
        if roles[..i].contains(r) {
            return Err(format!("axis {} is named twice", r.letter()));
        }
    }
    for need in [Role::X, Role::Y] {
        if !roles.contains(&need) {
            return Err(format!("no axis is {}", need.letter()));
        }
    }
    Ok(())
}

/// Axis names from a string attribute: one name per element of a string
/// array, or one letter per axis of a single string.
fn names_of(value: &AttrValue) -> Option<Vec<String>> {
    use AttrValue as A;
    match value {
        A::StringArray(v)
        | A::AsciiStringArray(v)
        | A::VarLenStringArray(v)
        | A::VarLenAsciiStringArray(v)
        | A::VarLenAsciiCharArray(v)
        | A::StringArraySized { values: v, .. }
        | A::AsciiStringArraySized { values: v, .. }
            if v.len() > 1 =>
        {
            Some(
                v.iter()
                    .map(|s| s.trim_end_matches('\0').trim().to_string())
                    .collect(),
            )
        }
        _ => {
            let s = text(value)?;
            let s = s.trim();
            if !s.chars().all(|c| c.is_ascii_alphabetic()) {
                return None;
            }
            Some(s.chars().map(|c| c.to_string()).collect())
        }
    }
}

/// The keys of ilastik's / vigra's `axistags` JSON, in order.
fn axistags(json: &str) -> Option<Vec<String>> {
    let v: serde_json::Value = serde_json::from_str(json).ok()?;
    v.get("axes")?
        .as_array()?
        .iter()
        .map(|a| a.get("key")?.as_str().map(str::to_string))
        .collect()
}

/// The dimension names of a netCDF-C variable at `name`: its
/// `_Netcdf4Coordinates` dimension ids, each looked up among the
/// dimension scales (`CLASS` "DIMENSION_SCALE") with `_Netcdf4Dimid` in
/// its group and the groups above.
pub(crate) fn netcdf_dimensions(file: &File, name: &str, ids: &AttrValue) -> Option<Vec<String>> {
    let ids = crate::shared::hdf5::numbers(ids)?;
    let mut groups: Vec<&str> = Vec::new();
    let mut path = name.trim_end_matches('/');
    while let Some(at) = path.rfind('/') {
        path = &path[..at];
        groups.push(if path.is_empty() { "/" } else { path });
    }
    let mut dims: Vec<(f64, String)> = Vec::new();
    for g in groups {
        let Ok(group) = file.group(g) else { continue };
        for ds in group
            .datasets()
            .unwrap_or_default()
            .into_iter()
            .take(10_000)
        {
            let Ok(d) = group.dataset(&ds) else { continue };
            let Ok(attrs) = d.attrs() else { continue };
            // A scale: h5netcdf gives its variables a _Netcdf4Dimid too.
            if attrs.get("CLASS").and_then(text).as_deref() != Some("DIMENSION_SCALE") {
                continue;
            }
            if let Some(id) = attrs
                .get("_Netcdf4Dimid")
                .and_then(crate::shared::hdf5::numbers)
                .and_then(|v| v.first().copied())
                && !dims.iter().any(|(i, _)| *i == id)
            {
                dims.push((id, ds));
            }
        }
    }
    ids.iter()
        .map(|id| dims.iter().find(|(i, _)| i == id).map(|(_, n)| n.clone()))
        .collect()
}

/// The time points and channels of a dataset of `shape` whose axes are
/// `roles`: the extent of its time axis and the product of its channel
/// axes' (1 where it has none).
pub(crate) fn volumes(shape: &[usize], roles: &[Role]) -> Volumes {
    let extent = |role: Role| {
        (roles.iter().zip(shape))
            .filter(|(r, _)| **r == role)
            .fold(1usize, |p, (_, &n)| p.saturating_mul(n))
    };
    Volumes::new(extent(Role::Time), extent(Role::Channel))
}

/// The number [`Placement::new`] takes (C order over the non-spatial
/// axes, as the dataset holds them) of time point and channel `picked`
/// of a dataset of `shape` whose axes are `roles`; several channel axes
/// (CF's axes one sample long) number the channels in C order.
pub(crate) fn frame_of(shape: &[usize], roles: &[Role], picked: Picked) -> usize {
    let mut index = vec![0usize; shape.len()];
    let mut channel = picked.channel;
    for a in (0..shape.len()).rev() {
        match roles[a] {
            Role::Time => index[a] = picked.time_point,
            Role::Channel => {
                let n = shape[a].max(1);
                index[a] = channel % n;
                channel /= n;
            }
            _ => {}
        }
    }
    (0..shape.len())
        .filter(|&a| roles[a].spatial().is_none())
        .fold(0, |f, a| f * shape[a].max(1) + index[a])
}

/// A dataset named (or found) and checked, its metadata read, nothing of
/// its samples: what the eager reader (`hdf5.rs`'s `read_opened`) and
/// the lazy source (`hdf5_lazy.rs`) both start from, kept here beside
/// its [`Placement`] so that neither imports the other for it.
pub(crate) struct Opened {
    /// The HDF5 file's own path (without `:/dataset`).
    pub file_path: std::path::PathBuf,
    pub h5: crate::shared::hdf5::H5File,
    /// The dataset's absolute path in the file.
    pub name: String,
    pub dataset: Dataset,
    pub sample: crate::shared::hdf5::NumericType,
    pub shape: Vec<usize>,
    /// Which dataset axis is x, y, z, and the volume read (the frame).
    pub placement: Placement,
    /// Samples along x, y, z (a 2-D image: z is 1).
    pub dims: [usize; 3],
    pub info: crate::FileInfo,
    pub spacing: volray_core::glam::DVec3,
    pub origin: volray_core::glam::DVec3,
}

impl Opened {
    /// The grid's steps along x, y, z: the spacing along the world axes.
    pub(crate) fn axis_steps(&self) -> [volray_core::glam::DVec3; 3] {
        use volray_core::glam::DVec3;
        [
            DVec3::X * self.spacing.x,
            DVec3::Y * self.spacing.y,
            DVec3::Z * self.spacing.z,
        ]
    }
}

/// Where each sample of a dataset lands: which dataset axis is x, y, z,
/// and at which index the other axes (time, channel) are held for the
/// volume read.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Placement {
    pub shape: Vec<usize>,
    pub roles: Vec<Role>,
    /// The dataset axis of x, y, z (`None`: z of a 2-D image).
    pub spatial: [Option<usize>; 3],
    /// Per dataset axis: the index held (time, channel), or `None` for a
    /// spatial axis.
    pub fixed: Vec<Option<usize>>,
    /// Samples along x, y, z.
    pub dims: [usize; 3],
    /// Volumes (the product of the time and channel extents) and the one
    /// read.
    pub frames: usize,
    pub frame: usize,
}

impl Placement {
    /// The placement of volume `frame` of a dataset of `shape` whose axes
    /// are `roles` (one per axis); `Err(frames)` for a frame past the
    /// last.
    pub fn new(shape: &[usize], roles: &[Role], frame: usize) -> Result<Placement, usize> {
        let mut spatial = [None; 3];
        for (a, r) in roles.iter().enumerate() {
            if let Some(v) = r.spatial() {
                spatial[v] = Some(a);
            }
        }
        let dims = spatial.map(|a| a.map_or(1, |a| shape[a]));
        let frames = roles
            .iter()
            .zip(shape)
            .filter(|(r, _)| r.spatial().is_none())
            .fold(1usize, |f, (_, &n)| f.saturating_mul(n));
        if frame >= frames {
            return Err(frames);
        }
        // Frame f in C order over the non-spatial axes.
        let mut fixed = vec![None; shape.len()];
        let mut rest = frame;
        for a in (0..shape.len()).rev() {
            if roles[a].spatial().is_none() {
                let n = shape[a].max(1);
                fixed[a] = Some(rest % n);
                rest /= n;
            }
        }
        Ok(Placement {
            shape: shape.to_vec(),
            roles: roles.to_vec(),
            spatial,
            fixed,
            dims,
            frames,
            frame,
        })
    }

    /// The index held along the first dataset axis, if it is not spatial
    /// (the row of a series read whole).
    pub fn first_fixed(&self) -> Option<usize> {
        self.fixed.first().copied().flatten()
    }

    /// The strides, per dataset axis, of a buffer of dims `dims` (x
    /// fastest) that the dataset's spatial axes step through; 0 for the
    /// others.
    pub fn strides(&self, dims: [usize; 3]) -> Vec<usize> {
        let step = [1, dims[0], dims[0] * dims[1]];
        self.roles
            .iter()
            .map(|r| r.spatial().map_or(0, |v| step[v]))
            .collect()
    }

    /// The dataset's box (per axis, `lo..hi`) that holds the volume's box
    /// `lo..hi` (x, y, z) of the frame read.
    pub fn dataset_box(&self, lo: [usize; 3], hi: [usize; 3]) -> (Vec<usize>, Vec<usize>) {
        self.roles
            .iter()
            .zip(&self.fixed)
            .map(|(r, f)| match (r.spatial(), f) {
                (Some(v), _) => (lo[v], hi[v]),
                (None, Some(i)) => (*i, i + 1),
                (None, None) => (0, 1),
            })
            .unzip()
    }

    /// Places C-order samples of the dataset, the first at dataset index
    /// `start` (flat), into the x-fastest volume buffer through `put(at,
    /// value)`, skipping those of other frames.
    pub fn place(&self, start: usize, values: &[f64], mut put: impl FnMut(usize, f64)) {
        let n = self.shape.len();
        let strides = self.strides(self.dims);
        let mut idx = vec![0usize; n];
        let mut rest = start;
        for a in (0..n).rev() {
            let k = self.shape[a].max(1);
            idx[a] = rest % k;
            rest /= k;
        }
        for &v in values {
            if self
                .fixed
                .iter()
                .zip(&idx)
                .all(|(f, &i)| f.is_none_or(|f| f == i))
            {
                let at: usize = idx.iter().zip(&strides).map(|(&i, &s)| i * s).sum();
                put(at, v);
            }
            for a in (0..n).rev() {
                idx[a] += 1;
                if idx[a] < self.shape[a] {
                    break;
                }
                idx[a] = 0;
            }
        }
    }
}

/// Calls `f` with every index of the box `lo..hi` over its first
/// `lo.len()` axes, in C order (once, with an empty index, for none).
pub(crate) fn each_index<E>(
    lo: &[usize],
    hi: &[usize],
    mut f: impl FnMut(&[usize]) -> Result<(), E>,
) -> Result<(), E> {
    if lo.iter().zip(hi).any(|(l, h)| l >= h) {
        return Ok(());
    }
    let mut idx = lo.to_vec();
    loop {
        f(&idx)?;
        let mut a = idx.len();
        loop {
            if a == 0 {
                return Ok(());
            }
            a -= 1;
            idx[a] += 1;
            if idx[a] < hi[a] {
                break;
            }
            idx[a] = lo[a];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Role::*;

    #[test]
    fn time_points_and_channels_are_found_in_either_order() {
        let picked = |t, c| Picked {
            time_point: t,
            channel: c,
        };
        // a[t, c, z, y, x] of 2 times and 3 channels.
        let (shape, roles) = ([2, 3, 4, 5, 6], [Time, Channel, Z, Y, X]);
        assert_eq!(volumes(&shape, &roles), Volumes::new(2, 3));
        let p = Placement::new(&shape, &roles, frame_of(&shape, &roles, picked(1, 2))).unwrap();
        assert_eq!(p.fixed[..2], [Some(1), Some(2)]);
        // a[c, t, z, y, x]: the same volume, the dataset's order.
        let (shape, roles) = ([3, 2, 4, 5, 6], [Channel, Time, Z, Y, X]);
        assert_eq!(volumes(&shape, &roles), Volumes::new(2, 3));
        let p = Placement::new(&shape, &roles, frame_of(&shape, &roles, picked(1, 2))).unwrap();
        assert_eq!(p.fixed[..2], [Some(2), Some(1)]);
        // a[z, y, x, c] and no time.
        let (shape, roles) = ([2, 2, 3, 4], [Z, Y, X, Channel]);
        assert_eq!(volumes(&shape, &roles), Volumes::new(1, 4));
        assert_eq!(frame_of(&shape, &roles, picked(0, 3)), 3);
    }

    #[test]
    fn frames_number_time_and_channel_in_the_datasets_order() {
        // a[t, c, z, y, x] of 2 times and 3 channels: frame 4 is t 1, c 1.
        let p = Placement::new(&[2, 3, 4, 5, 6], &[Time, Channel, Z, Y, X], 4).unwrap();
        assert_eq!(p.frames, 6);
        assert_eq!(p.fixed, vec![Some(1), Some(1), None, None, None]);
        assert_eq!(p.dims, [6, 5, 4]);
        assert_eq!(p.spatial, [Some(4), Some(3), Some(2)]);
        assert_eq!(
            Placement::new(&[2, 3, 4, 5, 6], &[Time, Channel, Z, Y, X], 6),
            Err(6)
        );
    }

    #[test]
    fn samples_of_a_zyxc_dataset_land_at_x_fastest_places_of_their_channel() {
        // a[z, y, x, c] of shape (2, 2, 3, 2), channel 1.
        let p = Placement::new(&[2, 2, 3, 2], &[Z, Y, X, Channel], 1).unwrap();
        let values: Vec<f64> = (0..24).map(f64::from).collect();
        let mut out = [-1.0; 12];
        p.place(0, &values, |at, v| out[at] = v);
        // Volume (x, y, z) holds file index ((z·2 + y)·3 + x)·2 + 1.
        for z in 0..2 {
            for y in 0..2 {
                for x in 0..3 {
                    assert_eq!(
                        out[x + 3 * (y + 2 * z)],
                        (((z * 2 + y) * 3 + x) * 2 + 1) as f64
                    );
                }
            }
        }
    }

    #[test]
    fn axis_names_are_letters_or_arrays_of_names() {
        assert_eq!(
            names_of(&AttrValue::VarLenString("zyx".into())),
            Some(vec!["z".into(), "y".into(), "x".into()])
        );
        assert_eq!(
            names_of(&AttrValue::VarLenAsciiStringArray(vec![
                "Z".into(),
                "y".into(),
                "x".into()
            ])),
            Some(vec!["Z".into(), "y".into(), "x".into()])
        );
        assert_eq!(names_of(&AttrValue::VarLenString("z y x".into())), None);
        assert_eq!(
            axistags(r#"{"axes": [{"key": "t"}, {"key": "x"}]}"#),
            Some(vec!["t".into(), "x".into()])
        );
        assert!(check_roles(&[Z, Y, Y]).is_err());
        assert!(check_roles(&[Z, Y, Time]).is_err());
    }

    #[test]
    fn each_index_walks_a_box_in_c_order() {
        let mut seen = Vec::new();
        each_index::<()>(&[1, 0], &[3, 2], |i| {
            seen.push(i.to_vec());
            Ok(())
        })
        .unwrap();
        assert_eq!(seen, vec![vec![1, 0], vec![1, 1], vec![2, 0], vec![2, 1]]);
        let mut once = 0;
        each_index::<()>(&[], &[], |_| {
            once += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(once, 1);
    }
}
