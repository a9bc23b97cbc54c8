//! OME-Zarr (NGFF) image metadata: the `multiscales` attribute of a
//! group, version 0.4 (in `.zattrs`, Zarr v2; the key at the top of the
//! attributes) or 0.5 (in `zarr.json`, Zarr v3; under `ome`).
//!
//! One multiscale lists its axes (`name`, `type`: `time`, `channel` or
//! `space`, and `unit`) and its levels (`datasets`), finest first, each
//! an array path with coordinate transformations: a `scale`, then
//! optionally a `translation`, one value per axis. The multiscale itself
//! may carry one more scale and translation that apply to every level
//! after the level's own. A point at index `i` along an axis is at
//! (NGFF 0.4, "coordinateTransformations")
//!
//! ```text
//! world = global_scale · (scale · i + translation) + global_translation
//! ```
//!
//! so each level's spacing is `global_scale · scale` and its origin
//! `global_scale · translation + global_translation`. Only the first
//! multiscale is read (the specification allows several; writers make
//! one). `omero` rendering hints (channel windows and colours) are not
//! read yet. Parsed with `serde_json` by hand rather than with the
//! `ome_zarr_metadata` crate: a few fields, and errors that name them.

use std::path::Path;

use serde_json::Value;

use crate::IoError;

/// What an axis of an OME-Zarr image is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AxisKind {
    Time,
    Channel,
    Space,
}

/// One axis: its name, kind and unit.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Axis {
    pub name: String,
    pub kind: AxisKind,
    pub unit: Option<String>,
}

/// One level of a multiscale: the array's path in the group, and where
/// its samples are (per axis, in the array's axis order).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Level {
    pub path: String,
    pub scale: Vec<f64>,
    pub translation: Vec<f64>,
}

/// A multiscale image: its axes and its levels, finest first.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Multiscale {
    /// `0.4`, `0.5`, ... as the metadata says.
    pub version: String,
    pub axes: Vec<Axis>,
    pub levels: Vec<Level>,
    /// The image holds `omero` rendering hints (not read yet).
    pub has_omero: bool,
}

/// The image a group's attributes describe, or `None` if they hold no
/// `multiscales` (a plain group).
pub(crate) fn multiscale(path: &Path, attrs: &Value) -> Result<Option<Multiscale>, IoError> {
    // 0.5 nests everything under "ome", with the version there.
    let (root, version) = match attrs.get("ome") {
        Some(ome) => (ome, ome.get("version").and_then(Value::as_str)),
        None => (attrs, None),
    };
    let Some(list) = root.get("multiscales") else {
        return Ok(None);
    };
    let bad = |what: &str| IoError::invalid(path, format!("OME-Zarr \"multiscales\": {what}"));
    let first = list
        .as_array()
        .and_then(|l| l.first())
        .ok_or_else(|| bad("expected a non-empty list"))?;
    let version = version
        .or_else(|| first.get("version").and_then(Value::as_str))
        .unwrap_or("unknown")
        .to_string();
    let axes = first
        .get("axes")
        .and_then(Value::as_array)
        .ok_or_else(|| bad("no \"axes\" list"))?
        .iter()
        .map(|a| axis(a).ok_or_else(|| bad(&format!("axis {a} has no name"))))
        .collect::<Result<Vec<_>, _>>()?;
    let n = axes.len();
    let global = transforms(first.get("coordinateTransformations"), n).map_err(|e| {
        bad(&format!(
            "the multiscale's \"coordinateTransformations\": {e}"
        ))
    })?;
    let datasets = first
        .get("datasets")
        .and_then(Value::as_array)
        .filter(|d| !d.is_empty())
        .ok_or_else(|| bad("no \"datasets\" list"))?;
    let mut levels = Vec::with_capacity(datasets.len());
    for (i, d) in datasets.iter().enumerate() {
        let p = d
            .get("path")
            .and_then(Value::as_str)
            .ok_or_else(|| bad(&format!("dataset {i} has no \"path\"")))?;
        // A level is a subdirectory: no climbing out of the image.
        if p.is_empty() || p.split('/').any(|part| part == ".." || part.is_empty()) {
            return Err(bad(&format!("dataset {i} has path \"{p}\"")));
        }
        let (scale, translation) = transforms(d.get("coordinateTransformations"), n)
            .map_err(|e| bad(&format!("dataset \"{p}\": {e}")))?;
        levels.push(Level {
            path: p.to_string(),
            scale: (0..n).map(|k| global.0[k] * scale[k]).collect(),
            translation: (0..n)
                .map(|k| global.0[k] * translation[k] + global.1[k])
                .collect(),
        });
    }
    Ok(Some(Multiscale {
        version,
        axes,
        levels,
        has_omero: root.get("omero").is_some() || attrs.get("omero").is_some(),
    }))
}

/// An axis of the `axes` list; 0.3 wrote bare names, so a string is a
/// name. Without a `type`, `t` is time, `c` a channel, anything else space.
fn axis(value: &Value) -> Option<Axis> {
    let (name, kind, unit) = match value {
        Value::String(s) => (s.clone(), None, None),
        Value::Object(o) => (
            o.get("name")?.as_str()?.to_string(),
            o.get("type").and_then(Value::as_str),
            o.get("unit").and_then(Value::as_str).map(str::to_string),
        ),
        _ => return None,
    };
    let kind = match (kind, name.as_str()) {
        (Some("time"), _) | (None, "t") => AxisKind::Time,
        (Some("channel"), _) | (None, "c") => AxisKind::Channel,
        _ => AxisKind::Space,
    };
    Some(Axis { name, kind, unit })
}

/// The scale and translation of a `coordinateTransformations` list (each
/// 1 and 0 where it has none), `n` values each.
fn transforms(list: Option<&Value>, n: usize) -> Result<(Vec<f64>, Vec<f64>), String> {
    let mut scale = vec![1.0; n];
    let mut translation = vec![0.0; n];
    let Some(list) = list else {
        return Ok((scale, translation));
    };
    let list = list.as_array().ok_or("expected a list")?;
    for t in list {
        let kind = t.get("type").and_then(Value::as_str).unwrap_or("");
        let target = match kind {
            "scale" => &mut scale,
            "translation" => &mut translation,
            "identity" => continue,
            other => return Err(format!("transformation type \"{other}\" is not supported")),
        };
        let values = t
            .get(kind)
            .and_then(Value::as_array)
            .ok_or_else(|| format!("{kind} has no list of values"))?;
        if values.len() != n {
            return Err(format!("{kind} has {} values for {n} axes", values.len()));
        }
        for (slot, v) in target.iter_mut().zip(values) {
            *slot = v
                .as_f64()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{kind} value {v} is not a finite number"))?;
        }
    }
    if scale.iter().any(|&s| s <= 0.0) {
        return Err(format!("scale {scale:?} must be positive"));
    }
    Ok((scale, translation))
}
