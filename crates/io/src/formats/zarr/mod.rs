//! Zarr arrays (v2 and v3) and OME-Zarr images (0.4 on Zarr v2, 0.5 on
//! Zarr v3), read whole into memory, one level, time point and channel
//! at a time.
//!
//! The path is a directory: an OME-Zarr image (a group whose attributes
//! hold `multiscales`, see `ome.rs`), or a bare array (`zarr.json` or
//! `.zarray`). Directories are recognised by those files (`store.rs`),
//! not by their name. The samples are read through the `zarrs` crate
//! (`chunks.rs`), which does the codecs, fill values and missing chunks;
//! what it reads is checked before it decodes or allocates for it
//! (`guard.rs`: compressed chunks that would inflate past their size,
//! shard indexes pointing outside their shard, reads past a file's end
//! or over the memory limit).
//!
//! Axes: OME-Zarr orders an image's axes time, channel, then space
//! z, y, x, each array in C order (the last index fastest), so the
//! samples of one time point and channel are volray's own layout, x
//! fastest: no transpose. A bare array is read as (z, y, x), (t, z, y,
//! x) or (t, c, z, y, x) by its number of dimensions. `ReadOptions`
//! chooses the level (`level`, 0 the finest), the time point (`frame`)
//! and the channel (`channel`); each level's `scale` and `translation`
//! give its spacing and origin.

mod chunks;
mod guard;
mod lazy;
mod ome;
mod store;
mod write;

pub(crate) use lazy::ZarrLevel;
pub(crate) use store::{is_zarr_dir, stored_bytes};
pub use write::{OmeZarrOptions, OmeZarrWritten, WrittenLevel, ZarrVersion, write_ome_zarr};

use std::path::{Path, PathBuf};

use serde_json::Value;
use zarrs::array::{ArrayMetadata, ArrayShardedExt};

use crate::shared::units::{AxisUnit, one_length_unit};
use crate::{AxisNames, FileInfo, IoError, LevelInfo, Loaded, ReadOptions, VolumeFormat, Volumes};
use chunks::{ZarrArray, ZarrType, open_array};
use ome::{Axis, AxisKind, Level};
use store::NodeKind;

/// Reads one level, time point and channel of the image or array at `path`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (level, info) = open(path, opts)?;
    let volume = level.read_whole()?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Zarr,
        info,
    })
}

/// Opens one level, time point and channel of the image or array at
/// `path` without reading a sample: the level as a source of boxes (see
/// `lazy.rs`), and what the metadata says.
pub(crate) fn open(path: &Path, opts: &ReadOptions) -> Result<(ZarrLevel, FileInfo), IoError> {
    let (image_path, held) = ome::choose_image(path, opts.array.as_deref())?;
    let path = image_path.as_path();
    let (kind, attrs) = store::node(path)?;
    let image = match kind {
        NodeKind::Array => None,
        NodeKind::Group => Some(ome::multiscale(path, &attrs)?.ok_or_else(|| {
            IoError::invalid(
                path,
                "a Zarr group without OME-Zarr \"multiscales\": give the path of an array in it",
            )
        })?),
    };
    let (axes, levels) = match &image {
        Some(m) => (m.axes.clone(), m.levels.clone()),
        None => {
            let (array, _) = open_array(path, opts.max_memory)?;
            let axes = bare_axes(path, array.dimensionality())?;
            let n = axes.len();
            let level = Level {
                path: String::new(),
                scale: vec![1.0; n],
                translation: vec![0.0; n],
            };
            (axes, vec![level])
        }
    };
    let layout = Layout::of(path, &axes)?;

    let chosen = opts.level.unwrap_or(0);
    if chosen >= levels.len() {
        return Err(IoError::invalid(
            path,
            format!(
                "level {chosen} is out of range: the image holds {} level{} (multiscales datasets), numbered from 0",
                levels.len(),
                if levels.len() == 1 { "" } else { "s" }
            ),
        ));
    }
    let mut opened = Vec::with_capacity(levels.len());
    let mut infos = Vec::with_capacity(levels.len());
    for level in &levels {
        let dir = level_dir(path, level);
        let (array, ty) = open_array(&dir, opts.max_memory)?;
        if array.dimensionality() != axes.len() {
            return Err(IoError::invalid(
                &dir,
                format!(
                    "the array has {} dimensions but the image has {} axes",
                    array.dimensionality(),
                    axes.len()
                ),
            ));
        }
        infos.push(level_info(&dir, level, &array, ty, &layout));
        opened.push((dir, array, ty));
    }
    let (dir, array, ty) = opened.swap_remove(chosen);
    let shape = array.shape().to_vec();

    // The time point and channel asked for (`axes.rs`).
    let extent =
        |axis: Option<usize>| axis.map_or(1, |a| usize::try_from(shape[a]).unwrap_or(usize::MAX));
    let volumes = Volumes::new(extent(layout.time), extent(layout.channel));
    let picked = volumes.pick(
        path,
        opts,
        AxisNames {
            holder: "the image",
            time: "axis \"t\"",
            channel: "axis \"c\"",
        },
    )?;
    let (frame, channel, channels) = (picked.time_point, picked.channel, volumes.channels);
    let mut start = vec![0u64; shape.len()];
    for (axis, index) in [
        (layout.time, frame as u64),
        (layout.channel, channel as u64),
    ] {
        if let Some(a) = axis {
            start[a] = index;
        }
    }

    let mut file_info = FileInfo::new(ty.name());
    let format = match array.metadata() {
        ArrayMetadata::V2(_) => "2",
        ArrayMetadata::V3(_) => "3",
    };
    file_info.header.push(("zarr_format".into(), format.into()));
    let names: Vec<&str> = axes.iter().map(|a| a.name.as_str()).collect();
    file_info.header.push(("axes".into(), names.join(" ")));
    if let Some(m) = &image {
        file_info
            .header
            .push(("OME-Zarr version".into(), m.version.clone()));
        file_info
            .header
            .push(("levels".into(), levels.len().to_string()));
        file_info.omero = ome::omero(&attrs, opts.channel.unwrap_or(0));
    }
    if channels > 1 {
        file_info
            .header
            .push(("channels".into(), channels.to_string()));
        file_info
            .notes
            .push(format!("channel {channel} of {channels} read"));
    }
    file_info.length_unit = layout.unit.clone();
    file_info.axis_units = layout.axis_units.clone();
    file_info.notes.extend(layout.unit_notes.iter().cloned());
    file_info.set_volumes(volumes, picked);
    let level = ZarrLevel::new(
        path,
        &dir,
        array,
        ty,
        start,
        &infos[chosen],
        opts.max_memory,
    )?;
    file_info.levels = infos;
    file_info.level = chosen;
    if let Some(name) = &opts.array {
        file_info.array = Some(name.clone());
        file_info.arrays = held;
    }
    Ok((level, file_info))
}

/// The directory of a level's array.
fn level_dir(root: &Path, level: &Level) -> PathBuf {
    level.path.split('/').fold(root.to_path_buf(), |p, part| {
        if part.is_empty() { p } else { p.join(part) }
    })
}

/// The axes of a bare array, by its number of dimensions.
fn bare_axes(path: &Path, n: usize) -> Result<Vec<Axis>, IoError> {
    let names: &[&str] = match n {
        3 => &["z", "y", "x"],
        4 => &["t", "z", "y", "x"],
        5 => &["t", "c", "z", "y", "x"],
        _ => {
            return Err(IoError::invalid(
                path,
                format!(
                    "a Zarr array of {n} dimensions: volray reads (z, y, x), (t, z, y, x) and (t, c, z, y, x)"
                ),
            ));
        }
    };
    Ok(names
        .iter()
        .map(|&name| Axis {
            name: name.to_string(),
            kind: match name {
                "t" => AxisKind::Time,
                "c" => AxisKind::Channel,
                _ => AxisKind::Space,
            },
            unit: None,
        })
        .collect())
}

/// Where the time and channel axes are, and the space axes' unit.
struct Layout {
    time: Option<usize>,
    channel: Option<usize>,
    /// The space axes' length unit, when all are lengths: the finest of
    /// theirs (`shared/units.rs`).
    unit: Option<String>,
    /// What each space axis's scale and translation are multiplied by to
    /// be in that unit, as x, y, z.
    factors: [f64; 3],
    /// What the conversion did, for the notes.
    unit_notes: Vec<String>,
    /// Each space axis's name and unit, as x, y, z, where they are kept
    /// apart ([`FileInfo::axis_units`](crate::FileInfo)).
    axis_units: Option<[crate::AxisUnitName; 3]>,
    /// How many axes there are: the last three are z, y, x.
    n: usize,
}

impl Layout {
    /// Checks that the image has three space axes, last, and at most one
    /// time and one channel axis.
    fn of(path: &Path, axes: &[Axis]) -> Result<Self, IoError> {
        let n = axes.len();
        let find = |kind| {
            let mut at = axes.iter().enumerate().filter(|(_, a)| a.kind == kind);
            let first = at.next().map(|(i, _)| i);
            (first, at.next().is_some())
        };
        let (time, two_times) = find(AxisKind::Time);
        let (channel, two_channels) = find(AxisKind::Channel);
        let space = axes.iter().filter(|a| a.kind == AxisKind::Space).count();
        let names: Vec<&str> = axes.iter().map(|a| a.name.as_str()).collect();
        if two_times
            || two_channels
            || space != 3
            || axes[n - 3..].iter().any(|a| a.kind != AxisKind::Space)
        {
            return Err(IoError::invalid(
                path,
                format!(
                    "axes [{}]: volray reads three space axes (z, y, x) last, after at most one time and one channel axis",
                    names.join(", ")
                ),
            ));
        }
        let space: Vec<AxisUnit> = axes[n - 3..]
            .iter()
            .map(|a| AxisUnit {
                name: &a.name,
                unit: a.unit.as_deref(),
            })
            .collect();
        let one = one_length_unit(&space);
        // The space axes are z, y, x: x is the last.
        let axis_units = (one.apart.len() == 3).then(|| {
            std::array::from_fn(|a| crate::AxisUnitName {
                name: space[2 - a].name.to_string(),
                unit: one.apart[2 - a].clone(),
            })
        });
        Ok(Layout {
            time,
            channel,
            unit: one.length_unit,
            factors: [one.factors[2], one.factors[1], one.factors[0]],
            unit_notes: one.notes,
            axis_units,
            n,
        })
    }

    /// Per-axis values (x, y, z) of the space axes in their own units, in
    /// the one length unit.
    fn in_unit(&self, xyz: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| xyz[a] * self.factors[a])
    }

    /// The last three values of a per-axis list, as x, y, z.
    fn xyz<T: Copy>(&self, values: &[T]) -> [T; 3] {
        [values[self.n - 1], values[self.n - 2], values[self.n - 3]]
    }
}

/// What `volray info` shows of one level.
fn level_info(
    dir: &Path,
    level: &Level,
    array: &ZarrArray,
    ty: ZarrType,
    layout: &Layout,
) -> LevelInfo {
    let shape = array.shape().to_vec();
    let dims = layout
        .xyz(&shape)
        .map(|d| usize::try_from(d).unwrap_or(usize::MAX));
    let (chunk, shard) = match (array.is_sharded(), array.subchunk_shape()) {
        (true, Some(inner)) => (
            Some(inner.iter().map(|n| n.get()).collect()),
            chunks::chunk_shape(array),
        ),
        _ => (chunks::chunk_shape(array), None),
    };
    let volume_values = dims.iter().fold(1u64, |p, &d| p.saturating_mul(d as u64));
    LevelInfo {
        path: level.path.clone(),
        shape,
        dims,
        spacing: layout.in_unit(layout.xyz(&level.scale)),
        origin: layout.in_unit(layout.xyz(&level.translation)),
        chunk_shape: chunk,
        shard_shape: shard,
        codecs: codecs(&serde_json::to_value(array.metadata()).unwrap_or(Value::Null)),
        dir: dir.to_path_buf(),
        bytes_stored: None,
        bytes_in_memory: volume_values.saturating_mul(ty.kept_bytes()),
    }
}

/// The codecs of an array's metadata, in order, for `volray info`:
/// `bytes, zstd` (v3), `sharding_indexed(bytes, blosc)`, `blosc (lz4)` (v2).
fn codecs(meta: &Value) -> String {
    fn named(list: &[Value]) -> Vec<String> {
        list.iter()
            .map(|c| {
                // A codec without configuration may be its bare name.
                let name = c
                    .as_str()
                    .or_else(|| c.get("name").and_then(Value::as_str))
                    .unwrap_or("?");
                let config = c.get("configuration");
                match config
                    .and_then(|c| c.get("codecs"))
                    .and_then(Value::as_array)
                {
                    Some(inner) => format!("{name}({})", named(inner).join(", ")),
                    None => match config.and_then(|c| c.get("cname")).and_then(Value::as_str) {
                        Some(cname) => format!("{name} ({cname})"),
                        None => name.to_string(),
                    },
                }
            })
            .collect()
    }
    if let Some(list) = meta.get("codecs").and_then(Value::as_array) {
        return named(list).join(", ");
    }
    // v2: filters, then the compressor.
    let mut parts: Vec<String> = meta
        .get("filters")
        .and_then(Value::as_array)
        .map(|f| {
            f.iter()
                .filter_map(|c| c.get("id")?.as_str().map(str::to_string))
                .collect()
        })
        .unwrap_or_default();
    if let Some(c) = meta.get("compressor").filter(|c| !c.is_null()) {
        let id = c.get("id").and_then(Value::as_str).unwrap_or("?");
        parts.push(match c.get("cname").and_then(Value::as_str) {
            Some(cname) => format!("{id} ({cname})"),
            None => id.to_string(),
        });
    }
    if parts.is_empty() {
        "none".to_string()
    } else {
        parts.join(", ")
    }
}
