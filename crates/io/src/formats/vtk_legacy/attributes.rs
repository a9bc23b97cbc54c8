//! The attribute sections of a legacy VTK file (`POINT_DATA n`,
//! `CELL_DATA n`): each keyword's header words (`SCALARS name type`,
//! `VECTORS`, `FIELD` arrays, ...) become an [`ArraySpec`] (`values.rs`), and the
//! [`Scan`] decodes the best candidate for the volume so far and skips
//! every other array ([`crate::shared::vtk_arrays`] ranks them).

use super::lexer::Lexer;
use super::values::{ArraySpec, Encoding, SampleType, array_values, parse_type};
use crate::FileInfo;
use crate::dtype::DType;
use crate::error::IoError;
use crate::shared::vtk_arrays::{ArrayEntry, Association, rank};

/// The best array found so far and its values (`None` when it cannot be
/// used: not a scalar, or a FIELD array of the wrong length).
pub(super) struct Best {
    pub(super) rank: u8,
    pub(super) index: usize,
    pub(super) values: Option<Vec<f32>>,
}

/// What the scan of the attribute sections has found.
pub(super) struct Scan<'a> {
    pub(super) request: Option<&'a str>,
    pub(super) entries: Vec<ArrayEntry>,
    pub(super) tuples: Vec<usize>,
    pub(super) best: Option<Best>,
    /// Sample type names of the entries, for `stored_type`.
    pub(super) types: Vec<String>,
    /// `--max-memory`: the array decoded must fit it.
    pub(super) max_memory: u64,
}

/// Reads one attribute keyword's words and data in a POINT_DATA or
/// CELL_DATA section of `n` tuples.
#[allow(clippy::too_many_arguments)]
pub(super) fn attribute<R: std::io::BufRead + std::io::Seek>(
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

/// An array of `tuples` tuples as its header words describe it.
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
pub(super) fn field_array<R: std::io::BufRead + std::io::Seek>(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_percent_decoded() {
        assert_eq!(decode_name("n%20c"), "n c");
        assert_eq!(decode_name("100%25"), "100%");
        assert_eq!(decode_name("a%2"), "a%2");
        assert_eq!(decode_name("a%zz"), "a%zz");
    }
}
