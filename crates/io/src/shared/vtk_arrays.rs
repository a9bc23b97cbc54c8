//! Choosing which named array of a VTK file becomes the volume, for both
//! VTK readers (legacy `.vtk` and XML `.vti`).
//!
//! VTK image files carry any number of named point-data and cell-data
//! arrays. volray renders one scalar array:
//! - `--array NAME` picks it by name, point data first if both hold the
//!   name; `point:NAME` and `cell:NAME` say which explicitly;
//! - otherwise the active scalars of the point data (legacy `SCALARS`,
//!   XML `PointData Scalars="..."`), else the first one-component point
//!   array, else the same in the cell data (voxels are grid points, so point
//!   data is preferred).
//!
//! Cell data of `c` cells per axis becomes a volume of `c` points at the
//! cell centres, half a step inside the point grid.

use std::path::Path;

use volray_core::glam::DVec3;

use crate::FileInfo;
use crate::error::IoError;

/// Whether an array holds a value per grid point or per cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Association {
    Point,
    Cell,
}

impl Association {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Association::Point => "point",
            Association::Cell => "cell",
        }
    }
}

/// What a reader knows about an array before decoding it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ArrayEntry {
    pub name: String,
    pub association: Association,
    pub components: usize,
    /// The active scalars of its association (legacy `SCALARS`, XML
    /// `Scalars="name"`).
    pub active_scalars: bool,
    /// The sample type as the file names it, for messages.
    pub type_name: String,
}

/// How well `entry` answers the request (lower is better); `None` if it
/// does not answer it at all. `request` is the `--array` value, if any.
pub(crate) fn rank(entry: &ArrayEntry, request: Option<&str>) -> Option<u8> {
    let point = entry.association == Association::Point;
    match request {
        Some(req) => {
            if entry.name == req {
                Some(if point { 0 } else { 1 })
            } else if let Some(name) = req.strip_prefix("point:") {
                (point && entry.name == name).then_some(0)
            } else if let Some(name) = req.strip_prefix("cell:") {
                (!point && entry.name == name).then_some(0)
            } else {
                None
            }
        }
        None => {
            if entry.components != 1 {
                return None;
            }
            Some(match (point, entry.active_scalars) {
                (true, true) => 0,
                (true, false) => 1,
                (false, true) => 2,
                (false, false) => 3,
            })
        }
    }
}

/// The error for a file in which nothing answers the request, listing
/// what the file holds.
pub(crate) fn no_match(path: &Path, entries: &[ArrayEntry], request: Option<&str>) -> IoError {
    let held = if entries.is_empty() {
        "the file holds no point or cell arrays".to_string()
    } else {
        format!("the file holds {}", describe(entries))
    };
    match request {
        Some(req) => IoError::no_such_array(path, req, held),
        None => IoError::invalid(
            path,
            format!("no one-component point or cell array to render: {held}"),
        ),
    }
}

/// The error for a chosen array that is not a scalar.
pub(crate) fn not_scalar(path: &Path, entry: &ArrayEntry, entries: &[ArrayEntry]) -> IoError {
    let array = format!(
        "{} array \"{}\" has {} components",
        entry.association.name(),
        entry.name,
        entry.components
    );
    let scalars: Vec<&str> = entries
        .iter()
        .filter(|e| e.components == 1)
        .map(|e| e.name.as_str())
        .collect();
    if scalars.is_empty() {
        return IoError::invalid(
            path,
            format!(
                "{array}: volray renders scalar arrays; the file holds no one-component arrays"
            ),
        );
    }
    IoError::array_not_scalar(path, array, scalars.join(", "))
}

/// "point arrays a (float), b (3 components, float); cell arrays c (double)".
fn describe(entries: &[ArrayEntry]) -> String {
    let mut parts = Vec::new();
    for assoc in [Association::Point, Association::Cell] {
        let list: Vec<String> = entries
            .iter()
            .filter(|e| e.association == assoc)
            .map(|e| {
                if e.components == 1 {
                    format!("\"{}\" ({})", e.name, e.type_name)
                } else {
                    format!(
                        "\"{}\" ({} components, {})",
                        e.name, e.components, e.type_name
                    )
                }
            })
            .collect();
        if !list.is_empty() {
            parts.push(format!("{} arrays {}", assoc.name(), list.join(", ")));
        }
    }
    parts.join("; ")
}

/// Fills `info.arrays`/`info.array` and notes the choice.
pub(crate) fn record_choice(
    info: &mut FileInfo,
    entries: &[ArrayEntry],
    chosen: &ArrayEntry,
    request: Option<&str>,
) {
    info.arrays = entries.iter().map(|e| e.name.clone()).collect();
    info.array = Some(chosen.name.clone());
    let why = match request {
        Some(_) => "the one asked for",
        None if chosen.active_scalars => "the active scalars",
        None => "the first one-component array",
    };
    info.notes.push(format!(
        "read {} data array \"{}\" ({why})",
        chosen.association.name(),
        chosen.name
    ));
}

/// Cells per axis of a grid of `points` per axis (VTK: `max(n − 1, 1)`).
pub(crate) fn cell_dims(points: [usize; 3]) -> [usize; 3] {
    points.map(|n| n.saturating_sub(1).max(1))
}

/// Turns the grid geometry of the points into that of the cell centres:
/// the origin moves half a step along every axis that has cells between
/// points. Notes the conversion.
pub(crate) fn cell_centres(
    points: [usize; 3],
    steps: [DVec3; 3],
    origin: DVec3,
    info: &mut FileInfo,
    name: &str,
) -> DVec3 {
    let cells = cell_dims(points);
    let mut shifted = origin;
    for a in 0..3 {
        if points[a] > 1 {
            shifted += steps[a] * 0.5;
        }
    }
    info.notes.push(format!(
        "cell data \"{name}\" ({}x{}x{} cells) read as one voxel per cell at the cell centres: origin moved half a step, to ({}, {}, {})",
        cells[0], cells[1], cells[2], shifted.x, shifted.y, shifted.z
    ));
    shifted
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(name: &str, association: Association, components: usize, active: bool) -> ArrayEntry {
        ArrayEntry {
            name: name.to_string(),
            association,
            components,
            active_scalars: active,
            type_name: "float".to_string(),
        }
    }

    fn best<'a>(entries: &'a [ArrayEntry], request: Option<&str>) -> Option<&'a str> {
        let mut best: Option<(u8, &ArrayEntry)> = None;
        for e in entries {
            if let Some(r) = rank(e, request)
                && best.is_none_or(|(b, _)| r < b)
            {
                best = Some((r, e));
            }
        }
        best.map(|(_, e)| e.name.as_str())
    }

    #[test]
    fn default_prefers_point_scalars_then_point_then_cell() {
        use Association::*;
        let all = [
            entry("c", Cell, 1, true),
            entry("v", Point, 3, true),
            entry("p", Point, 1, false),
            entry("s", Point, 1, true),
        ];
        assert_eq!(best(&all, None), Some("s"));
        assert_eq!(best(&all[..3], None), Some("p"));
        assert_eq!(best(&all[..2], None), Some("c"));
        assert_eq!(best(&all[1..2], None), None);
    }

    #[test]
    fn requests_match_names_point_first() {
        use Association::*;
        let all = [
            entry("a", Cell, 1, true),
            entry("a", Point, 1, false),
            entry("v", Point, 3, false),
        ];
        assert_eq!(
            rank(&all[0], Some("a")),
            Some(1),
            "cell match ranks after point"
        );
        assert_eq!(rank(&all[1], Some("a")), Some(0));
        assert_eq!(rank(&all[0], Some("cell:a")), Some(0));
        assert_eq!(rank(&all[1], Some("cell:a")), None);
        assert_eq!(best(&all, Some("v")), Some("v"));
        assert_eq!(best(&all, Some("w")), None);
        let msg = no_match(Path::new("f.vtk"), &all, Some("w")).to_string();
        assert!(
            msg.contains("no array named \"w\"")
                && msg.contains("point arrays \"a\" (float), \"v\" (3 components, float)")
                && msg.contains("cell arrays \"a\" (float)"),
            "{msg}"
        );
        let msg = not_scalar(Path::new("f.vtk"), &all[2], &all).to_string();
        assert!(
            msg.contains("has 3 components") && msg.contains("(a, a)"),
            "{msg}"
        );
    }

    #[test]
    fn cell_centres_sit_half_a_step_in() {
        let mut info = FileInfo::default();
        let steps = [DVec3::X * 2.0, DVec3::Y * -1.0, DVec3::Z * 0.5];
        let o = cell_centres([4, 3, 5], steps, DVec3::new(1.0, 1.0, 1.0), &mut info, "c");
        assert_eq!(o, DVec3::new(2.0, 0.5, 1.25));
        assert_eq!(cell_dims([4, 3, 5]), [3, 2, 4]);
        assert_eq!(cell_dims([1, 3, 5]), [1, 2, 4]);
        assert!(info.notes[0].contains("3x2x4 cells"));
    }
}
