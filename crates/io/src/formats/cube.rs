//! Gaussian cube files (`.cube`, `.cub`): volumetric data of quantum
//! chemistry codes (Gaussian's cubegen, ORCA, CP2K, Quantum ESPRESSO,
//! ASE), read with volray's own parser.
//!
//! The layout (Gaussian's cubegen documentation; P. Bourke, "Gaussian
//! cube files"):
//!
//! ```text
//! comment line 1
//! comment line 2
//! NAtoms  X0 Y0 Z0  [NVal]        origin; NVal values per point (default 1)
//! N1  X1 Y1 Z1                    points and step along axis 1 (slowest)
//! N2  X2 Y2 Z2
//! N3  X3 Y3 Z3                    axis 3 runs fastest
//! Z  charge  x y z                |NAtoms| atom lines
//! [M  MO1 MO2 ... MOM]            only if NAtoms < 0: the orbitals stored
//! values ...                      for i1, for i2, for i3, for each value per point
//! ```
//!
//! N > 0 means lengths in bohr, N < 0 in ångström; volray keeps the
//! file's unit and says which in [`FileInfo::length_unit`]. Several values
//! per point (orbitals, or NVal > 1) are frames: `--frame` picks one,
//! counted from 0, and a note names its orbital number. Axis 3 is volray's
//! index axis 0; `grid_to_volume` turns the axes to world x, y, z.
//! Skewed axes (crystal cells written by periodic codes) are resampled as
//! one periodic cell (see [`crate::shared::periodic_cell`]).

use std::path::Path;

use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::{F32_BYTES, check_dims};
use crate::shared::packed::open_unpacked;
use crate::shared::periodic_cell;
use crate::shared::text_reader::{TextReader, all_numbers, integer, number, whole_lines};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Atom lines listed one by one in [`FileInfo::header`]; the rest are counted.
const LISTED_ATOMS: usize = 32;

/// Whether a file's first bytes (`text`) open as a cube file: two comment
/// lines, the atom count (an integer) and the origin (three numbers,
/// maybe NVal), three axis lines of a non-zero point count and a non-zero
/// step vector; then, as far as the window reaches, one line per atom of
/// five numbers. The lines up to the third axis must be within the window.
pub(crate) fn sniff_text(text: &str) -> bool {
    let mut lines = whole_lines(text).skip(2);
    // Every token of a header line a number, the first an integer.
    let mut header = |len: std::ops::RangeInclusive<usize>| {
        let line = lines.next()?;
        let values = all_numbers(line).filter(|v| len.contains(&v.len()))?;
        let first = line.split_whitespace().next()?.parse::<i64>().ok()?;
        Some((first, values))
    };
    let Some((atoms, _)) = header(4..=5) else {
        return false;
    };
    for _ in 0..3 {
        match header(4..=4) {
            Some((n, v)) if n != 0 && v[1..].iter().any(|&x| x != 0.0) => {}
            _ => return false,
        }
    }
    // From here on the window may end.
    lines
        .take(atoms.unsigned_abs().min(1 << 20) as usize)
        .all(|l| all_numbers(l).is_some_and(|v| v.len() == 5))
}

/// Reads the cube file at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let opened = open_unpacked(path)?;
    let mut info = FileInfo::new("decimal text");
    info.notes.extend(opened.note());
    let file_len = opened.len;
    let size = opened.size_phrase();
    let mut r = TextReader::new(path, opened.reader);
    let invalid = |reason: String| IoError::invalid(path, reason);

    for n in 1..=2 {
        let comment = r.line(&format!("comment line {n}"))?;
        info.header
            .push((format!("comment {n}"), comment.trim().to_string()));
    }

    // NAtoms, origin and the optional NVal.
    let line = r.line("the atom count and origin")?;
    let fields: Vec<&str> = line.split_whitespace().collect();
    if fields.len() < 4 {
        return Err(r.error(format!(
            "expected the atom count and three origin coordinates, found \"{}\"",
            line.trim()
        )));
    }
    let natoms = integer(fields[0], "NAtoms").map_err(|e| r.error(e))?;
    let mut origin = DVec3::ZERO;
    for a in 0..3 {
        origin[a] = number(fields[1 + a], "origin").map_err(|e| r.error(e))?;
    }
    let nval = match fields.get(4) {
        Some(t) => {
            let v = integer(t, "NVal").map_err(|e| r.error(e))?;
            if v < 1 {
                return Err(r.error(format!("NVal {v}: must be at least 1")));
            }
            Some(v as u64)
        }
        None => None,
    };
    if fields.len() > 5 {
        info.notes.push(format!(
            "line 3 has {} fields after NAtoms, origin and NVal; ignored",
            fields.len() - 5
        ));
    }
    info.header.push(("NAtoms".into(), natoms.to_string()));
    info.header.push((
        "origin".into(),
        format!("{} {} {}", fields[1], fields[2], fields[3]),
    ));
    if let Some(v) = nval {
        info.header.push(("NVal".into(), v.to_string()));
    }

    // The three axes: point count and step; the count's sign is the unit.
    let mut counts = [0usize; 3];
    let mut steps = [DVec3::ZERO; 3];
    let mut bohr = [false; 3];
    for a in 0..3 {
        let line = r.line(&format!("axis line {}", a + 1))?;
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.len() < 4 {
            return Err(r.error(format!(
                "axis {}: expected a point count and a step vector, found \"{}\"",
                a + 1,
                line.trim()
            )));
        }
        let n = integer(fields[0], &format!("N{}", a + 1)).map_err(|e| r.error(e))?;
        if n == 0 {
            return Err(r.error(format!("N{}: 0 points", a + 1)));
        }
        bohr[a] = n > 0;
        counts[a] = usize::try_from(n.unsigned_abs()).map_err(|_| {
            r.error(format!(
                "N{}: {n} points is more than this machine can address",
                a + 1
            ))
        })?;
        for c in 0..3 {
            steps[a][c] =
                number(fields[1 + c], &format!("axis {} step", a + 1)).map_err(|e| r.error(e))?;
        }
        info.header.push((
            format!("axis {}", a + 1),
            format!("{} {} {} {}", fields[0], fields[1], fields[2], fields[3]),
        ));
    }
    let unit = match bohr {
        [true, true, true] => "bohr",
        [false, false, false] => "angstrom",
        _ => {
            return Err(invalid(format!(
                "axis point counts have mixed signs ({}): a positive count means bohr, a negative one ångström, and one file uses one unit",
                (0..3)
                    .map(|a| format!("N{} {}", a + 1, if bohr[a] { "> 0" } else { "< 0" }))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
    };
    info.length_unit = Some(unit.to_string());
    info.notes.push(format!(
        "spacing and origin are in {unit}, as the file gives them ({} point counts); not converted",
        if unit == "bohr" {
            "positive"
        } else {
            "negative"
        }
    ));
    if let Some(&n) = counts.iter().find(|&&n| n < 2) {
        return Err(invalid(format!(
            "the axes have {}x{}x{} points (N1 x N2 x N3): an axis with {n} point cannot span a volume",
            counts[0], counts[1], counts[2]
        )));
    }

    // Atom lines: Z, charge, position.
    let atom_count = natoms.unsigned_abs();
    for n in 1..=atom_count {
        let line = r.line(&format!("atom line {n} of {atom_count}"))?;
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.len() < 5 {
            return Err(r.error(format!(
                "atom {n}: expected atomic number, charge and position, found \"{}\"",
                line.trim()
            )));
        }
        let mut values = [0.0; 5];
        for (v, t) in values.iter_mut().zip(&fields) {
            *v = number(t, &format!("atom {n}")).map_err(|e| r.error(e))?;
        }
        if n as usize <= LISTED_ATOMS {
            info.header.push((
                format!("atom {n}"),
                format!(
                    "Z {} charge {} at ({}, {}, {})",
                    fields[0], fields[1], fields[2], fields[3], fields[4]
                ),
            ));
        }
    }
    if atom_count as usize > LISTED_ATOMS {
        info.header.push((
            "atoms not listed".into(),
            format!("{}", atom_count as usize - LISTED_ATOMS),
        ));
    }

    // Negative NAtoms: the orbital list (count, then the orbital numbers,
    // over as many lines as it takes).
    let mut orbitals: Vec<i64> = Vec::new();
    if natoms < 0 {
        let mut m = 0u64;
        r.tokens(1, "the orbital count (DSET_IDS)", |_, t| {
            let v = integer(t, "orbital count (DSET_IDS)")?;
            if v < 1 {
                return Err(format!("orbital count (DSET_IDS) {v}: must be at least 1"));
            }
            m = v as u64;
            Ok(())
        })?;
        if m > file_len / 2 {
            return Err(r.error(format!(
                "orbital count (DSET_IDS) {m} is more than a {size} can list"
            )));
        }
        orbitals.reserve(m as usize);
        r.tokens(m as usize, "the orbital numbers (DSET_IDS)", |_, t| {
            orbitals.push(integer(t, "orbital number (DSET_IDS)")?);
            Ok(())
        })?;
        r.finish_line("the orbital numbers (DSET_IDS)")?;
        let ids: Vec<String> = orbitals.iter().map(|o| o.to_string()).collect();
        info.header
            .push(("DSET_IDS".into(), format!("{m}: {}", ids.join(" "))));
        if let Some(v) = nval
            && v > 1
            && v != m
        {
            return Err(invalid(format!(
                "NVal {v} but the DSET_IDS line lists {m} orbitals: the values per point are unclear"
            )));
        }
    }
    let per_point = if natoms < 0 {
        orbitals.len()
    } else {
        nval.unwrap_or(1) as usize
    };

    // The grid: check the declared size against the file before allocating.
    let points = counts[0]
        .checked_mul(counts[1])
        .and_then(|n| n.checked_mul(counts[2]));
    let total = points.and_then(|n| n.checked_mul(per_point));
    let (points, total) = match (points, total) {
        (Some(p), Some(t)) if (t as u64) <= file_len / 2 + 1 => (p, t),
        _ => {
            return Err(invalid(format!(
                "the header declares {}x{}x{} points with {per_point} value(s) each, more than a {size} can hold",
                counts[0], counts[1], counts[2]
            )));
        }
    };
    let frame = opts.frame.unwrap_or(0);
    if frame >= per_point {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the file holds {per_point} {} per point (frames 0 to {})",
                if natoms < 0 { "orbital(s)" } else { "value(s)" },
                per_point - 1
            ),
        ));
    }
    info.frames = per_point;
    info.frame = frame;
    if natoms < 0 {
        info.notes.push(format!(
            "frame {frame} of {per_point} is molecular orbital {} (the DSET_IDS line lists orbitals {})",
            orbitals[frame],
            orbitals
                .iter()
                .map(|o| o.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    } else if per_point > 1 {
        info.notes.push(format!(
            "frame {frame} is value {} of the {per_point} stored per point (NVal)",
            frame + 1
        ));
    }

    check_dims(path, "N1 x N2 x N3", &counts, F32_BYTES, opts.max_memory)?;
    let mut data = Vec::with_capacity(points);
    r.tokens(total, "the grid", |i, t| {
        if i % per_point == frame {
            data.push(number(t, "grid value")? as f32);
        }
        Ok(())
    })?;
    r.expect_end(&format!("the {total} grid values the header declares"))?;

    // Axis 3 runs fastest: it is volray's index axis 0.
    let dims = [counts[2], counts[1], counts[0]];
    let steps = [steps[2], steps[1], steps[0]];
    let volume = if periodic_cell::is_skewed(steps) {
        let (volume, note) = periodic_cell::resample(
            dims,
            &data,
            steps,
            origin,
            ["axis 3", "axis 2", "axis 1"],
            unit,
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "axis steps"))?;
        info.notes.push(note);
        volume
    } else {
        grid_to_volume(path, dims, data, steps, origin, &mut info)?
    };
    Ok(Loaded {
        volume,
        format: VolumeFormat::Cube,
        info,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str, frame: Option<usize>) -> Result<Loaded, IoError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.cube");
        std::fs::write(&path, text).unwrap();
        let opts = ReadOptions {
            frame,
            ..ReadOptions::default()
        };
        read(&path, &opts)
    }

    const HEAD: &str = "c1\nc2\n    1 0.0 0.0 0.0\n    2 1.0 0.0 0.0\n    2 0.0 1.0 0.0\n    2 0.0 0.0 1.0\n    1 1.0 0.0 0.0 0.0\n";

    #[test]
    fn smallest_file_reads_with_axis_3_fastest() {
        let text = format!("{HEAD}0 1 2 3 4 5 6 7\n");
        let l = read_text(&text, None).unwrap();
        // Value n = i3 + 2·i2 + 4·i1 sits at world (i1, i2, i3).
        for n in 0..8usize {
            let (i3, i2, i1) = (n % 2, (n / 2) % 2, n / 4);
            assert_eq!(l.volume.get(i1, i2, i3), n as f32);
        }
        assert_eq!(l.info.length_unit.as_deref(), Some("bohr"));
        assert_eq!(l.info.frames, 1);
    }

    #[test]
    fn malformed_headers_name_line_and_field() {
        let cases: [(&str, &str); 8] = [
            (
                "c1\nc2\n",
                "file ends at line 3 where the atom count and origin should be",
            ),
            (
                "c1\nc2\n 1 0 0\n",
                "line 3: expected the atom count and three origin coordinates",
            ),
            (
                "c1\nc2\n x 0 0 0\n",
                "line 3: NAtoms: \"x\" is not an integer",
            ),
            ("c1\nc2\n 1 0 0 0 0\n", "line 3: NVal 0: must be at least 1"),
            ("c1\nc2\n 1 0 0 0\n 0 1 0 0\n", "line 4: N1: 0 points"),
            (
                "c1\nc2\n 1 0 0 0\n 2 1 0 0\n -2 0 1 0\n 2 0 0 1\n",
                "mixed signs (N1 > 0, N2 < 0, N3 > 0)",
            ),
            (
                "c1\nc2\n 1 0 0 0\n 1 1 0 0\n 2 0 1 0\n 2 0 0 1\n",
                "an axis with 1 point cannot span a volume",
            ),
            (
                "c1\nc2\n 2 0 0 0\n 2 1 0 0\n 2 0 1 0\n 2 0 0 1\n 1 0 0 0 0\n 1 0 0 0\n",
                "line 8: atom 2: expected atomic number, charge and position",
            ),
        ];
        for (text, want) in cases {
            let err = read_text(text, None).unwrap_err();
            assert!(!err.is_io_failure());
            let msg = err.to_string();
            assert!(msg.contains(want), "{msg}\nwanted: {want}");
            assert!(!msg.contains('\n'));
        }
    }

    #[test]
    fn lying_sizes_and_bad_data_are_refused_before_or_while_reading() {
        let huge = "c1\nc2\n 0 0 0 0\n 100000 1 0 0\n 100000 0 1 0\n 100000 0 0 1\n1\n";
        let err = read_text(huge, None).unwrap_err().to_string();
        assert!(
            err.contains("100000x100000x100000 points with 1 value(s) each, more than"),
            "{err}"
        );
        let overflow = format!(
            "c1\nc2\n 0 0 0 0\n {n} 1 0 0\n {n} 0 1 0\n {n} 0 0 1\n1\n",
            n = i64::MAX
        );
        assert!(read_text(&overflow, None).is_err());
        let short = format!("{HEAD}0 1 2 3 4 5 6\n");
        let err = read_text(&short, None).unwrap_err().to_string();
        assert!(err.contains("after 7 of the 8 values of the grid"), "{err}");
        let long = format!("{HEAD}0 1 2 3 4 5 6 7 8\n");
        let err = read_text(&long, None).unwrap_err().to_string();
        assert!(
            err.contains("line 8: \"8\" follows the last of the 8 grid values"),
            "{err}"
        );
        let bad = format!("{HEAD}0 1 2 3 4 5 6 seven\n");
        let err = read_text(&bad, None).unwrap_err().to_string();
        assert!(err.contains("line 8: grid value: \"seven\""), "{err}");
        let err = read_text(&format!("{HEAD}0 1 2 3 4 5 6 7\n"), Some(1)).unwrap_err();
        assert!(
            err.to_string().contains(
                "frame 1 is out of range: the file holds 1 value(s) per point (frames 0 to 0)"
            ),
            "{err}"
        );
        assert!(matches!(err, IoError::FrameOutOfRange { frame: 1, .. }));
    }

    #[test]
    fn nval_values_per_point_are_frames() {
        let head = "c1\nc2\n 0 0 0 0 2\n 2 1 0 0\n 2 0 1 0\n 2 0 0 1\n";
        let values: Vec<String> = (0..8)
            .flat_map(|n| [n, 100 + n])
            .map(|v| v.to_string())
            .collect();
        let text = format!("{head}{}\n", values.join(" "));
        let l = read_text(&text, Some(1)).unwrap();
        assert_eq!(l.info.frames, 2);
        assert_eq!(l.volume.get(1, 1, 1), 107.0);
        assert!(l.info.notes.iter().any(|n| n.contains("value 2 of the 2")));
        let text = format!("{}\n", &text.replace(" 0 0 0 0 2\n", " 0 0 0 0 3\n"));
        let err = read_text(&text, None).unwrap_err().to_string();
        assert!(
            err.contains("after 16 of the 24 values of the grid"),
            "{err}"
        );
    }

    #[test]
    fn dset_ids_must_agree_with_nval() {
        let text = "c1\nc2\n -1 0 0 0 3\n 2 1 0 0\n 2 0 1 0\n 2 0 0 1\n 1 1 0 0 0\n 2 5 6\n";
        let err = read_text(text, None).unwrap_err().to_string();
        assert!(
            err.contains("NVal 3 but the DSET_IDS line lists 2 orbitals"),
            "{err}"
        );
        let text = "c1\nc2\n -1 0 0 0\n 2 1 0 0\n 2 0 1 0\n 2 0 0 1\n 1 1 0 0 0\n 0\n";
        let err = read_text(text, None).unwrap_err().to_string();
        assert!(
            err.contains("orbital count (DSET_IDS) 0: must be at least 1"),
            "{err}"
        );
    }
}
