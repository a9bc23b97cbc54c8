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

mod lexer;

use std::io::BufReader;
use std::path::Path;

use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::dtype::{DType, Endian, extend_f32};
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::open_input;
use crate::shared::limits::{F32_BYTES, check_memory};
use crate::shared::vtk_arrays::{
    ArrayEntry, Association, cell_centres, cell_dims, no_match, not_scalar, rank, record_choice,
};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};
use lexer::Lexer;

/// Samples decoded per read of BINARY data.
const CHUNK_SAMPLES: usize = 1 << 16;

/// The sample types of legacy VTK arrays (vtkDataReader::ReadArray).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SampleType {
    /// One bit per value, packed most significant bit first.
    Bit,
    Number(DType),
}

/// The sample type a legacy type name (case-insensitive) stands for.
/// `long` is 8 bytes, as VTK on 64-bit Linux and macOS reads it;
/// `vtkIdType` is written as 4-byte `int` (vtkDataWriter).
fn sample_type(name: &str) -> Option<SampleType> {
    Some(SampleType::Number(
        match name.to_ascii_lowercase().as_str() {
            "bit" => return Some(SampleType::Bit),
            "char" | "signed_char" => DType::I8,
            "unsigned_char" => DType::U8,
            "short" => DType::I16,
            "unsigned_short" => DType::U16,
            "int" | "vtkidtype" => DType::I32,
            "unsigned_int" => DType::U32,
            "long" | "vtktypeint64" => DType::I64,
            "unsigned_long" | "vtktypeuint64" => DType::U64,
            "float" => DType::F32,
            "double" => DType::F64,
            _ => return None,
        },
    ))
}

impl SampleType {
    /// Bytes of `count` values in a BINARY file.
    fn binary_len(self, count: usize) -> Option<u64> {
        match self {
            SampleType::Bit => Some((count as u64).div_ceil(8)),
            SampleType::Number(d) => (count as u64).checked_mul(d.size() as u64),
        }
    }
}

/// ASCII or BINARY.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Binary,
}

/// One array's description, as its header words give it.
struct ArraySpec {
    entry: ArrayEntry,
    sample: SampleType,
    tuples: usize,
    /// ASCII `COLOR_SCALARS`: floats in [0, 1] that stand for bytes.
    ascii_colour: bool,
}

/// The best array found so far and its values (`None` when it cannot be
/// used: not a scalar, or a FIELD array of the wrong length).
struct Best {
    rank: u8,
    index: usize,
    values: Option<Vec<f32>>,
}

/// What the scan of the attribute sections has found.
struct Scan<'a> {
    request: Option<&'a str>,
    entries: Vec<ArrayEntry>,
    tuples: Vec<usize>,
    best: Option<Best>,
    /// Sample type names of the entries, for `stored_type`.
    types: Vec<String>,
    /// `--max-memory`: the array decoded must fit it.
    max_memory: u64,
}

/// Reads the legacy VTK file at `path` (see the module documentation).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (file, len) = open_input(path)?;
    let mut lx = Lexer::new(path, BufReader::new(file), len);
    let mut info = FileInfo::new("");

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

/// A type name, known or refused.
fn parse_type(path: &Path, name: &str, what: &str) -> Result<SampleType, IoError> {
    sample_type(name).ok_or_else(|| {
        let lower = name.to_ascii_lowercase();
        if matches!(lower.as_str(), "string" | "utf8_string" | "variant") {
            IoError::invalid(
                path,
                format!("{what} holds {name} values: volray reads numeric arrays only"),
            )
        } else {
            IoError::invalid(
                path,
                format!("{what} has data type \"{name}\": not a legacy VTK data type"),
            )
        }
    })
}

/// vtkDataReader::DecodeString: `%XX` stands for the byte 0xXX.
fn decode_name(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Reads one attribute keyword's words and data in a POINT_DATA or
/// CELL_DATA section of `n` tuples.
#[allow(clippy::too_many_arguments)]
fn attribute<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    word: &str,
    assoc: Association,
    n: usize,
    encoding: Encoding,
    scalars_seen: &mut bool,
    scan: &mut Scan,
    info: &mut FileInfo,
) -> Result<(), IoError> {
    let path = lx.path().to_path_buf();
    let section = match assoc {
        Association::Point => "POINT_DATA",
        Association::Cell => "CELL_DATA",
    };
    let key = word.to_ascii_lowercase();
    let spec = match key.as_str() {
        "scalars" => {
            let name = decode_name(&lx.expect("the SCALARS name")?);
            let type_name = lx.expect("the SCALARS data type")?;
            let sample = parse_type(&path, &type_name, &format!("SCALARS \"{name}\""))?;
            let mut next = lx.expect("LOOKUP_TABLE")?;
            let mut components = 1;
            if !next.eq_ignore_ascii_case("lookup_table") {
                components = next
                    .parse()
                    .ok()
                    .filter(|&c: &usize| (1..=64).contains(&c))
                    .ok_or_else(|| {
                        IoError::invalid(
                            &path,
                            format!("SCALARS \"{name}\" has {next} components: expected 1 to 64"),
                        )
                    })?;
                next = lx.expect("LOOKUP_TABLE")?;
            }
            if !next.eq_ignore_ascii_case("lookup_table") {
                return Err(IoError::invalid(
                    &path,
                    format!("SCALARS \"{name}\" is followed by \"{next}\", not LOOKUP_TABLE"),
                ));
            }
            let table = lx.expect("the LOOKUP_TABLE name")?;
            info.header
                .push((word.to_string(), format!("{name} {type_name} {components}")));
            info.header.push(("LOOKUP_TABLE".into(), table));
            let active = !*scalars_seen;
            *scalars_seen = true;
            spec(name, assoc, components, active, type_name, sample, n)
        }
        "color_scalars" => {
            let name = decode_name(&lx.expect("the COLOR_SCALARS name")?);
            let components: usize = lx.number("the COLOR_SCALARS value count")?;
            if !(1..=4).contains(&components) {
                return Err(IoError::invalid(
                    &path,
                    format!(
                        "COLOR_SCALARS \"{name}\" has {components} values per colour: expected 1 to 4"
                    ),
                ));
            }
            info.header
                .push((word.to_string(), format!("{name} {components}")));
            // Colours are bytes: stored as such in BINARY files, as floats
            // in [0, 1] in ASCII ones (vtkDataReader::ReadCoScalarData).
            // VTK writes unsigned_char point scalars this way.
            let sample = match encoding {
                Encoding::Ascii => SampleType::Number(DType::F32),
                Encoding::Binary => SampleType::Number(DType::U8),
            };
            let active = !*scalars_seen;
            *scalars_seen = true;
            let mut s = spec(
                name,
                assoc,
                components,
                active,
                "unsigned_char".into(),
                sample,
                n,
            );
            s.ascii_colour = encoding == Encoding::Ascii;
            s
        }
        "lookup_table" => {
            let name = lx.expect("the LOOKUP_TABLE name")?;
            let size: usize = lx.number("the LOOKUP_TABLE size")?;
            info.header
                .push((word.to_string(), format!("{name} {size}")));
            let (sample, type_name) = match encoding {
                Encoding::Ascii => (SampleType::Number(DType::F32), "float"),
                Encoding::Binary => (SampleType::Number(DType::U8), "unsigned_char"),
            };
            let table = spec(name, assoc, 4, false, type_name.into(), sample, size);
            return array_values(lx, encoding, &table, None).map(|_| ());
        }
        "vectors" | "normals" => simple(lx, word, assoc, 3, n, info)?,
        "tensors" => simple(lx, word, assoc, 9, n, info)?,
        "tensors6" => simple(lx, word, assoc, 6, n, info)?,
        "global_ids" | "pedigree_ids" | "edge_flags" => simple(lx, word, assoc, 1, n, info)?,
        "texture_coordinates" => {
            let name = decode_name(&lx.expect("the TEXTURE_COORDINATES name")?);
            let dim: usize = lx.number("the TEXTURE_COORDINATES dimension")?;
            if !(1..=3).contains(&dim) {
                return Err(IoError::invalid(
                    &path,
                    format!("TEXTURE_COORDINATES \"{name}\" has dimension {dim}: expected 1 to 3"),
                ));
            }
            let type_name = lx.expect("the TEXTURE_COORDINATES data type")?;
            let sample = parse_type(
                &path,
                &type_name,
                &format!("TEXTURE_COORDINATES \"{name}\""),
            )?;
            info.header
                .push((word.to_string(), format!("{name} {dim} {type_name}")));
            spec(name, assoc, dim, false, type_name, sample, n)
        }
        "field" => {
            let name = lx.expect("the FIELD name")?;
            let count: usize = lx.number("the FIELD array count")?;
            info.header
                .push((word.to_string(), format!("{name} {count}")));
            for _ in 0..count {
                if let Some(spec) = field_array(lx, assoc, info)? {
                    take(lx, encoding, spec, n, scan)?;
                }
            }
            return Ok(());
        }
        _ => {
            return Err(IoError::invalid(
                &path,
                format!(
                    "unknown keyword \"{word}\" in the {section} section (byte {})",
                    lx.pos()
                ),
            ));
        }
    };
    take(lx, encoding, spec, n, scan)
}

/// An array announced as `KEYWORD name type`, of `components` per tuple.
fn simple<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    word: &str,
    assoc: Association,
    components: usize,
    n: usize,
    info: &mut FileInfo,
) -> Result<ArraySpec, IoError> {
    let name = decode_name(&lx.expect(&format!("the {word} name"))?);
    let type_name = lx.expect(&format!("the {word} data type"))?;
    let sample = parse_type(lx.path(), &type_name, &format!("{word} \"{name}\""))?;
    info.header
        .push((word.to_string(), format!("{name} {type_name}")));
    Ok(spec(name, assoc, components, false, type_name, sample, n))
}

fn spec(
    name: String,
    association: Association,
    components: usize,
    active_scalars: bool,
    type_name: String,
    sample: SampleType,
    tuples: usize,
) -> ArraySpec {
    ArraySpec {
        entry: ArrayEntry {
            name,
            association,
            components,
            active_scalars,
            type_name,
        },
        sample,
        tuples,
        ascii_colour: false,
    }
}

/// One array of a FIELD: `name numComponents numTuples type`, or
/// `NULL_ARRAY` (`None`).
fn field_array<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    assoc: Association,
    info: &mut FileInfo,
) -> Result<Option<ArraySpec>, IoError> {
    let raw = lx.expect("a FIELD array name")?;
    if raw == "NULL_ARRAY" {
        return Ok(None);
    }
    let name = decode_name(&raw);
    let components: usize = lx.number(&format!("the components of FIELD array \"{name}\""))?;
    let tuples: usize = lx.number(&format!("the tuples of FIELD array \"{name}\""))?;
    let type_name = lx.expect(&format!("the data type of FIELD array \"{name}\""))?;
    if components == 0 {
        return Err(IoError::invalid(
            lx.path(),
            format!("FIELD array \"{name}\" has 0 components"),
        ));
    }
    let sample = parse_type(lx.path(), &type_name, &format!("FIELD array \"{name}\""))?;
    info.header.push((
        "FIELD array".into(),
        format!("{name} {components} {tuples} {type_name}"),
    ));
    Ok(Some(spec(
        name, assoc, components, false, type_name, sample, tuples,
    )))
}

/// Records an array of a section of `n` tuples, decoding its values if it
/// is the best candidate so far, skipping them otherwise.
fn take<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    encoding: Encoding,
    spec: ArraySpec,
    n: usize,
    scan: &mut Scan,
) -> Result<(), IoError> {
    let rank = rank(&spec.entry, scan.request);
    let better = rank.filter(|&r| scan.best.as_ref().is_none_or(|b| r < b.rank));
    let usable = spec.entry.components == 1 && spec.tuples == n;
    let decode = (better.is_some() && usable).then_some(scan.max_memory);
    let mut values = array_values(lx, encoding, &spec, decode)?;
    if spec.ascii_colour
        && let Some(values) = values.as_mut()
    {
        // As vtkDataReader: byte = (unsigned char)(255 · value + 0.5).
        for v in values.iter_mut() {
            *v = (255.0 * *v + 0.5).clamp(0.0, 255.0).floor();
        }
    }
    if let Some(rank) = better {
        scan.best = Some(Best {
            rank,
            index: scan.entries.len(),
            values,
        });
    }
    scan.types.push(spec.entry.type_name.clone());
    scan.tuples.push(spec.tuples);
    scan.entries.push(spec.entry);
    Ok(())
}

/// Reads (`decode` holds the memory limit, `--max-memory`) or skips the
/// values of one array, then any METADATA block after it. The size is
/// checked against the rest of the file first, then against the limit.
fn array_values<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    encoding: Encoding,
    spec: &ArraySpec,
    decode: Option<u64>,
) -> Result<Option<Vec<f32>>, IoError> {
    let name = &spec.entry.name;
    let count = spec
        .tuples
        .checked_mul(spec.entry.components)
        .ok_or_else(|| {
            IoError::invalid(
                lx.path(),
                format!("array \"{name}\": the value count overflows"),
            )
        })?;
    let values = match encoding {
        Encoding::Binary => {
            // vtkDataReader skips the rest of the announcing line first.
            lx.end_line()?;
            let bytes = spec.sample.binary_len(count).unwrap_or(u64::MAX);
            if bytes > lx.remaining() {
                return Err(IoError::invalid(
                    lx.path(),
                    format!(
                        "BINARY data of array \"{name}\" ({count} {} values) needs {bytes} bytes, but only {} are left in the file",
                        spec.entry.type_name,
                        lx.remaining()
                    ),
                ));
            }
            if let Some(max_memory) = decode {
                check_memory(
                    lx.path(),
                    &format!("array \"{name}\""),
                    count as u128,
                    F32_BYTES,
                    max_memory,
                )?;
                Some(binary_values(lx, spec.sample, count)?)
            } else {
                lx.skip(bytes)?;
                None
            }
        }
        Encoding::Ascii => {
            // Each value takes at least one character and a separator.
            if count as u64 > lx.remaining().div_ceil(2) {
                return Err(IoError::invalid(
                    lx.path(),
                    format!(
                        "ASCII data of array \"{name}\" ({count} values) cannot fit in the {} bytes left in the file",
                        lx.remaining()
                    ),
                ));
            }
            if let Some(max_memory) = decode {
                check_memory(
                    lx.path(),
                    &format!("array \"{name}\""),
                    count as u128,
                    F32_BYTES,
                    max_memory,
                )?;
            }
            let mut out = decode.map(|_| Vec::with_capacity(count));
            for i in 0..count {
                let t = lx.next_token()?.ok_or_else(|| {
                    IoError::invalid(
                        lx.path(),
                        format!("ASCII data of array \"{name}\" ends after {i} of {count} values"),
                    )
                })?;
                if let Some(out) = out.as_mut() {
                    out.push(ascii_value(&t, spec.sample).ok_or_else(|| {
                        IoError::invalid(
                            lx.path(),
                            format!(
                                "value {i} of array \"{name}\" is \"{t}\": not a valid {} value",
                                spec.entry.type_name
                            ),
                        )
                    })?);
                }
            }
            out
        }
    };
    skip_metadata(lx, spec.entry.components)?;
    Ok(values)
}

/// One ASCII value, converted as VTK's stream reads it into the array type
/// (integers wrap into narrower types as a C cast does).
fn ascii_value(t: &str, sample: SampleType) -> Option<f32> {
    let int = || t.parse::<i64>().ok();
    Some(match sample {
        SampleType::Bit => (int()? != 0) as u8 as f32,
        SampleType::Number(d) => match d {
            DType::U8 => int()? as u8 as f32,
            DType::I8 => int()? as i8 as f32,
            DType::U16 => int()? as u16 as f32,
            DType::I16 => int()? as i16 as f32,
            DType::U32 => int()? as u32 as f32,
            DType::I32 => int()? as i32 as f32,
            DType::I64 => int()? as f32,
            DType::U64 => match t.parse::<u64>() {
                Ok(v) => v as f32,
                Err(_) => int()? as u64 as f32,
            },
            DType::F16 | DType::F32 => t.parse::<f32>().ok()?,
            DType::F64 => t.parse::<f64>().ok()? as f32,
        },
    })
}

/// `count` BINARY values (big-endian), read in chunks.
fn binary_values<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    sample: SampleType,
    count: usize,
) -> Result<Vec<f32>, IoError> {
    let mut out = Vec::with_capacity(count);
    match sample {
        SampleType::Bit => {
            let mut bytes = vec![0u8; count.div_ceil(8)];
            lx.bytes(&mut bytes)?;
            // vtkBitArray: value i is bit 7 - i % 8 of byte i / 8.
            out.extend((0..count).map(|i| f32::from((bytes[i / 8] >> (7 - i % 8)) & 1)));
        }
        SampleType::Number(d) => {
            let size = d.size();
            let mut buf = vec![0u8; count.min(CHUNK_SAMPLES) * size];
            let mut done = 0;
            while done < count {
                let k = (count - done).min(CHUNK_SAMPLES);
                lx.bytes(&mut buf[..k * size])?;
                extend_f32(&mut out, &buf[..k * size], d, Endian::Big);
                done += k;
            }
        }
    }
    Ok(out)
}

/// Skips a `METADATA` block after an array, if there is one: a
/// `COMPONENT_NAMES` list (one line per component) and `INFORMATION` keys,
/// ended by a blank line (vtkDataReader::ReadArray).
fn skip_metadata<R: std::io::BufRead + std::io::Seek>(
    lx: &mut Lexer<R>,
    components: usize,
) -> Result<(), IoError> {
    if !lx
        .peek_token()?
        .is_some_and(|t| t.eq_ignore_ascii_case("metadata"))
    {
        return Ok(());
    }
    lx.next_token()?;
    lx.end_line()?;
    while let Some(line) = lx.line()? {
        let line = line.trim();
        if line.is_empty() {
            break;
        }
        if line.eq_ignore_ascii_case("component_names") {
            for _ in 0..components {
                if lx.line()?.is_none() {
                    break;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_names_follow_vtk_data_reader() {
        assert_eq!(sample_type("FLOAT"), Some(SampleType::Number(DType::F32)));
        assert_eq!(
            sample_type("vtkIdType"),
            Some(SampleType::Number(DType::I32))
        );
        assert_eq!(sample_type("long"), Some(SampleType::Number(DType::I64)));
        assert_eq!(
            sample_type("vtktypeuint64"),
            Some(SampleType::Number(DType::U64))
        );
        assert_eq!(sample_type("bit"), Some(SampleType::Bit));
        assert_eq!(sample_type("integer"), None);
        assert_eq!(SampleType::Bit.binary_len(9), Some(2));
        assert_eq!(SampleType::Number(DType::F64).binary_len(3), Some(24));
    }

    #[test]
    fn names_are_percent_decoded() {
        assert_eq!(decode_name("n%20c"), "n c");
        assert_eq!(decode_name("100%25"), "100%");
        assert_eq!(decode_name("a%2"), "a%2");
        assert_eq!(decode_name("a%zz"), "a%zz");
    }

    #[test]
    fn ascii_values_convert_like_a_c_stream() {
        let u8t = SampleType::Number(DType::U8);
        assert_eq!(ascii_value("200", u8t), Some(200.0));
        assert_eq!(ascii_value("300", u8t), Some(44.0));
        assert_eq!(ascii_value("1.5", u8t), None);
        assert_eq!(ascii_value("-2", SampleType::Number(DType::I8)), Some(-2.0));
        assert_eq!(ascii_value("2", SampleType::Bit), Some(1.0));
        assert_eq!(
            ascii_value("1e3", SampleType::Number(DType::F64)),
            Some(1000.0)
        );
        assert!(
            ascii_value("nan", SampleType::Number(DType::F32))
                .unwrap()
                .is_nan()
        );
        assert_eq!(
            ascii_value("18446744073709551615", SampleType::Number(DType::U64)),
            Some(u64::MAX as f32)
        );
    }
}
