//! The values of a legacy VTK array: its description as its header
//! words give it ([`ArraySpec`]), its sample types, and reading (ASCII,
//! or BINARY big-endian) or skipping the values of one array and the
//! `METADATA` block after it, each size checked against the rest of the
//! file before anything is allocated.

use std::path::Path;

use super::lexer::Lexer;
use crate::dtype::{DType, Endian, extend_f32};
use crate::error::IoError;
use crate::shared::limits::{F32_BYTES, check_memory};
use crate::shared::mapped::{self, MapPolicy};
use crate::shared::vtk_arrays::ArrayEntry;

/// Samples decoded per read of BINARY data.
const CHUNK_SAMPLES: usize = 1 << 16;

/// The sample types of legacy VTK arrays (vtkDataReader::ReadArray).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum SampleType {
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
pub(super) enum Encoding {
    Ascii,
    Binary,
}

/// One array's description, as its header words give it.
pub(super) struct ArraySpec {
    pub(super) entry: ArrayEntry,
    pub(super) sample: SampleType,
    pub(super) tuples: usize,
    /// ASCII `COLOR_SCALARS`: floats in [0, 1] that stand for bytes.
    pub(super) ascii_colour: bool,
}

/// A type name, known or refused.
pub(super) fn parse_type(path: &Path, name: &str, what: &str) -> Result<SampleType, IoError> {
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

/// Reads (`decode` holds the memory limit, `--max-memory`) or skips the
/// values of one array, then any METADATA block after it. The size is
/// checked against the rest of the file first, then against the limit.
pub(super) fn array_values<R: std::io::BufRead + std::io::Seek>(
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
                within(
                    check_memory(
                        lx.path(),
                        &format!("array \"{name}\""),
                        count as u128,
                        F32_BYTES,
                        max_memory,
                    ),
                    "legacy VTK stores BINARY values big-endian, and volray reads its arrays into f32",
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
                within(
                    check_memory(
                        lx.path(),
                        &format!("array \"{name}\""),
                        count as u128,
                        F32_BYTES,
                        max_memory,
                    ),
                    "its values are ASCII text, parsed into f32",
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
/// A legacy VTK array is never mapped: over the memory limit, `check` is
/// refused with `why` and what to do instead.
fn within(check: Result<(), IoError>, why: &str) -> Result<(), IoError> {
    mapped::plan(
        MapPolicy::IfLarger,
        Err(format!(
            "{why}: save the volume as raw NRRD with a detached header, or .npy, in little-endian u8, i8, u16, i16 or f32"
        )),
        check.map(|()| 0),
    )
    .map(drop)
}

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
