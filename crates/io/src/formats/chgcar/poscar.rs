//! The POSCAR block that opens every VASP volumetric file (and every
//! image of a CHG file): the cell and the atoms
//! (<https://www.vasp.at/wiki/index.php/POSCAR>).
//!
//! ```text
//! system name
//! scale                  > 0 factor; < 0 target cell volume (Å³); or 3 factors for x, y, z
//! a1 a2 a3               lattice vectors (Å, before scaling)
//! b1 b2 b3
//! c1 c2 c3
//! [Si O]                 species names (VASP 5 and later)
//! 1 2                    atoms per species
//! [Selective dynamics]
//! Direct | Cartesian     (first letter: C or K Cartesian, anything else direct)
//! x y z [T T F]          one line per atom
//! ```

use std::io::BufRead;

use volray_core::glam::{DMat3, DVec3};

use crate::error::IoError;
use crate::shared::text_reader::{TextReader, all_numbers, integer, parse_number, whole_lines};

/// Atom positions listed one by one in the header; the rest are counted.
const LISTED_ATOMS: usize = 32;

/// The cell and what the header said, as read.
#[derive(Debug, Clone)]
pub(super) struct Poscar {
    /// The lattice vectors a, b, c after scaling, in ångström.
    pub lattice: [DVec3; 3],
    /// The cell volume |a · (b × c)|, in Å³.
    pub volume: f64,
    /// The header's fields, as written, for `FileInfo::header`.
    pub header: Vec<(String, String)>,
}

/// Reads a POSCAR block whose first line (the system name) was `system`.
/// `file_len` bounds the atom count before the atom lines are read.
pub(super) fn read<R: BufRead>(
    r: &mut TextReader<R>,
    system: String,
    file_len: u64,
) -> Result<Poscar, IoError> {
    let mut header = vec![("system".to_string(), system.trim().to_string())];

    // Scale: one factor, a target volume, or three factors.
    let line = r.line("the scale factor")?;
    let scale: Vec<f64> = line.split_whitespace().map_while(parse_number).collect();
    if !(scale.len() == 1 || scale.len() == 3) || scale.iter().any(|s| !s.is_finite()) {
        return Err(r.error(format!(
            "scale factor: expected one number or three, found \"{}\"",
            line.trim()
        )));
    }
    if scale.len() == 1 && scale[0] == 0.0 {
        return Err(r.error("scale factor 0"));
    }
    if scale.len() == 3 && scale.iter().any(|&s| s <= 0.0) {
        return Err(r.error(format!(
            "scale factors {} {} {}: three factors must all be positive",
            scale[0], scale[1], scale[2]
        )));
    }
    header.push((
        "scale".into(),
        scale
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join(" "),
    ));

    let mut lattice = [DVec3::ZERO; 3];
    for (v, name) in lattice.iter_mut().zip(["a", "b", "c"]) {
        let line = r.line(&format!("lattice vector {name}"))?;
        let values: Vec<f64> = line
            .split_whitespace()
            .take(3)
            .map_while(parse_number)
            .collect();
        if values.len() < 3 || values.iter().any(|x| !x.is_finite()) {
            return Err(r.error(format!(
                "lattice vector {name}: expected three numbers, found \"{}\"",
                line.trim()
            )));
        }
        *v = DVec3::new(values[0], values[1], values[2]);
        header.push((format!("lattice {name}"), line.trim().to_string()));
    }
    let raw_volume = DMat3::from_cols(lattice[0], lattice[1], lattice[2])
        .determinant()
        .abs();
    match scale[..] {
        [s] if s > 0.0 => lattice = lattice.map(|v| v * s),
        [s] if s < 0.0 => {
            // A negative scale is the cell volume wanted (VASP wiki, POSCAR).
            if raw_volume == 0.0 {
                return Err(r.error("lattice vectors span no volume".to_string()));
            }
            let f = (-s / raw_volume).cbrt();
            lattice = lattice.map(|v| v * f);
        }
        // Three factors scale the x, y and z components (VASP wiki, POSCAR).
        [x, y, z] => lattice = lattice.map(|v| v * DVec3::new(x, y, z)),
        _ => return Err(r.error("scale factor: not one number or three")),
    }
    let volume = DMat3::from_cols(lattice[0], lattice[1], lattice[2])
        .determinant()
        .abs();
    if !(volume.is_finite() && volume > 0.0) {
        return Err(r.error(format!(
            "the lattice vectors span a cell of volume {volume}: they must be independent"
        )));
    }

    // Species names (VASP 5) and counts.
    let mut line = r.line("the atom counts")?;
    let first = line.split_whitespace().next().unwrap_or("");
    if first.parse::<i64>().is_err() {
        header.push(("species".into(), line.trim().to_string()));
        line = r.line("the atom counts")?;
    }
    let counts: Vec<i64> = line
        .split_whitespace()
        .map_while(|t| t.parse::<i64>().ok())
        .collect();
    if counts.is_empty() || counts.iter().any(|&n| n < 0) {
        return Err(r.error(format!(
            "atom counts: expected non-negative integers, found \"{}\"",
            line.trim()
        )));
    }
    header.push(("counts".into(), line.trim().to_string()));
    let natoms: u64 = counts.iter().map(|&n| n as u64).sum();
    // Each atom line holds at least three numbers: "0 0 0\n".
    if natoms > file_len / 6 {
        return Err(r.error(format!(
            "atom counts sum to {natoms}, more atom lines than a {file_len}-byte file can hold"
        )));
    }

    // Selective dynamics, then the coordinate kind.
    let mut line = r.line("the coordinate kind (Direct or Cartesian)")?;
    if line.trim_start().starts_with(['s', 'S']) {
        header.push(("selective dynamics".into(), line.trim().to_string()));
        line = r.line("the coordinate kind (Direct or Cartesian)")?;
    }
    let kind = line.trim();
    if kind.is_empty() {
        return Err(r.error("coordinate kind: expected Direct or Cartesian, found an empty line"));
    }
    header.push(("coordinates".into(), kind.to_string()));

    for n in 1..=natoms {
        let line = r.line(&format!("atom position {n} of {natoms}"))?;
        let fields: Vec<&str> = line.split_whitespace().collect();
        let ok = fields.len() >= 3
            && fields[..3]
                .iter()
                .all(|t| parse_number(t).is_some_and(f64::is_finite));
        if !ok {
            return Err(r.error(format!(
                "atom position {n}: expected three numbers, found \"{}\"",
                line.trim()
            )));
        }
        if n as usize <= LISTED_ATOMS {
            header.push((format!("atom {n}"), fields[..3].join(" ")));
        }
    }
    if natoms as usize > LISTED_ATOMS {
        header.push((
            "atoms not listed".into(),
            (natoms as usize - LISTED_ATOMS).to_string(),
        ));
    }
    Ok(Poscar {
        lattice,
        volume,
        header,
    })
}

/// Whether a file's first bytes (`text`) open with a POSCAR block: a
/// comment, the scale (one number, or three positive ones), three lattice
/// vectors of three numbers, species names (VASP 5) and their counts, an
/// optional `Selective dynamics`, `Direct` or `Cartesian`; then, as far
/// as the window reaches, one position per atom and the grid line of
/// three positive integers. Every line up to the coordinate kind must be
/// within the window.
pub(crate) fn sniff_text(text: &str) -> bool {
    let mut lines = whole_lines(text);
    let mut next = || lines.next();
    let (Some(_comment), Some(scale)) = (next(), next().and_then(all_numbers)) else {
        return false;
    };
    let scale_ok = match scale[..] {
        [s] => s != 0.0,
        [x, y, z] => x > 0.0 && y > 0.0 && z > 0.0,
        _ => false,
    };
    if !scale_ok || !(0..3).all(|_| next().and_then(all_numbers).is_some_and(|v| v.len() == 3)) {
        return false;
    }
    let Some(mut line) = next() else {
        return false;
    };
    let species: Vec<&str> = line.split_whitespace().collect();
    let named = species
        .first()
        .is_some_and(|w| w.starts_with(|c: char| c.is_ascii_alphabetic()));
    if named {
        let name = |w: &&str| {
            w.starts_with(|c: char| c.is_ascii_alphabetic())
                && w.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "_/.-".contains(c))
        };
        match next() {
            Some(counts) if species.iter().all(name) => line = counts,
            _ => return false,
        }
    }
    let counts: Option<Vec<u64>> = line.split_whitespace().map(|t| t.parse().ok()).collect();
    let Some(counts) = counts.filter(|c| !c.is_empty() && (!named || c.len() == species.len()))
    else {
        return false;
    };
    let Some(mut line) = next() else {
        return false;
    };
    if line.trim_start().starts_with(['s', 'S']) {
        match next() {
            Some(kind) => line = kind,
            None => return false,
        }
    }
    if !line
        .trim_start()
        .starts_with(['d', 'D', 'c', 'C', 'k', 'K'])
    {
        return false;
    }
    // From here on the window may end.
    let atoms: u64 = counts.iter().sum();
    for _ in 0..atoms {
        match lines.next() {
            None => return true,
            Some(l) => {
                let coords: Vec<&str> = l.split_whitespace().take(3).collect();
                if coords.len() < 3
                    || !coords
                        .iter()
                        .all(|t| parse_number(t).is_some_and(f64::is_finite))
                {
                    return false;
                }
            }
        }
    }
    match lines.find(|l| !l.trim().is_empty()) {
        None => true,
        Some(grid) => {
            let n: Vec<&str> = grid.split_whitespace().collect();
            n.len() == 3 && n.iter().all(|t| t.parse::<u64>().is_ok_and(|v| v > 0))
        }
    }
}

/// Reads the grid line `NGX NGY NGZ` after the atoms (blank lines before
/// it are skipped), checking the point count against the file's length.
pub(super) fn read_grid_line<R: BufRead>(
    r: &mut TextReader<R>,
    file_len: u64,
) -> Result<([usize; 3], Vec<String>), IoError> {
    let line = loop {
        let line = r.line("the grid size NGX NGY NGZ")?;
        if !line.trim().is_empty() {
            break line;
        }
    };
    let fields: Vec<String> = line.split_whitespace().map(str::to_string).collect();
    if fields.len() != 3 {
        return Err(r.error(format!(
            "grid size: expected NGX NGY NGZ, found \"{}\"",
            line.trim()
        )));
    }
    let mut ng = [0usize; 3];
    for (a, name) in ["NGX", "NGY", "NGZ"].iter().enumerate() {
        let n = integer(&fields[a], name).map_err(|e| r.error(e))?;
        if n < 1 {
            return Err(r.error(format!("{name} {n}: a grid needs at least one point")));
        }
        ng[a] = usize::try_from(n).map_err(|_| r.error(format!("{name} {n}: too large")))?;
    }
    let count = ng[0].checked_mul(ng[1]).and_then(|n| n.checked_mul(ng[2]));
    match count {
        Some(c) if c as u64 <= file_len / 2 + 1 => Ok((ng, fields)),
        _ => Err(r.error(format!(
            "grid size {} x {} x {}: more values than a {file_len}-byte file can hold",
            ng[0], ng[1], ng[2]
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;
    use std::path::Path;

    fn parse(text: &str) -> Result<Poscar, IoError> {
        let mut r = TextReader::new(Path::new("CHGCAR"), Cursor::new(text.as_bytes().to_vec()));
        let system = r.line("system").unwrap();
        read(&mut r, system, 1 << 20)
    }

    #[test]
    fn scale_factor_forms() {
        let body = " 2.0 0.0 0.0\n 0.0 3.0 0.0\n 0.0 0.0 4.0\nSi\n 1\nDirect\n 0 0 0\n";
        let p = parse(&format!("sys\n 1.5\n{body}")).unwrap();
        assert_eq!(p.lattice[1], DVec3::new(0.0, 4.5, 0.0));
        assert!((p.volume - 24.0 * 1.5f64.powi(3)).abs() < 1e-9);
        // A negative scale is the volume: 24 Å³ scaled to 81 Å³.
        let p = parse(&format!("sys\n -81\n{body}")).unwrap();
        assert!((p.volume - 81.0).abs() < 1e-9);
        assert!((p.lattice[0].x - 2.0 * 1.5).abs() < 1e-12);
        // Three factors scale x, y, z components.
        let p = parse(&format!("sys\n 1 2 0.5\n{body}")).unwrap();
        assert_eq!(p.lattice[2], DVec3::new(0.0, 0.0, 2.0));
        assert!((p.volume - 24.0).abs() < 1e-12);
        let err = parse(&format!("sys\n 0\n{body}")).unwrap_err().to_string();
        assert_eq!(err, "CHGCAR: line 2: scale factor 0");
        let err = parse(&format!("sys\n 1 2\n{body}"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("line 2: scale factor: expected one number or three"),
            "{err}"
        );
    }

    #[test]
    fn vasp4_counts_selective_dynamics_and_cartesian() {
        let text = "sys\n1\n 3 0 0\n 0 3 0\n 0 0 3\n 1 1\nSelective dynamics\nCartesian\n 0 0 0 T T F\n 1.5 1.5 1.5 F F F\n";
        let p = parse(text).unwrap();
        let keys: Vec<&str> = p.header.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "system",
                "scale",
                "lattice a",
                "lattice b",
                "lattice c",
                "counts",
                "selective dynamics",
                "coordinates",
                "atom 1",
                "atom 2"
            ]
        );
        assert_eq!(p.header[7].1, "Cartesian");
    }

    #[test]
    fn malformed_blocks_name_line_and_field() {
        let cases = [
            (
                "sys\n1\n 3 0 0\n 0 3\n",
                "line 4: lattice vector b: expected three numbers",
            ),
            (
                "sys\n1\n 1 0 0\n 2 0 0\n 0 0 1\n 1\nDirect\n 0 0 0\n",
                "line 5: the lattice vectors span a cell of volume 0",
            ),
            (
                "sys\n1\n 1 0 0\n 0 1 0\n 0 0 1\nSi\n x\n",
                "line 7: atom counts: expected non-negative integers",
            ),
            (
                "sys\n1\n 1 0 0\n 0 1 0\n 0 0 1\n 99999999\nDirect\n",
                "atom counts sum to 99999999, more atom lines than",
            ),
            (
                "sys\n1\n 1 0 0\n 0 1 0\n 0 0 1\n 2\nDirect\n 0 0 0\n",
                "where atom position 2 of 2 should be",
            ),
            (
                "sys\n1\n 1 0 0\n 0 1 0\n 0 0 1\n 1\nDirect\n 0 zero 0\n",
                "line 8: atom position 1: expected three numbers",
            ),
        ];
        for (text, want) in cases {
            let err = parse(text).unwrap_err().to_string();
            assert!(err.contains(want), "{err}\nwanted: {want}");
        }
    }

    #[test]
    fn grid_line_is_checked_against_the_file() {
        let mut r = TextReader::new(Path::new("CHG"), Cursor::new(b"\n\n 2 3 4\n".to_vec()));
        let (ng, fields) = read_grid_line(&mut r, 100).unwrap();
        assert_eq!(ng, [2, 3, 4]);
        assert_eq!(fields, ["2", "3", "4"]);
        let mut r = TextReader::new(Path::new("CHG"), Cursor::new(b" 200 300 400\n".to_vec()));
        let err = read_grid_line(&mut r, 1000).unwrap_err().to_string();
        assert!(
            err.contains("grid size 200 x 300 x 400: more values than a 1000-byte file"),
            "{err}"
        );
        let mut r = TextReader::new(Path::new("CHG"), Cursor::new(b" 2 0 4\n".to_vec()));
        let err = read_grid_line(&mut r, 1000).unwrap_err().to_string();
        assert!(
            err.contains("line 1: NGY 0: a grid needs at least one point"),
            "{err}"
        );
    }
}
