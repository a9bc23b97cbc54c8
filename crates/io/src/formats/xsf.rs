//! XCrySDen structure files (`.xsf`) and band-grid files (`.bxsf`): the 3-D
//! data grids Quantum ESPRESSO's pp.x, VASP tools, ASE and VESTA write
//! (densities, potentials, wave functions) and the Fermi surfaces of
//! band structures, read with volray's own parser.
//!
//! The layout (A. Kokalj, "XSF format specification", xcrysden.org):
//!
//! ```text
//! CRYSTAL / PRIMVEC a b c / PRIMCOORD ...    the structure: not read, but PRIMVEC
//! BEGIN_BLOCK_DATAGRID_3D
//!  block comment
//!  BEGIN_DATAGRID_3D_name                    (or DATAGRID_3D_name; ASE writes no `_`)
//!   nx ny nz
//!   origin
//!   spanning vector 1                        the grid spans origin .. origin + vector
//!   spanning vector 2
//!   spanning vector 3
//!   values, x fastest ("column-major")
//!  END_DATAGRID_3D
//!  (more grids)
//! END_BLOCK_DATAGRID_3D
//! ```
//!
//! A `.bxsf` holds `BEGIN_BANDGRID_3D_name`, the band count, the grid as
//! above in reciprocal space, then `BAND: n` and its values for each band.
//!
//! Choices, each stated in [`FileInfo::notes`]:
//!
//! - The grids are "general grids": point `i` of `n` sits at `i/(n-1)` of
//!   the spanning vector, the last point repeating the first in a
//!   periodic crystal. An orthogonal grid is read as it stands (all `n`
//!   points, so the volume spans the cell). A skewed one is one periodic
//!   cell: its last point on each axis is dropped and the cell resampled
//!   onto an axis-aligned grid as CHGCAR's is ([`crate::shared::periodic_cell`]);
//!   in a file with no `PRIMVEC` (a molecule) the grid's own box is
//!   resampled instead, NaN outside it.
//! - Several grids are arrays, named as the file names them: `--array NAME`
//!   picks one, the first by default, with a note listing them. A band
//!   grid's bands are frames (`--frame`, from 0 for band 1).
//! - Lengths in ångström (the XSF specification); a band grid is in
//!   reciprocal space (1/ångström), said in a note.

use std::io::BufRead;
use std::path::Path;

use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::{F32_BYTES, check_dims};
use crate::shared::packed::open_unpacked;
use crate::shared::periodic_cell;
use crate::shared::text_reader::{TextReader, all_numbers, integer, number, whole_lines};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Whether a file's first bytes (`text`) open as XSF: a line that is one
/// of XSF's own keywords (the structure's or a grid block's), comments
/// and blank lines aside, as its first word.
pub(crate) fn sniff_text(text: &str) -> bool {
    const KEYWORDS: [&str; 9] = [
        "CRYSTAL",
        "MOLECULE",
        "SLAB",
        "POLYMER",
        "PRIMVEC",
        "ATOMS",
        "BEGIN_BLOCK_DATAGRID_3D",
        "BEGIN_BLOCK_BANDGRID_3D",
        "BEGIN_INFO",
    ];
    let mut lines = whole_lines(text)
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'));
    lines
        .next()
        .is_some_and(|l| KEYWORDS.contains(&l.split_whitespace().next().unwrap_or("")))
}

/// One grid's header.
struct Grid {
    name: String,
    bands: Option<usize>,
    n: [usize; 3],
    origin: DVec3,
    spans: [DVec3; 3],
}

/// The grid read: its header and the chosen band's values.
struct Chosen {
    grid: Grid,
    data: Vec<f32>,
}

/// Reads the XSF or BXSF file at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let opened = open_unpacked(path)?;
    let mut info = FileInfo::new("decimal text");
    info.notes.extend(opened.note());
    let len = opened.len;
    let size = opened.size_phrase();
    let mut r = TextReader::new(path, opened.reader);
    let frame = opts.frame.unwrap_or(0);

    let mut names: Vec<String> = Vec::new();
    let mut chosen: Option<Chosen> = None;
    let mut crystal = false;
    while let Some(line) = r.try_line()? {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let up = t.to_ascii_uppercase();
        let grid_name = |keyword: &str| {
            ["BEGIN_", ""].iter().find_map(|begin| {
                let rest = up.strip_prefix(begin)?.strip_prefix(keyword)?;
                // The name keeps the file's case.
                let name = &t[t.len() - rest.len()..];
                Some(name.trim_start_matches('_').trim().to_string())
            })
        };
        let (name, band) = if let Some(name) = grid_name("DATAGRID_3D") {
            (name, false)
        } else if let Some(name) = grid_name("BANDGRID_3D") {
            (name, true)
        } else {
            if up == "PRIMVEC" {
                crystal = true;
                for n in 1..=3 {
                    let v = r.line(&format!("PRIMVEC vector {n}"))?;
                    info.header
                        .push((format!("PRIMVEC {n}"), v.trim().to_string()));
                }
            } else if up.starts_with("FERMI ENERGY") {
                let value = t.split(':').nth(1).unwrap_or("").trim();
                info.header.push(("Fermi Energy".into(), value.to_string()));
            } else if up.starts_with("BEGIN_DATAGRID_2D") || up.starts_with("DATAGRID_2D") {
                skip_to(&mut r, "END_DATAGRID_2D")?;
                info.notes
                    .push("a 2-D data grid in the file was skipped".into());
            }
            continue;
        };
        let name = if name.is_empty() {
            format!("grid {}", names.len() + 1)
        } else {
            name
        };
        let grid = grid_header(&mut r, name.clone(), band, len, &size)?;
        let wanted = match &opts.array {
            Some(a) => *a == name,
            None => chosen.is_none(),
        };
        names.push(name);
        let end = if band {
            "END_BANDGRID_3D"
        } else {
            "END_DATAGRID_3D"
        };
        if !wanted || chosen.is_some() {
            skip_to(&mut r, end)?;
            continue;
        }
        let data = grid_values(path, &mut r, &grid, frame, opts.max_memory)?;
        // The grid ends here: no value may follow its count.
        let next = loop {
            match r.try_line()? {
                Some(l) if l.trim().is_empty() => continue,
                other => break other,
            }
        };
        match next {
            Some(l) if l.trim().to_ascii_uppercase().starts_with(end) => {}
            other => {
                return Err(r.error(format!(
                    "\"{}\" where {end} should end the grid \"{}\" after its {} x {} x {} values",
                    other.as_deref().unwrap_or("the end of the file").trim(),
                    grid.name,
                    grid.n[0],
                    grid.n[1],
                    grid.n[2]
                )));
            }
        }
        chosen = Some(Chosen { grid, data });
    }

    let Some(Chosen { grid, data }) = chosen else {
        return Err(match &opts.array {
            Some(a) => IoError::no_such_array(
                path,
                a,
                if names.is_empty() {
                    "the file holds no 3-D data grid".to_string()
                } else {
                    format!("the file holds the grids {}", quoted(&names))
                },
            ),
            None => IoError::invalid(
                path,
                "no 3-D data grid (BEGIN_BLOCK_DATAGRID_3D ... BEGIN_DATAGRID_3D_name) in the file",
            ),
        });
    };
    info.arrays = names.clone();
    info.array = Some(grid.name.clone());
    if names.len() > 1 {
        info.notes.push(format!(
            "read the grid \"{}\" ({}) of the {} the file holds: {} (pick one with --array)",
            grid.name,
            if opts.array.is_some() {
                "the one asked for"
            } else {
                "the first"
            },
            names.len(),
            quoted(&names)
        ));
    }
    if let Some(bands) = grid.bands {
        info.frames = bands;
        info.frame = frame;
        info.notes.push(format!(
            "frame {frame} is band {} of the {bands} the band grid holds; the grid is in reciprocal space (1/angstrom)",
            frame + 1
        ));
    } else {
        info.length_unit = Some("angstrom".into());
    }
    info.header.push(("grid".into(), grid.name.clone()));
    info.header.push((
        "points".into(),
        format!("{} {} {}", grid.n[0], grid.n[1], grid.n[2]),
    ));
    info.header.push(("origin".into(), vec3_text(grid.origin)));
    for (a, s) in grid.spans.iter().enumerate() {
        info.header
            .push((format!("spanning vector {}", a + 1), vec3_text(*s)));
    }

    // Point i of n at i/(n-1) of the spanning vector.
    let steps = [0, 1, 2].map(|a| grid.spans[a] / (grid.n[a].max(2) - 1) as f64);
    let unit = if grid.bands.is_some() {
        "1/angstrom"
    } else {
        "angstrom"
    };
    let volume = if !periodic_cell::is_skewed(steps) {
        grid_to_volume(path, grid.n, data, steps, grid.origin, &mut info)?
    } else if crystal && grid.n.iter().all(|&n| n >= 3) {
        // One period: the last point of each axis repeats the first.
        let dims = grid.n.map(|n| n - 1);
        let [nx, ny, _] = grid.n;
        let cell: Vec<f32> = (0..dims[2])
            .flat_map(|k| (0..dims[1]).flat_map(move |j| (0..dims[0]).map(move |i| (i, j, k))))
            .map(|(i, j, k)| data[i + nx * (j + ny * k)])
            .collect();
        let (volume, note) = periodic_cell::resample(
            dims,
            &cell,
            steps,
            grid.origin,
            ["vector 1", "vector 2", "vector 3"],
            unit,
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "spanning vectors"))?;
        info.notes.push(format!(
            "{note} (the grid's last point on each axis repeats its first, so {} x {} x {} points make the cell)",
            dims[0], dims[1], dims[2]
        ));
        volume
    } else {
        let (volume, note) = periodic_cell::resample_sheared(
            grid.n,
            &data,
            steps,
            grid.origin,
            ["vector 1", "vector 2", "vector 3"],
            unit,
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "spanning vectors"))?;
        info.notes.push(note);
        info.nan_is_empty = true;
        volume
    };
    Ok(Loaded {
        volume,
        format: VolumeFormat::Xsf,
        info,
    })
}

/// A grid's header: the band count of a band grid, the point counts, the
/// origin and the spanning vectors; the counts bounded by what `len`
/// bytes of text can hold (`size` says it in messages).
fn grid_header<R: BufRead>(
    r: &mut TextReader<R>,
    name: String,
    band: bool,
    len: u64,
    size: &str,
) -> Result<Grid, IoError> {
    let bands = if band {
        let line = r.line("the band count")?;
        let n = integer(line.trim(), "band count").map_err(|e| r.error(e))?;
        if n < 1 || n as u64 > len / 4 {
            return Err(r.error(format!("band count {n}: not a count a {size} can hold")));
        }
        Some(n as usize)
    } else {
        None
    };
    let line = r.line("the point counts nx ny nz")?;
    let words: Vec<&str> = line.split_whitespace().collect();
    if words.len() != 3 {
        return Err(r.error(format!(
            "expected the point counts nx ny nz, found \"{}\"",
            line.trim()
        )));
    }
    let mut n = [0usize; 3];
    for (a, w) in words.iter().enumerate() {
        let v = integer(w, "point count").map_err(|e| r.error(e))?;
        if v < 1 {
            return Err(r.error(format!(
                "point count {v}: a grid has at least 1 point per axis"
            )));
        }
        n[a] = usize::try_from(v).map_err(|_| r.error(format!("point count {v}")))?;
    }
    let points = n.iter().try_fold(1u64, |p, &v| p.checked_mul(v as u64));
    let values = points.and_then(|p| p.checked_mul(bands.unwrap_or(1) as u64));
    if values.is_none_or(|v| v > len / 2 + 1) {
        return Err(r.error(format!(
            "the grid {} x {} x {}{} holds more values than a {size} can hold",
            n[0],
            n[1],
            n[2],
            bands.map_or(String::new(), |b| format!(" of {b} bands"))
        )));
    }
    let mut vectors = [DVec3::ZERO; 4];
    for (k, v) in vectors.iter_mut().enumerate() {
        let what = if k == 0 {
            "the origin".to_string()
        } else {
            format!("spanning vector {k}")
        };
        let line = r.line(&what)?;
        match all_numbers(&line) {
            Some(x) if x.len() == 3 => *v = DVec3::new(x[0], x[1], x[2]),
            _ => {
                return Err(r.error(format!(
                    "{what}: expected three numbers, found \"{}\"",
                    line.trim()
                )));
            }
        }
    }
    Ok(Grid {
        name,
        bands,
        n,
        origin: vectors[0],
        spans: [vectors[1], vectors[2], vectors[3]],
    })
}

/// The values of `grid` (of band `frame` in a band grid), within
/// `max_memory`.
fn grid_values<R: BufRead>(
    path: &Path,
    r: &mut TextReader<R>,
    grid: &Grid,
    frame: usize,
    max_memory: u64,
) -> Result<Vec<f32>, IoError> {
    let bands = grid.bands.unwrap_or(1);
    if frame >= bands {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            match grid.bands {
                Some(b) => format!(
                    "the band grid \"{}\" holds {b} band(s) (frames 0 to {})",
                    grid.name,
                    b - 1
                ),
                None => format!("the data grid \"{}\" holds one volume (frame 0)", grid.name),
            },
        ));
    }
    let count = check_dims(path, "nx ny nz", &grid.n, F32_BYTES, max_memory)?;
    let mut data = Vec::with_capacity(count);
    for b in 0..bands {
        if grid.bands.is_some() {
            let line = loop {
                let l = r.line(&format!("BAND: {}", b + 1))?;
                if !l.trim().is_empty() {
                    break l;
                }
            };
            if !line.trim().to_ascii_uppercase().starts_with("BAND") {
                return Err(r.error(format!(
                    "\"{}\" where \"BAND: {}\" should start band {}",
                    line.trim(),
                    b + 1,
                    b + 1
                )));
            }
        }
        let keep = b == frame;
        let what = format!("the grid \"{}\"", grid.name);
        r.tokens(count, &what, |i, t| {
            if t.to_ascii_uppercase().starts_with("END") {
                return Err(format!("{t} after {i} of the {count} values of {what}"));
            }
            let v = number(t, "grid value")?;
            if keep {
                data.push(v as f32);
            }
            Ok(())
        })?;
        r.finish_line(&format!("the {count} values of {what}"))?;
    }
    Ok(data)
}

/// Skips lines up to and including the one starting with `end`.
fn skip_to<R: BufRead>(r: &mut TextReader<R>, end: &str) -> Result<(), IoError> {
    loop {
        let line = r.line(end)?;
        if line.trim().to_ascii_uppercase().starts_with(end) {
            return Ok(());
        }
    }
}

fn quoted(names: &[String]) -> String {
    names
        .iter()
        .map(|n| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

fn vec3_text(v: DVec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sniffer_knows_xsf_keywords() {
        assert!(sniff_text("CRYSTAL\nPRIMVEC\n"));
        assert!(sniff_text("# made by pp.x\n\n BEGIN_BLOCK_DATAGRID_3D\n"));
        assert!(sniff_text(" BEGIN_INFO\n"));
        assert!(!sniff_text("object 1 class gridpositions counts 2 2 2\n"));
        assert!(!sniff_text("CRYSTALS\n"));
    }
}
