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
//! one). The `omero` rendering hints of the channel read (its window,
//! colour, label, whether it is shown) go to `volray info` ([`omero`]).
//!
//! An image inside a plate (`plate`: wells, each a group whose `well`
//! lists its fields, the images) or a collection (a group of image
//! groups, as bioformats2raw writes: `OME/` beside series `0/`, `1/`,
//! ...) is named by `--array` ([`choose_image`]); without it, the error
//! lists the images held. Parsed with `serde_json` by hand rather than with the
//! `ome_zarr_metadata` crate: a few fields, and errors that name them.

use std::path::Path;

use serde_json::Value;

use super::store::{self, NodeKind};
use crate::{IoError, OmeroChannel};

/// Images listed in an error, at most.
const LISTED: usize = 10;
/// Images looked for in a plate or collection, at most (a 1536-well
/// plate of a few fields each).
const MAX_IMAGES: usize = 100_000;

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

/// The attributes' OME root: `ome` in 0.5, the attributes themselves in 0.4.
fn ome_root(attrs: &Value) -> &Value {
    attrs.get("ome").unwrap_or(attrs)
}

/// Whether a group's attributes describe an image.
fn is_image(attrs: &Value) -> bool {
    ome_root(attrs).get("multiscales").is_some()
}

/// A relative path inside a store: no climbing out, no empty parts.
fn inside(path: &str) -> bool {
    !path.is_empty()
        && !path.starts_with('/')
        && path
            .split('/')
            .all(|p| !p.is_empty() && p != "." && p != "..")
}

/// The image `array` names inside the group at `path` (a plate or a
/// collection), or `path` itself without `array`; and the images the
/// group holds when `array` was given. Without `array`, a group that is
/// a plate or a collection and no image is refused, listing its images.
pub(crate) fn choose_image(
    path: &Path,
    array: Option<&str>,
) -> Result<(std::path::PathBuf, Vec<String>), IoError> {
    let Some(name) = array else {
        if let Ok((NodeKind::Group, attrs)) = store::node(path)
            && !is_image(&attrs)
        {
            let (what, images) = images_in(path, &attrs);
            if !images.is_empty() {
                let mut shown: Vec<String> = images.iter().take(LISTED).cloned().collect();
                if images.len() > LISTED {
                    shown.push(format!("and {} more", images.len() - LISTED));
                }
                return Err(IoError::invalid(
                    path,
                    format!(
                        "an OME-Zarr {what} of {} image{}: name one with --array PATH ({})",
                        images.len(),
                        if images.len() == 1 { "" } else { "s" },
                        shown.join(", ")
                    ),
                ));
            }
        }
        return Ok((path.to_path_buf(), Vec::new()));
    };
    let name = name.trim_matches('/');
    let held = match store::node(path) {
        Ok((NodeKind::Group, attrs)) => images_in(path, &attrs).1,
        _ => Vec::new(),
    };
    let target = path.join(name);
    if !inside(name) || !store::is_zarr_dir(&target) {
        let listed = if held.is_empty() {
            "it holds no plate or collection of images".to_string()
        } else {
            let mut shown: Vec<String> = held.iter().take(LISTED).cloned().collect();
            if held.len() > LISTED {
                shown.push(format!("and {} more", held.len() - LISTED));
            }
            format!("its images: {}", shown.join(", "))
        };
        return Err(IoError::invalid(
            path,
            format!("--array \"{name}\" is no Zarr group or array in the store; {listed}"),
        ));
    }
    Ok((target, held))
}

/// What the group is (`plate`, `collection`) and the images in it, in
/// order: a plate's wells' fields (`A/1/0`), else the series of a
/// bioformats2raw layout (`OME/`'s `series`, else `0`, `1`, ...), else the
/// subgroups that are images, in name order.
fn images_in(path: &Path, attrs: &Value) -> (&'static str, Vec<String>) {
    let root = ome_root(attrs);
    if let Some(wells) = root
        .get("plate")
        .and_then(|p| p.get("wells"))
        .and_then(Value::as_array)
    {
        let mut images = Vec::new();
        for well in wells {
            let Some(w) = well
                .get("path")
                .and_then(Value::as_str)
                .filter(|w| inside(w))
            else {
                continue;
            };
            let Ok((_, wattrs)) = store::node(&path.join(w)) else {
                continue;
            };
            let fields = ome_root(&wattrs)
                .get("well")
                .and_then(|w| w.get("images"))
                .and_then(Value::as_array)
                .cloned()
                .unwrap_or_default();
            for f in &fields {
                if let Some(p) = f.get("path").and_then(Value::as_str).filter(|p| inside(p)) {
                    images.push(format!("{w}/{p}"));
                }
                if images.len() >= MAX_IMAGES {
                    return ("plate", images);
                }
            }
        }
        return ("plate", images);
    }
    // bioformats2raw: OME/.zattrs (or zarr.json) lists the series.
    if let Ok((_, ome)) = store::node(&path.join("OME"))
        && let Some(series) = ome_root(&ome).get("series").and_then(Value::as_array)
    {
        let images: Vec<String> = series
            .iter()
            .filter_map(Value::as_str)
            .filter(|s| inside(s))
            .take(MAX_IMAGES)
            .map(str::to_string)
            .collect();
        if !images.is_empty() {
            return ("collection", images);
        }
    }
    let mut names: Vec<String> = std::fs::read_dir(path)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .filter_map(|e| e.file_name().to_str().map(str::to_string))
                .take(MAX_IMAGES)
                .collect()
        })
        .unwrap_or_default();
    // Numbered series in numeric order, then names.
    names.sort_by_key(|n| (n.parse::<u64>().unwrap_or(u64::MAX), n.clone()));
    let images = names
        .into_iter()
        .filter(|n| matches!(store::node(&path.join(n)), Ok((NodeKind::Group, a)) if is_image(&a)))
        .collect();
    ("collection", images)
}

/// The `omero` rendering hints of channel `channel`, if the image gives
/// any: `omero.channels[channel]`'s `window` (`start`, `end`, `min`,
/// `max`), `color` (hex RGB), `label` and `active`.
pub(crate) fn omero(attrs: &Value, channel: usize) -> Option<OmeroChannel> {
    let c = ome_root(attrs)
        .get("omero")
        .or_else(|| attrs.get("omero"))?
        .get("channels")?
        .as_array()?
        .get(channel)?;
    let number = |w: &Value, k: &str| w.get(k).and_then(Value::as_f64).filter(|v| v.is_finite());
    let window = c.get("window").map(|w| {
        [
            number(w, "start"),
            number(w, "end"),
            number(w, "min"),
            number(w, "max"),
        ]
    });
    let color = c
        .get("color")
        .and_then(Value::as_str)
        .map(|s| s.trim_start_matches('#').to_ascii_uppercase())
        .filter(|s| s.len() == 6 && s.chars().all(|ch| ch.is_ascii_hexdigit()));
    Some(OmeroChannel {
        channel,
        label: c.get("label").and_then(Value::as_str).map(str::to_string),
        color,
        active: c.get("active").and_then(Value::as_bool),
        window: window.and_then(|[s, e, lo, hi]| Some((s?, e?, lo, hi))),
    })
}
