//! A Zarr directory on disk: what it is (a v2 or v3 group or array, by
//! its metadata files), its attributes, and the bytes its chunks take.
//!
//! Zarr v2 marks a group with `.zgroup` and an array with `.zarray`, and
//! keeps user attributes (OME's `multiscales`) in `.zattrs`; Zarr v3
//! keeps all of it in one `zarr.json`, whose `node_type` is `group` or
//! `array` and whose `attributes` hold OME 0.5's `ome` key. A directory
//! holding none of these is no Zarr node (it may be a DICOM series).

use std::path::Path;

use serde_json::Value;

use crate::IoError;

/// The metadata files that make a directory a Zarr node.
pub(crate) const MARKERS: [&str; 4] = ["zarr.json", ".zarray", ".zgroup", ".zattrs"];

/// The most bytes a metadata file may hold: OME metadata for a pyramid of
/// many levels and channels is a few KiB; anything near this is no
/// metadata file.
pub(crate) const MAX_METADATA_BYTES: u64 = 16 << 20;

/// Whether `dir` is a Zarr group or array: it holds a metadata file.
pub(crate) fn is_zarr_dir(dir: &Path) -> bool {
    dir.is_dir() && MARKERS.iter().any(|m| dir.join(m).is_file())
}

/// What a Zarr directory holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NodeKind {
    Group,
    Array,
}

/// A directory's node kind and its attributes (an empty object where it
/// has none).
pub(crate) fn node(dir: &Path) -> Result<(NodeKind, Value), IoError> {
    if dir.join("zarr.json").is_file() {
        let meta = read_json(&dir.join("zarr.json"))?;
        let kind = match meta.get("node_type").and_then(Value::as_str) {
            Some("group") => NodeKind::Group,
            Some("array") => NodeKind::Array,
            other => {
                return Err(IoError::invalid(
                    &dir.join("zarr.json"),
                    format!(
                        "Zarr v3 field \"node_type\" is {}: expected \"group\" or \"array\"",
                        other.map_or("missing".to_string(), |s| format!("\"{s}\""))
                    ),
                ));
            }
        };
        let attributes = meta.get("attributes").cloned().unwrap_or(Value::Null);
        return Ok((kind, object_or_empty(attributes)));
    }
    let attrs = dir.join(".zattrs");
    let attributes = if attrs.is_file() {
        read_json(&attrs)?
    } else {
        Value::Null
    };
    let kind = if dir.join(".zarray").is_file() {
        NodeKind::Array
    } else if dir.join(".zgroup").is_file() || attrs.is_file() {
        NodeKind::Group
    } else {
        return Err(IoError::invalid(
            dir,
            "not a Zarr group or array: no zarr.json (v3), .zarray, .zgroup or .zattrs (v2)",
        ));
    };
    Ok((kind, object_or_empty(attributes)))
}

fn object_or_empty(value: Value) -> Value {
    if value.is_object() {
        value
    } else {
        Value::Object(Default::default())
    }
}

/// Reads and parses a JSON metadata file, refusing one over
/// [`MAX_METADATA_BYTES`] before reading it.
fn read_json(path: &Path) -> Result<Value, IoError> {
    let len = std::fs::metadata(path)
        .map_err(|e| IoError::os(path, "read", e))?
        .len();
    if len > MAX_METADATA_BYTES {
        return Err(IoError::invalid(
            path,
            format!("{len} bytes is too large for Zarr metadata (at most {MAX_METADATA_BYTES})"),
        ));
    }
    let text = std::fs::read(path).map_err(|e| IoError::os(path, "read", e))?;
    serde_json::from_slice(&text).map_err(|e| IoError::invalid(path, format!("invalid JSON: {e}")))
}

/// The bytes an array's chunk files take on disk: every file below `dir`
/// but its metadata files (chunks of v2 arrays sit beside `.zarray`, of
/// v3 arrays under `c/`, shards alike). Unreadable entries count as 0:
/// this is a statistic for `volray info`, not a check. `None` once more
/// than `max_files` files are found.
pub(crate) fn stored_bytes(dir: &Path, max_files: usize) -> Option<u64> {
    let mut total = 0;
    let mut files = 0usize;
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            let Ok(kind) = entry.file_type() else {
                continue;
            };
            let name = entry.file_name();
            if kind.is_dir() {
                pending.push(entry.path());
            } else if kind.is_file() && !MARKERS.iter().any(|m| name == *m) {
                files += 1;
                if files > max_files {
                    return None;
                }
                total += entry.metadata().map_or(0, |m| m.len());
            }
        }
    }
    Some(total)
}
