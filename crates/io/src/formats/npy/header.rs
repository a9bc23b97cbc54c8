//! The `.npy` preamble and header: the magic and version, the header's
//! length, and the dict that names the element type ([`Elem`]), the order
//! and the shape, checked against the file's length before anything is
//! allocated.

use std::io::Read;
use std::path::Path;

use volray_core::SampleType;

use super::literal::{Lit, Parser, snippet};
use crate::dtype::{DType, Endian, Stored, f16_to_f32};
use crate::error::IoError;
use crate::shared::input::read_exact_at;

pub(super) const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// Largest header accepted (NumPy itself writes a few hundred bytes at most).
const MAX_HEADER_LEN: usize = 1 << 20;

/// An element type a `.npy` file may hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Elem {
    Plain(DType, Endian),
    Bool,
    I64(Endian),
    U64(Endian),
    F16(Endian),
}

impl Elem {
    pub(super) fn size(self) -> usize {
        match self {
            Elem::Plain(d, _) => d.size(),
            Elem::Bool => 1,
            Elem::I64(_) | Elem::U64(_) => 8,
            Elem::F16(_) => 2,
        }
    }

    /// The type a volume keeps these in: booleans as `u8`, 64-bit integers
    /// and `f2` as `f32`, the rest as [`DType::stored`] says.
    pub(super) fn stored(self) -> SampleType {
        match self {
            Elem::Plain(d, _) => d.stored(),
            Elem::Bool => SampleType::U8,
            Elem::I64(_) | Elem::U64(_) | Elem::F16(_) => SampleType::F32,
        }
    }

    /// Appends `bytes` decoded to `out`, of the type [`Elem::stored`] names.
    pub(super) fn decode<T: Stored>(self, bytes: &[u8], out: &mut Vec<T>) {
        fn words<const N: usize>(bytes: &[u8], e: Endian) -> impl Iterator<Item = [u8; N]> + '_ {
            bytes.chunks_exact(N).map(move |c| {
                let mut a = [0u8; N];
                a.copy_from_slice(c);
                if e == Endian::Big {
                    a.reverse();
                }
                a
            })
        }
        match self {
            Elem::Plain(d, e) => T::extend(out, bytes, d, e),
            Elem::Bool => out.extend(bytes.iter().map(|&b| T::from_f64(f64::from(b != 0)))),
            // Rounded to f32 first (as before), then stored exactly as f32.
            Elem::I64(e) => out.extend(
                words(bytes, e).map(|a| T::from_f64(f64::from(i64::from_le_bytes(a) as f32))),
            ),
            Elem::U64(e) => out.extend(
                words(bytes, e).map(|a| T::from_f64(f64::from(u64::from_le_bytes(a) as f32))),
            ),
            Elem::F16(e) => out.extend(
                words(bytes, e).map(|a| T::from_f64(f64::from(f16_to_f32(u16::from_le_bytes(a))))),
            ),
        }
    }
}

/// What the header says about the array.
#[derive(Debug, PartialEq)]
pub(super) struct Header {
    pub(super) elem: Elem,
    pub(super) fortran_order: bool,
    pub(super) shape: [usize; 3],
    /// Where the data starts in the file.
    pub(super) data_offset: u64,
}

/// Reads and checks the preamble and header, leaving `file` at the data.
pub(super) fn read_header(
    path: &Path,
    file: &mut impl Read,
    file_len: u64,
) -> Result<Header, IoError> {
    let err = |reason: String| IoError::npy(path, reason);
    if file_len < 8 {
        return Err(err(format!(
            "not a .npy file: {file_len} bytes is too short for the .npy preamble"
        )));
    }
    let mut pre = [0u8; 8];
    read_exact_at(path, file, &mut pre, 0, file_len)?;
    if &pre[..6] != MAGIC {
        return Err(err(
            "not a .npy file: it does not start with \\x93NUMPY".into()
        ));
    }
    let (major, minor) = (pre[6], pre[7]);
    let len_bytes = match (major, minor) {
        (1, 0) => 2,
        (2, 0) | (3, 0) => 4,
        _ => {
            return Err(err(format!(
                "unsupported .npy format version {major}.{minor} (supported: 1.0, 2.0, 3.0)"
            )));
        }
    };
    if file_len < 8 + len_bytes {
        return Err(err(format!(
            "truncated .npy file: {file_len} bytes end inside the header length"
        )));
    }
    let mut lb = [0u8; 4];
    read_exact_at(path, file, &mut lb[..len_bytes as usize], 8, file_len)?;
    let header_len = u32::from_le_bytes(lb) as usize;
    if header_len > MAX_HEADER_LEN {
        return Err(err(format!(
            ".npy header length {header_len} is over the {MAX_HEADER_LEN}-byte limit"
        )));
    }
    let data_offset = 8 + len_bytes + header_len as u64;
    if file_len < data_offset {
        return Err(err(format!(
            "truncated .npy file: the header claims {header_len} bytes but the file is {file_len} bytes"
        )));
    }
    let mut text = vec![0u8; header_len];
    read_exact_at(path, file, &mut text, 8 + len_bytes, file_len)?;
    let text =
        std::str::from_utf8(&text).map_err(|_| err(".npy header is not valid text".into()))?;

    let (elem, fortran_order, shape) = parse_header(text).map_err(err)?;

    let [nx, ny, nz] = shape;
    let shape_text = format!("({nx}, {ny}, {nz})");
    let data_len = file_len - data_offset;
    let needed = nx
        .checked_mul(ny)
        .and_then(|n| n.checked_mul(nz))
        .and_then(|n| n.checked_mul(elem.size()))
        .and_then(|n| u64::try_from(n).ok())
        .ok_or_else(|| {
            err(format!(
                ".npy shape {shape_text} is too large for this machine"
            ))
        })?;
    if needed != data_len {
        return Err(err(format!(
            ".npy header says shape {shape_text} of {} ({needed} bytes) but the file has {data_len} bytes of data",
            descr_name(elem)
        )));
    }
    Ok(Header {
        elem,
        fortran_order,
        shape,
        data_offset,
    })
}

/// A canonical spelling of an element type, for messages.
pub(super) fn descr_name(elem: Elem) -> String {
    let order = |e: Endian| if e == Endian::Little { '<' } else { '>' };
    match elem {
        Elem::Bool => "|b1".into(),
        Elem::Plain(DType::U8, _) => "|u1".into(),
        Elem::Plain(DType::I8, _) => "|i1".into(),
        Elem::Plain(d, e) => {
            let kind = match d {
                DType::F16 | DType::F32 | DType::F64 => 'f',
                DType::U16 | DType::U32 | DType::U64 => 'u',
                _ => 'i',
            };
            format!("{}{kind}{}", order(e), d.size())
        }
        Elem::I64(e) => format!("{}i8", order(e)),
        Elem::U64(e) => format!("{}u8", order(e)),
        Elem::F16(e) => format!("{}f2", order(e)),
    }
}

/// Interprets the header dict: element type, Fortran order and 3-D shape.
pub(super) fn parse_header(text: &str) -> Result<(Elem, bool, [usize; 3]), String> {
    let mut p = Parser {
        src: text.as_bytes(),
        pos: 0,
    };
    let (value, _) = p.value(0)?;
    p.skip_ws();
    if p.pos != p.src.len() {
        return Err(format!(
            ".npy header has text after the dict at byte {}",
            p.pos
        ));
    }
    let Lit::Dict(entries) = value else {
        return Err(".npy header is not a dict".into());
    };
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    for (key, value, span) in entries {
        let Lit::Str(key) = key else {
            return Err(".npy header has a key that is not a string".into());
        };
        let raw = snippet(&text[span.0..span.1]);
        let slot = match key.as_str() {
            "descr" => &mut descr,
            "fortran_order" => &mut fortran,
            "shape" => &mut shape,
            other => {
                return Err(format!(
                    ".npy header has an unexpected key '{}'",
                    snippet(other)
                ));
            }
        };
        if slot.is_some() {
            return Err(format!(".npy header repeats the key '{key}'"));
        }
        *slot = Some((value, raw));
    }
    let missing = |k: &str| format!(".npy header lacks the key '{k}'");
    let (descr, descr_raw) = descr.ok_or_else(|| missing("descr"))?;
    let (fortran, fortran_raw) = fortran.ok_or_else(|| missing("fortran_order"))?;
    let (shape, shape_raw) = shape.ok_or_else(|| missing("shape"))?;

    let elem = match descr {
        Lit::Str(s) => parse_descr(&s),
        _ => None,
    }
    .ok_or_else(|| {
        format!(
            "unsupported .npy dtype descr {descr_raw} (supported: b1, i1, u1, i2, u2, i4, u4, i8, u8, f2, f4, f8 with byte order <, >, | or =)"
        )
    })?;
    let Lit::Bool(fortran) = fortran else {
        return Err(format!(
            ".npy header has fortran_order {fortran_raw}, not True or False"
        ));
    };
    let Lit::Tuple(items) = shape else {
        return Err(format!(".npy header has shape {shape_raw}, not a tuple"));
    };
    let mut dims = Vec::with_capacity(items.len());
    for item in &items {
        match item {
            Lit::Int(n) if *n >= 0 => match usize::try_from(*n) {
                Ok(n) => dims.push(n),
                Err(_) => {
                    return Err(format!(
                        ".npy shape {shape_raw} is too large for this machine"
                    ));
                }
            },
            _ => {
                return Err(format!(
                    ".npy header has shape {shape_raw}, not a tuple of non-negative integers"
                ));
            }
        }
    }
    let shape: [usize; 3] = dims.try_into().map_err(|d: Vec<usize>| {
        format!(
            ".npy array has shape {shape_raw} ({}-D) but a volume needs a 3-D array",
            d.len()
        )
    })?;
    Ok((elem, fortran, shape))
}

/// Reads a descr string such as `'<f4'`.
fn parse_descr(s: &str) -> Option<Elem> {
    let mut chars = s.chars();
    let order = match chars.next()? {
        '<' => Endian::Little,
        '>' => Endian::Big,
        '|' | '=' => Endian::NATIVE,
        _ => return None,
    };
    Some(match chars.as_str() {
        "b1" => Elem::Bool,
        "i1" => Elem::Plain(DType::I8, order),
        "u1" => Elem::Plain(DType::U8, order),
        "i2" => Elem::Plain(DType::I16, order),
        "u2" => Elem::Plain(DType::U16, order),
        "i4" => Elem::Plain(DType::I32, order),
        "u4" => Elem::Plain(DType::U32, order),
        "i8" => Elem::I64(order),
        "u8" => Elem::U64(order),
        "f2" => Elem::F16(order),
        "f4" => Elem::Plain(DType::F32, order),
        "f8" => Elem::Plain(DType::F64, order),
        _ => return None,
    })
}
