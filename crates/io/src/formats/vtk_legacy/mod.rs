//! Legacy VTK files (`.vtk`, "# vtk DataFile Version 2.0" to "5.1") holding
//! `DATASET STRUCTURED_POINTS`, ASCII or BINARY (big-endian, as the VTK
//! file-format document specifies and vtkDataWriter writes).
//!
//! The grid is `DIMENSIONS`, `SPACING` (or its old name `ASPECT_RATIO`) and
//! `ORIGIN`. Its `POINT_DATA` and `CELL_DATA` sections hold attribute
//! arrays (`SCALARS`, `VECTORS`, `FIELD` arrays, ...), read the way
//! vtkDataReader reads them: keywords are case-insensitive, array names
//! are %XX-encoded, BINARY data starts after the line that announces it,
//! and an array may be followed by a `METADATA` block (VTK 8.1+) that ends
//! at a blank line. Which array becomes the volume is decided in
//! [`crate::shared::vtk_arrays`]: `--array NAME`, or the point `SCALARS`.
//!
//! The file is read once, as a stream: every array's size is checked
//! against the bytes left in the file before anything is allocated, arrays
//! that are not wanted are skipped (seeked over when binary), and at most
//! the best candidate so far is kept in memory.

mod attributes;
mod lexer;
mod values;

use std::path::Path;

use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::packed::open_unpacked;
use crate::shared::vtk_arrays::{
    Association, cell_centres, cell_dims, no_match, not_scalar, record_choice,
};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};
use attributes::{Scan, attribute, field_array};
use lexer::Lexer;
use values::{Encoding, array_values};

/// Reads the legacy VTK file at `path` (see the module documentation).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let opened = open_unpacked(path)?;
    let mut info = FileInfo::new("");
    info.notes.extend(opened.note());
    let mut lx = Lexer::new(path, opened.reader, opened.len);

    let first = lx.line()?.unwrap_or_default();
    let version = first
        .strip_prefix("# vtk DataFile Version")
        .ok_or_else(|| {
            IoError::invalid(
                path,
                format!(
                    "first line is \"{}\": a legacy VTK file starts with \"# vtk DataFile Version x.y\"",
                    first.chars().take(60).collect::<String>()
                ),
            )
        })?
        .trim()
        .to_string();
    info.header.push(("version".into(), version));
    let title = lx.line()?.ok_or_else(|| {
        IoError::invalid(
            path,
            "file ends after the first line, where the title should be",
        )
    })?;
    info.header.push(("title".into(), title));
    let file_type = lx.expect("the file type (ASCII or BINARY)")?;
    let encoding = match file_type.to_ascii_lowercase().as_str() {
        "ascii" => Encoding::Ascii,
        "binary" => Encoding::Binary,
        _ => {
            return Err(IoError::invalid(
                path,
                format!("file type (third line) is \"{file_type}\": expected ASCII or BINARY"),
            ));
        }
    };
    info.header.push(("file type".into(), file_type));
    let keyword = lx.expect("DATASET")?;
    if !keyword.eq_ignore_ascii_case("dataset") {
        return Err(IoError::invalid(
            path,
            format!("expected DATASET after the file type, found \"{keyword}\""),
        ));
    }
    let dataset = lx.expect("the dataset type")?;
    if !dataset.eq_ignore_ascii_case("structured_points") {
        return Err(IoError::invalid(
            path,
            format!(
                "DATASET {dataset}: volray reads STRUCTURED_POINTS (image data) only, not other legacy VTK datasets"
            ),
        ));
    }
    info.header.push(("DATASET".into(), dataset));

    let mut dims: Option<[usize; 3]> = None;
    let mut spacing = DVec3::ONE;
    let mut origin = DVec3::ZERO;
    let mut section: Option<(Association, usize)> = None;
    let mut scalars_seen = [false; 2];
    let mut scan = Scan {
        request: opts.array.as_deref(),
        entries: Vec::new(),
        tuples: Vec::new(),
        best: None,
        types: Vec::new(),
        max_memory: opts.max_memory,
    };

    while let Some(word) = lx.next_token()? {
        let key = word.to_ascii_lowercase();
        match key.as_str() {
            "dimensions" if section.is_none() => {
                let mut d = [0usize; 3];
                for n in &mut d {
                    *n = lx.number("DIMENSIONS")?;
                    if *n == 0 {
                        return Err(IoError::invalid(
                            path,
                            "DIMENSIONS has a 0: every axis needs at least 1 point",
                        ));
                    }
                }
                info.header
                    .push((word, format!("{} {} {}", d[0], d[1], d[2])));
                dims = Some(d);
            }
            "spacing" | "aspect_ratio" if section.is_none() => {
                spacing = vec3(&mut lx, &word)?;
                if !(spacing.is_finite()
                    && spacing.x != 0.0
                    && spacing.y != 0.0
                    && spacing.z != 0.0)
                {
                    return Err(IoError::invalid(
                        path,
                        format!(
                            "{word} {} {} {}: spacings must be finite and non-zero",
                            spacing.x, spacing.y, spacing.z
                        ),
                    ));
                }
                info.header
                    .push((word, format!("{} {} {}", spacing.x, spacing.y, spacing.z)));
            }
            "origin" if section.is_none() => {
                origin = vec3(&mut lx, &word)?;
                info.header
                    .push((word, format!("{} {} {}", origin.x, origin.y, origin.z)));
            }
            "point_data" | "cell_data" => {
                let Some(d) = dims else {
                    return Err(IoError::invalid(
                        path,
                        format!("{word} comes before DIMENSIONS"),
                    ));
                };
                let n: usize = lx.number(&word)?;
                let (assoc, expected) = if key == "point_data" {
                    (
                        Association::Point,
                        d[0].checked_mul(d[1]).and_then(|x| x.checked_mul(d[2])),
                    )
                } else {
                    let c = cell_dims(d);
                    (
                        Association::Cell,
                        c[0].checked_mul(c[1]).and_then(|x| x.checked_mul(c[2])),
                    )
                };
                if Some(n) != expected {
                    return Err(IoError::invalid(
                        path,
                        format!(
                            "{word} {n}, but DIMENSIONS {} {} {} make {} {}s",
                            d[0],
                            d[1],
                            d[2],
                            expected.map_or("too many".to_string(), |e| e.to_string()),
                            assoc.name()
                        ),
                    ));
                }
                info.header.push((word, n.to_string()));
                section = Some((assoc, n));
            }
            "field" if section.is_none() => {
                // Field data of the whole dataset (e.g. TIME): not a grid array.
                let name = lx.expect("the FIELD name")?;
                let count: usize = lx.number("FIELD array count")?;
                info.header.push((word, format!("{name} {count}")));
                for _ in 0..count {
                    if let Some(spec) = field_array(&mut lx, Association::Point, &mut info)? {
                        array_values(&mut lx, encoding, &spec, None)?;
                    }
                }
                info.notes
                    .push(format!("dataset field data \"{name}\" ignored"));
            }
            _ => {
                let Some((assoc, n)) = section else {
                    return Err(IoError::invalid(
                        path,
                        format!(
                            "unexpected \"{word}\" at byte {} in the STRUCTURED_POINTS header",
                            lx.pos()
                        ),
                    ));
                };
                let a = assoc as usize;
                attribute(
                    &mut lx,
                    &word,
                    assoc,
                    n,
                    encoding,
                    &mut scalars_seen[a],
                    &mut scan,
                    &mut info,
                )?;
            }
        }
    }

    let dims = dims.ok_or_else(|| IoError::invalid(path, "no DIMENSIONS in the file"))?;
    let Some(best) = scan.best else {
        return Err(no_match(path, &scan.entries, scan.request));
    };
    let entry = scan.entries[best.index].clone();
    if entry.components != 1 {
        return Err(not_scalar(path, &entry, &scan.entries));
    }
    let Some(data) = best.values else {
        return Err(IoError::invalid(
            path,
            format!(
                "FIELD array \"{}\" has {} tuples, not one per {} of the grid",
                entry.name,
                scan.tuples[best.index],
                entry.association.name()
            ),
        ));
    };
    record_choice(&mut info, &scan.entries, &entry, scan.request);
    info.stored_type = format!(
        "{} ({})",
        scan.types[best.index],
        match encoding {
            Encoding::Ascii => "ASCII",
            Encoding::Binary => "big-endian",
        }
    );
    let steps = [
        DVec3::X * spacing.x,
        DVec3::Y * spacing.y,
        DVec3::Z * spacing.z,
    ];
    let (grid, origin) = match entry.association {
        Association::Point => (dims, origin),
        Association::Cell => (
            cell_dims(dims),
            cell_centres(dims, steps, origin, &mut info, &entry.name),
        ),
    };
    let volume = grid_to_volume(path, grid, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::VtkLegacy,
        info,
    })
}

/// Three numbers after a keyword.
fn vec3<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    what: &str,
) -> Result<DVec3, IoError> {
    let x = lx.number(what)?;
    let y = lx.number(what)?;
    let z = lx.number(what)?;
    Ok(DVec3::new(x, y, z))
}
