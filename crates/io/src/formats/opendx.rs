//! OpenDX scalar fields (`.dx`): the regular grids APBS writes its
//! electrostatic potentials in, and VMD, PyMOL, Chimera and MDAnalysis's
//! GridDataFormats read and write, read with volray's own parser.
//!
//! The layout (IBM Visualization Data Explorer, "Native file format",
//! usrgu068; APBS's "OpenDX scalar data format"):
//!
//! ```text
//! # comments                               anywhere before the data
//! object 1 class gridpositions counts n1 n2 n3
//! origin x0 y0 z0
//! delta  d11 d12 d13                       the step along axis 1 (slowest)
//! delta  d21 d22 d23
//! delta  d31 d32 d33                       axis 3 runs fastest
//! object 2 class gridconnections counts n1 n2 n3
//! object 3 class array type double rank 0 items N data follows
//! v v v ...                                N values, axis 3 fastest ("z is the innermost loop")
//! attribute "dep" string "positions"      the field's closing records: not read
//! object "..." class field
//! component "data" value 3
//! ```
//!
//! Axis 3 is volray's index axis 0; `grid_to_volume` turns the axes to
//! world x, y, z. Deltas along the world axes (APBS, GridDataFormats,
//! VMD, PyMOL) place the grid exactly; orthogonal deltas rotated away from
//! the world axes keep the grid in its own axes with a note, as other
//! readers carry orientation; skewed deltas are resampled over the grid's
//! own box, NaN outside it (no data there, rendered as empty), with a
//! note. Lengths are the file's (ångström for APBS and the molecular
//! tools; the format names none). Data in a separate file or in binary
//! (`data file ...`, `binary`, `ieee`) are refused by name.

use std::path::Path;

use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::{F32_BYTES, check_dims};
use crate::shared::packed::open_unpacked;
use crate::shared::periodic_cell;
use crate::shared::text_reader::{TextReader, integer, number, whole_lines};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Whether a file's first bytes (`text`) open as an OpenDX field: a line,
/// comments aside, declaring an object of class `gridpositions`.
pub(crate) fn sniff_text(text: &str) -> bool {
    whole_lines(text).any(|line| {
        let mut words = line.split_whitespace();
        words.next() == Some("object")
            && words.any(|w| w.trim_matches('"') == "gridpositions")
            && line.contains("class")
    })
}

/// What the header declared, as far as it was read.
#[derive(Default)]
struct Header {
    counts: Option<[usize; 3]>,
    origin: Option<DVec3>,
    deltas: Vec<DVec3>,
    /// The data array's `type`, and its item count.
    array: Option<(String, u64)>,
}

/// Reads the OpenDX file at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let opened = open_unpacked(path)?;
    let mut info = FileInfo::new("decimal text");
    info.notes.extend(opened.note());
    let len = opened.len;
    let size = opened.size_phrase();
    let mut r = TextReader::new(path, opened.reader);
    let invalid = |reason: String| IoError::invalid(path, reason);

    let mut h = Header::default();
    while h.array.is_none() {
        let line = r.line("the data array (object ... class array ... data follows)")?;
        let text = line.split('#').next().unwrap_or("");
        let words: Vec<&str> = text
            .split_whitespace()
            .map(|w| w.trim_matches('"'))
            .collect();
        match words.first().copied() {
            None => {}
            Some("object") => object(&mut r, &words, &mut h, &mut info)?,
            Some("origin") => {
                let v = three(&words[1..], "origin").map_err(|e| r.error(e))?;
                info.header.push(("origin".into(), words[1..].join(" ")));
                h.origin = Some(v);
            }
            Some("delta") => {
                let v = three(&words[1..], "delta").map_err(|e| r.error(e))?;
                if h.deltas.len() == 3 {
                    return Err(r.error("a fourth delta line: a 3-D grid has three"));
                }
                info.header.push((
                    format!("delta {}", h.deltas.len() + 1),
                    words[1..].join(" "),
                ));
                h.deltas.push(v);
            }
            Some(other) => {
                info.header.push((other.to_string(), words[1..].join(" ")));
            }
        }
    }
    let Some(counts) = h.counts else {
        return Err(invalid(
            "the data array comes before any \"object ... class gridpositions counts n1 n2 n3\": the grid is unknown".into(),
        ));
    };
    let origin = h
        .origin
        .ok_or_else(|| invalid("no origin line before the data".into()))?;
    if h.deltas.len() != 3 {
        return Err(invalid(format!(
            "{} delta line(s) before the data: a 3-D grid needs three",
            h.deltas.len()
        )));
    }
    let (kind, items) = h.array.expect("loop ends with the array");
    info.stored_type = format!("decimal text ({kind})");
    let points = counts[0] as u64 * counts[1] as u64 * counts[2] as u64;
    if items != points {
        return Err(invalid(format!(
            "the data array holds {items} items but the grid {} x {} x {} has {points} points",
            counts[0], counts[1], counts[2]
        )));
    }
    if points > len / 2 + 1 {
        return Err(invalid(format!(
            "the grid {} x {} x {} has {points} points, more values than a {size} can hold",
            counts[0], counts[1], counts[2]
        )));
    }
    info.notes.push(
        "spacing and origin are in the file's unit (OpenDX names none; APBS and the molecular tools write angstrom)".into(),
    );
    // Axis 3 runs fastest: volray's index axis 0.
    let dims = [counts[2], counts[1], counts[0]];
    check_dims(path, "counts", &dims, F32_BYTES, opts.max_memory)?;
    let mut data = Vec::with_capacity(points as usize);
    r.tokens(points as usize, "the data array", |_, t| {
        data.push(number(t, "data value")? as f32);
        Ok(())
    })?;
    r.finish_line(&format!("the {points} values the data array declares"))?;

    let steps = [h.deltas[2], h.deltas[1], h.deltas[0]];
    let volume = if periodic_cell::is_skewed(steps) {
        let (volume, note) = periodic_cell::resample_sheared(
            dims,
            &data,
            steps,
            origin,
            ["axis 3", "axis 2", "axis 1"],
            "",
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "delta"))?;
        info.notes.push(note);
        info.nan_is_empty = true;
        volume
    } else {
        grid_to_volume(path, dims, data, steps, origin, &mut info)?
    };
    Ok(Loaded {
        volume,
        format: VolumeFormat::Dx,
        info,
    })
}

/// Reads an `object` line's declaration into `h`.
fn object<R: std::io::BufRead>(
    r: &mut TextReader<R>,
    words: &[&str],
    h: &mut Header,
    info: &mut FileInfo,
) -> Result<(), IoError> {
    let after = |key: &str| {
        words
            .iter()
            .position(|w| *w == key)
            .map(|i| &words[i + 1..])
    };
    let class = after("class")
        .and_then(|w| w.first().copied())
        .unwrap_or("");
    info.header.push((
        format!("object {}", words.get(1).unwrap_or(&"")),
        words[2..].join(" "),
    ));
    match class {
        "gridpositions" => {
            let counts = after("counts").unwrap_or(&[]);
            if counts.len() != 3 {
                return Err(r.error(format!(
                    "gridpositions with {} counts: volray reads 3-D grids (counts n1 n2 n3)",
                    counts.len()
                )));
            }
            let mut n = [0usize; 3];
            for (a, t) in counts.iter().enumerate() {
                let v = integer(t, &format!("count {}", a + 1)).map_err(|e| r.error(e))?;
                if v < 1 {
                    return Err(r.error(format!("count {}: {v} points", a + 1)));
                }
                n[a] = usize::try_from(v).map_err(|_| r.error(format!("count {}: {v}", a + 1)))?;
            }
            h.counts = Some(n);
        }
        "array" => {
            let kind = after("type")
                .and_then(|w| w.first().copied())
                .unwrap_or("float");
            let rank = after("rank")
                .and_then(|w| w.first().copied())
                .unwrap_or("0");
            let shape = after("shape")
                .and_then(|w| w.first().copied())
                .unwrap_or("1");
            if rank != "0" && !(rank == "1" && shape == "1") {
                return Err(r.error(format!(
                    "an array of rank {rank} (shape {shape}): volray reads scalar fields (rank 0)"
                )));
            }
            let items = after("items")
                .and_then(|w| w.first())
                .ok_or_else(|| r.error("the array declares no item count (items N)"))?;
            let items = integer(items, "items").map_err(|e| r.error(e))?;
            let items = u64::try_from(items).map_err(|_| r.error(format!("items {items}")))?;
            for word in ["binary", "ieee", "msb", "lsb"] {
                if words.contains(&word) {
                    return Err(r.error(format!(
                        "{word} data: volray reads OpenDX values written as text after the header (data follows)"
                    )));
                }
            }
            match after("data").and_then(|w| w.first().copied()) {
                Some("follows") => {}
                Some(other) => {
                    return Err(r.error(format!(
                        "data {other}: volray reads OpenDX values that follow the header in the same file (data follows), not values in another file or at an offset"
                    )));
                }
                None => {
                    return Err(r.error(
                        "the array says not where its data is (data follows): volray reads values that follow the header",
                    ));
                }
            }
            h.array = Some((kind.to_string(), items));
        }
        _ => {}
    }
    Ok(())
}

/// Three numbers, for the field `what`.
fn three(words: &[&str], what: &str) -> Result<DVec3, String> {
    if words.len() != 3 {
        return Err(format!(
            "{what}: expected three numbers, found {}",
            words.len()
        ));
    }
    let mut v = DVec3::ZERO;
    for a in 0..3 {
        v[a] = number(words[a], what)?;
        if !v[a].is_finite() {
            return Err(format!("{what}: \"{}\" is not finite", words[a]));
        }
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sniffer_knows_gridpositions_lines() {
        assert!(sniff_text(
            "# APBS\nobject 1 class gridpositions counts 2 2 2\n"
        ));
        assert!(sniff_text(
            "object 1 class \"gridpositions\" counts 2 2 2\n"
        ));
        assert!(!sniff_text("# object 1 class gridpositions counts 2 2 2\n"));
        assert!(!sniff_text("object 1 class array type float\n"));
    }
}
