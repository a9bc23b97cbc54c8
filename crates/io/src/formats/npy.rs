//! NumPy `.npy` files (format versions 1.0, 2.0 and 3.0), read and written
//! without NumPy.
//!
//! A `.npy` file is the magic `\x93NUMPY`, a version (major, minor byte),
//! a little-endian header length (`u16` in version 1, `u32` in 2 and 3), a
//! header that is a Python dict literal such as
//! `{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }`, and
//! then the array's bytes.
//!
//! # Axis convention
//!
//! A 3-D array is indexed `a[x, y, z]`, as yt, SciPy and PyVista do: its
//! shape is `(nx, ny, nz)`. A C-order array has z fastest in memory, so it
//! is transposed into volray's x-fastest layout; a Fortran-order array is
//! x-fastest already and is read as is. [`write_npy`] writes Fortran
//! order, so `np.load` gives back `a[x, y, z]` without any copy.

use std::fmt::Write as _;
use std::io::Read;
use std::path::Path;

use volray_core::{SampleType, Volume, VolumeError};

use crate::atomic::write_atomically;
use crate::dtype::{DType, Endian, Stored, f16_to_f32, read_as_stored};
use crate::error::IoError;
use crate::shared::input::{open_input, read_exact_at, read_samples};
use crate::shared::limits::check_dims;
use crate::shared::mapped::{self, MapPolicy, Plan};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// Largest header accepted (NumPy itself writes a few hundred bytes at most).
const MAX_HEADER_LEN: usize = 1 << 20;

/// Deepest nesting of brackets the header parser follows.
const MAX_DEPTH: usize = 16;

/// Header bytes are padded so the data starts at a multiple of this.
const ALIGN: usize = 64;

/// Reads the 3-D array in the `.npy` file at `path` as a volume with unit
/// spacing and its origin at zero.
///
/// The array is indexed `a[x, y, z]` (see the module docs). Accepted
/// element types (`descr`, byte order `<`, `>`, `|` or `=`): `b1` (as 0 or
/// 1), `i1 u1 i2 u2 i4 u4 i8 u8` (64-bit ones with `as f32`), `f2 f4 f8`.
/// The header is checked against the file's length before anything is
/// allocated, and the file must end exactly where the data does.
pub fn read_npy(path: &Path) -> Result<Volume, IoError> {
    read_npy_with_info(path, crate::default_max_memory(), MapPolicy::IfLarger).map(|(v, _)| v)
}

/// Reads the `.npy` file at `path` (see [`read_npy`]) within
/// `opts.max_memory`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (volume, info) = read_npy_with_info(path, opts.max_memory, opts.map)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Npy,
        info,
    })
}

/// [`read_npy`], with the header's fields for `volray info`, within
/// `max_memory` bytes: a larger array is mapped from the file where
/// `policy` and its layout allow, refused otherwise.
fn read_npy_with_info(
    path: &Path,
    max_memory: u64,
    policy: MapPolicy,
) -> Result<(Volume, FileInfo), IoError> {
    let (mut file, file_len) = open_input(path)?;
    let header = read_header(path, &mut file, file_len)?;
    let [nx, ny, nz] = header.shape;
    if nx < 2 || ny < 2 || nz < 2 {
        return Err(IoError::volume(path, VolumeError::TooThin(nx, ny, nz)));
    }
    // read_header checked count · size against the file, so no overflow.
    let stored = header.elem.stored();
    let count = nx * ny * nz;
    let mappable = match header.elem {
        _ if !header.fortran_order => Err(
            "C order: a[x, y, z] has z fastest and is transposed as it is read; save it with np.asfortranarray".to_string(),
        ),
        Elem::Plain(d, e) => mapped::mappable(d, e, header.data_offset),
        _ => Err(format!("{} elements are converted as they are read", descr_name(header.elem))),
    };
    let plan = mapped::plan(
        policy,
        mappable,
        check_dims(
            path,
            "shape",
            &header.shape,
            stored.bytes() as u64,
            max_memory,
        ),
    )?;
    let data = match (plan, header.elem) {
        (Plan::Map, Elem::Plain(d, _)) => mapped::map_samples(path, header.data_offset, d, count)?,
        _ => read_as_stored!(stored, |T| read_data::<T>(path, &mut file, &header, count))?,
    };
    let elem = header.elem;
    let mut info = FileInfo::new(descr_name(elem));
    info.header = vec![
        ("descr".into(), descr_name(elem)),
        (
            "fortran_order".into(),
            if header.fortran_order {
                "True"
            } else {
                "False"
            }
            .into(),
        ),
        ("shape".into(), format!("({nx}, {ny}, {nz})")),
    ];
    if !header.fortran_order {
        info.notes
            .push("C order: the array a[x, y, z] was transposed to x fastest".into());
    }
    let volume = Volume::from_samples(header.shape, data).map_err(|e| IoError::volume(path, e))?;
    if plan == Plan::Map {
        info.notes.push(mapped::mapped_note(&volume));
    }
    Ok((volume, info))
}

/// The `count` samples after the header, x fastest, as `T`.
fn read_data<T: Stored>(
    path: &Path,
    file: &mut impl Read,
    header: &Header,
    count: usize,
) -> Result<Vec<T>, IoError> {
    let [nx, ny, nz] = header.shape;
    let elem = header.elem;
    let decode = |bytes: &[u8], out: &mut Vec<T>| elem.decode(bytes, out);
    if header.fortran_order {
        let mut data = Vec::with_capacity(count);
        read_samples(
            path,
            file,
            count,
            elem.size(),
            header.data_offset,
            decode,
            |v| data.extend_from_slice(v),
        )?;
        return Ok(data);
    }
    // C order: z fastest in the file. Scatter into x-fastest order.
    let mut data = vec![T::default(); count];
    let (mut x, mut y, mut z) = (0usize, 0usize, 0usize);
    read_samples(
        path,
        file,
        count,
        elem.size(),
        header.data_offset,
        decode,
        |values| {
            for &v in values {
                data[x + nx * (y + ny * z)] = v;
                z += 1;
                if z == nz {
                    z = 0;
                    y += 1;
                    if y == ny {
                        y = 0;
                        x += 1;
                    }
                }
            }
        },
    )?;
    Ok(data)
}

/// Writes `volume` to `path` as a `.npy` file, atomically: format version
/// 1.0, `descr` `'<f4'`, Fortran order, shape `(nx, ny, nz)`, so that
/// `np.load(path)[x, y, z]` is the voxel at `(x, y, z)`. The header is
/// padded so the data starts at a multiple of 64 bytes. Spacing and origin
/// are not stored: `.npy` has no place for them.
pub fn write_npy(path: &Path, volume: &Volume) -> Result<(), IoError> {
    let header = header_text(volume.dims());
    let len = u16::try_from(header.len()).map_err(|_| {
        IoError::npy(
            path,
            format!(".npy header of {} bytes is too long", header.len()),
        )
    })?;
    write_atomically(path, |w| {
        w.write_all(MAGIC)?;
        w.write_all(&[1, 0])?;
        w.write_all(&len.to_le_bytes())?;
        w.write_all(header.as_bytes())?;
        let mut buf = Vec::with_capacity(4 * 8192);
        volume.samples().try_for_each_f32_chunk(8192, |chunk| {
            buf.clear();
            buf.extend(chunk.iter().flat_map(|v| v.to_le_bytes()));
            w.write_all(&buf)
        })?;
        Ok(())
    })
}

/// The version-1.0 header for a Fortran-order `<f4` array of `dims`,
/// padded with spaces and ended with a newline so that the 10-byte
/// preamble plus the header is a multiple of [`ALIGN`].
fn header_text(dims: [usize; 3]) -> String {
    let mut h = format!(
        "{{'descr': '<f4', 'fortran_order': True, 'shape': ({}, {}, {}), }}",
        dims[0], dims[1], dims[2]
    );
    let unpadded = 10 + h.len() + 1;
    let pad = (ALIGN - unpadded % ALIGN) % ALIGN;
    h.extend(std::iter::repeat_n(' ', pad));
    h.push('\n');
    h
}

/// An element type a `.npy` file may hold.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Elem {
    Plain(DType, Endian),
    Bool,
    I64(Endian),
    U64(Endian),
    F16(Endian),
}

impl Elem {
    fn size(self) -> usize {
        match self {
            Elem::Plain(d, _) => d.size(),
            Elem::Bool => 1,
            Elem::I64(_) | Elem::U64(_) => 8,
            Elem::F16(_) => 2,
        }
    }

    /// The type a volume keeps these in: booleans as `u8`, 64-bit integers
    /// and `f2` as `f32`, the rest as [`DType::stored`] says.
    fn stored(self) -> SampleType {
        match self {
            Elem::Plain(d, _) => d.stored(),
            Elem::Bool => SampleType::U8,
            Elem::I64(_) | Elem::U64(_) | Elem::F16(_) => SampleType::F32,
        }
    }

    /// Appends `bytes` decoded to `out`, of the type [`Elem::stored`] names.
    fn decode<T: Stored>(self, bytes: &[u8], out: &mut Vec<T>) {
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
struct Header {
    elem: Elem,
    fortran_order: bool,
    shape: [usize; 3],
    /// Where the data starts in the file.
    data_offset: u64,
}

/// Reads and checks the preamble and header, leaving `file` at the data.
fn read_header(path: &Path, file: &mut impl Read, file_len: u64) -> Result<Header, IoError> {
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
fn descr_name(elem: Elem) -> String {
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
fn parse_header(text: &str) -> Result<(Elem, bool, [usize; 3]), String> {
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

/// Header text quoted in a message: one line, at most 80 characters.
fn snippet(s: &str) -> String {
    let one_line: String = s
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if one_line.chars().count() > 80 {
        let mut t: String = one_line.chars().take(77).collect();
        t.push_str("...");
        t
    } else {
        one_line
    }
}

/// A Python literal, as far as `.npy` headers use them.
#[derive(Debug, Clone, PartialEq)]
enum Lit {
    Str(String),
    Int(i128),
    Bool(bool),
    None,
    Tuple(Vec<Lit>),
    List(Vec<Lit>),
    /// Entries with the byte span of each value's source text.
    Dict(Vec<(Lit, Lit, (usize, usize))>),
}

/// A recursive-descent parser of Python literals, bounded in depth.
struct Parser<'a> {
    src: &'a [u8],
    pos: usize,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self
            .src
            .get(self.pos)
            .is_some_and(|c| c.is_ascii_whitespace())
        {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.src.get(self.pos).copied()
    }

    fn fail<T>(&self, what: &str) -> Result<T, String> {
        let mut msg = format!(".npy header is malformed: {what} at byte {}", self.pos);
        if let Some(&c) = self.src.get(self.pos) {
            let _ = write!(msg, " ('{}')", snippet(&char::from(c).to_string()));
        }
        Err(msg)
    }

    fn expect(&mut self, c: u8) -> Result<(), String> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            self.fail(&format!("expected '{}'", char::from(c)))
        }
    }

    /// Parses one value; returns it with the byte span of its source text.
    fn value(&mut self, depth: usize) -> Result<(Lit, (usize, usize)), String> {
        if depth > MAX_DEPTH {
            return self.fail("nesting too deep");
        }
        let start = {
            self.skip_ws();
            self.pos
        };
        let lit = match self.peek() {
            None => return self.fail("unexpected end"),
            Some(b'{') => {
                self.pos += 1;
                let mut entries = Vec::new();
                loop {
                    if self.peek() == Some(b'}') {
                        self.pos += 1;
                        break;
                    }
                    let (key, _) = self.value(depth + 1)?;
                    self.expect(b':')?;
                    let (value, span) = self.value(depth + 1)?;
                    entries.push((key, value, span));
                    match self.peek() {
                        Some(b',') => self.pos += 1,
                        Some(b'}') => {}
                        _ => return self.fail("expected ',' or '}'"),
                    }
                }
                Lit::Dict(entries)
            }
            Some(open @ (b'(' | b'[')) => {
                let close = if open == b'(' { b')' } else { b']' };
                self.pos += 1;
                let mut items = Vec::new();
                let mut trailing_comma = false;
                loop {
                    if self.peek() == Some(close) {
                        self.pos += 1;
                        break;
                    }
                    items.push(self.value(depth + 1)?.0);
                    trailing_comma = false;
                    match self.peek() {
                        Some(b',') => {
                            self.pos += 1;
                            trailing_comma = true;
                        }
                        Some(c) if c == close => {}
                        _ => return self.fail("expected ',' or a closing bracket"),
                    }
                }
                if open == b'[' {
                    Lit::List(items)
                } else if items.len() == 1 && !trailing_comma {
                    // "(x)" is just x in Python.
                    items.pop().unwrap_or(Lit::None)
                } else {
                    Lit::Tuple(items)
                }
            }
            Some(q @ (b'\'' | b'"')) => {
                self.pos += 1;
                let mut bytes = Vec::new();
                loop {
                    match self.src.get(self.pos) {
                        None => return self.fail("unterminated string"),
                        Some(&c) if c == q => {
                            self.pos += 1;
                            break;
                        }
                        Some(b'\\') => {
                            let Some(&e) = self.src.get(self.pos + 1) else {
                                return self.fail("unterminated string");
                            };
                            bytes.push(e);
                            self.pos += 2;
                        }
                        Some(&c) => {
                            bytes.push(c);
                            self.pos += 1;
                        }
                    }
                }
                Lit::Str(String::from_utf8_lossy(&bytes).into_owned())
            }
            Some(c) if c.is_ascii_digit() || c == b'-' || c == b'+' => {
                let s = self.pos;
                self.pos += 1;
                while self.src.get(self.pos).is_some_and(u8::is_ascii_digit) {
                    self.pos += 1;
                }
                let digits = std::str::from_utf8(&self.src[s..self.pos]).unwrap_or("");
                let n = digits
                    .parse::<i128>()
                    .or_else(|_| self.fail("bad integer"))?;
                // Python 2 wrote long integers as "3L".
                if matches!(self.src.get(self.pos), Some(b'L' | b'l')) {
                    self.pos += 1;
                }
                Lit::Int(n)
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let s = self.pos;
                while self
                    .src
                    .get(self.pos)
                    .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
                {
                    self.pos += 1;
                }
                match &self.src[s..self.pos] {
                    b"True" => Lit::Bool(true),
                    b"False" => Lit::Bool(false),
                    b"None" => Lit::None,
                    _ => {
                        self.pos = s;
                        return self.fail("unknown name");
                    }
                }
            }
            Some(_) => return self.fail("unexpected character"),
        };
        Ok((lit, (start, self.pos)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;
    use std::path::PathBuf;

    /// A `.npy` file image: preamble, header padded to 64, data.
    fn npy_bytes(version: u8, header: &str, data: &[u8]) -> Vec<u8> {
        let pre = if version == 1 { 10 } else { 12 };
        let mut h = header.to_string();
        let pad = (64 - (pre + h.len() + 1) % 64) % 64;
        h.extend(std::iter::repeat_n(' ', pad));
        h.push('\n');
        let mut out = MAGIC.to_vec();
        out.extend([version, 0]);
        if version == 1 {
            out.extend((h.len() as u16).to_le_bytes());
        } else {
            out.extend((h.len() as u32).to_le_bytes());
        }
        out.extend(h.as_bytes());
        out.extend(data);
        out
    }

    fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
        let p = dir.join(name);
        fs::write(&p, bytes).unwrap();
        p
    }

    fn npy_err(bytes: &[u8]) -> String {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "bad.npy", bytes);
        let err = read_npy(&p).unwrap_err();
        assert!(!err.is_io_failure(), "{err}");
        let msg = err.to_string();
        assert!(msg.starts_with(&p.display().to_string()), "{msg}");
        assert!(!msg.contains('\n'), "{msg}");
        msg
    }

    fn f32_data(n: usize) -> Vec<u8> {
        (0..n).flat_map(|i| (i as f32).to_le_bytes()).collect()
    }

    #[test]
    fn c_order_is_transposed_fortran_is_not() {
        let dir = tempfile::tempdir().unwrap();
        // File order i = 0..24 for shape (2, 3, 4).
        let c = npy_bytes(
            1,
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }",
            &f32_data(24),
        );
        let v = read_npy(&write(dir.path(), "c.npy", &c)).unwrap();
        assert_eq!(v.dims(), [2, 3, 4]);
        for x in 0..2 {
            for y in 0..3 {
                for z in 0..4 {
                    // C order: z fastest.
                    assert_eq!(v.get(x, y, z), (z + 4 * (y + 3 * x)) as f32);
                }
            }
        }
        let f = npy_bytes(
            2,
            "{\"shape\": (2,3,4), \"fortran_order\": True, \"descr\": \"<f4\"}",
            &f32_data(24),
        );
        let v = read_npy(&write(dir.path(), "f.npy", &f)).unwrap();
        assert_eq!(v.values(), (0..24).map(|i| i as f32).collect::<Vec<_>>());
    }

    #[test]
    fn write_then_read_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let dims = [3, 4, 5];
        let data: Vec<f32> = (0..60).map(|i| i as f32 * 0.5 - 7.25).collect();
        let v = Volume::new(dims, data).unwrap();
        let p = dir.path().join("out.npy");
        write_npy(&p, &v).unwrap();
        let bytes = fs::read(&p).unwrap();
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        assert_eq!(bytes.len(), 10 + header_len + 60 * 4);
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let text = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(text.ends_with('\n'));
        assert_eq!(
            text.trim_end(),
            "{'descr': '<f4', 'fortran_order': True, 'shape': (3, 4, 5), }"
        );
        let back = read_npy(&p).unwrap();
        assert_eq!(back, v);
    }

    #[test]
    fn every_descr_decodes() {
        let dir = tempfile::tempdir().unwrap();
        let vals: [f64; 8] = [0.0, 1.0, 2.0, 3.0, 100.0, 120.0, 126.0, 127.0];
        let neg: [f64; 8] = [-1.0, -2.0, 0.0, 5.0, -100.0, 7.0, -127.0, 1.0];
        type Enc = fn(f64) -> Vec<u8>;
        let cases: Vec<(&str, Enc, &[f64; 8])> = vec![
            ("|u1", |v| vec![v as u8], &vals),
            ("|i1", |v| vec![v as i8 as u8], &neg),
            ("<i2", |v| (v as i16).to_le_bytes().to_vec(), &neg),
            (">i2", |v| (v as i16).to_be_bytes().to_vec(), &neg),
            ("<u2", |v| (v as u16).to_le_bytes().to_vec(), &vals),
            (">u2", |v| (v as u16).to_be_bytes().to_vec(), &vals),
            ("<i4", |v| (v as i32).to_le_bytes().to_vec(), &neg),
            (">u4", |v| (v as u32).to_be_bytes().to_vec(), &vals),
            ("<i8", |v| (v as i64).to_le_bytes().to_vec(), &neg),
            (">i8", |v| (v as i64).to_be_bytes().to_vec(), &neg),
            ("<u8", |v| (v as u64).to_le_bytes().to_vec(), &vals),
            ("<f4", |v| (v as f32).to_le_bytes().to_vec(), &neg),
            (">f4", |v| (v as f32).to_be_bytes().to_vec(), &neg),
            ("<f8", |v| v.to_le_bytes().to_vec(), &neg),
            (">f8", |v| v.to_be_bytes().to_vec(), &neg),
            ("=f8", |v| v.to_ne_bytes().to_vec(), &neg),
        ];
        for (descr, enc, values) in cases {
            let data: Vec<u8> = values.iter().flat_map(|&v| enc(v)).collect();
            let header =
                format!("{{'descr': '{descr}', 'fortran_order': True, 'shape': (2, 2, 2), }}");
            let p = write(dir.path(), "t.npy", &npy_bytes(1, &header, &data));
            let v = read_npy(&p).unwrap_or_else(|e| panic!("{descr}: {e}"));
            let want: Vec<f32> = values.iter().map(|&v| v as f32).collect();
            assert_eq!(v.values(), want, "{descr}");
        }
    }

    #[test]
    fn bool_and_half_decode() {
        let dir = tempfile::tempdir().unwrap();
        let h = "{'descr': '|b1', 'fortran_order': True, 'shape': (2, 2, 2), }";
        let p = write(
            dir.path(),
            "b.npy",
            &npy_bytes(1, h, &[0, 1, 2, 0, 255, 0, 0, 1]),
        );
        assert_eq!(
            *read_npy(&p).unwrap().values(),
            [0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0]
        );

        let halves: [u16; 8] = [
            0x0000, 0x3c00, 0xc000, 0x7bff, 0x0001, 0x3555, 0x7c00, 0x8000,
        ];
        let data: Vec<u8> = halves.iter().flat_map(|h| h.to_be_bytes()).collect();
        let h = "{'descr': '>f2', 'fortran_order': True, 'shape': (2, 2, 2), }";
        let p = write(dir.path(), "h.npy", &npy_bytes(3, h, &data));
        let v = read_npy(&p).unwrap();
        let want = [
            0.0,
            1.0,
            -2.0,
            65504.0,
            2f32.powi(-24),
            0.333_251_95,
            f32::INFINITY,
            -0.0,
        ];
        assert_eq!(*v.values(), want);
        assert!(v.values()[7].is_sign_negative());
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    #[test]
    fn header_errors_never_panic() {
        let good = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), }";
        let msg = npy_err(b"");
        assert!(msg.contains("too short"), "{msg}");
        let msg = npy_err(b"\x93NUMPX\x01\x00\x10\x00{}");
        assert!(msg.contains("\\x93NUMPY"), "{msg}");
        let msg = npy_err(b"\x93NUMPY\x04\x00\x10\x00");
        assert!(msg.contains("version 4.0"), "{msg}");
        let msg = npy_err(b"\x93NUMPY\x02\x00\x10\x00");
        assert!(msg.contains("truncated"), "{msg}");
        // Header length larger than the file.
        let mut b = npy_bytes(1, good, &f32_data(8));
        b.truncate(40);
        let msg = npy_err(&b);
        assert!(msg.contains("truncated"), "{msg}");
        // Header length over the limit.
        let msg = npy_err(b"\x93NUMPY\x02\x00\x00\x00\x20\x00    ");
        assert!(msg.contains("limit"), "{msg}");

        let msg = npy_err(&npy_bytes(
            1,
            "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 2), }",
            &f32_data(8),
        ));
        assert!(msg.contains("shape (4, 2)"), "{msg}");
        assert!(msg.contains("3-D"), "{msg}");
        let msg = npy_err(&npy_bytes(
            1,
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2, 1), }",
            &f32_data(8),
        ));
        assert!(msg.contains("(2, 2, 2, 1)"), "{msg}");

        for descr in ["'<c8'", "'|O'", "'<U3'", "'<f16'", "'f4'", "[('a', '<f4')]"] {
            let h = format!("{{'descr': {descr}, 'fortran_order': False, 'shape': (2, 2, 2), }}");
            let msg = npy_err(&npy_bytes(1, &h, &f32_data(8)));
            assert!(msg.contains("unsupported .npy dtype descr"), "{msg}");
            assert!(msg.contains(descr), "{msg}");
        }

        // A shape that lies about the data size, either way.
        let big = "{'descr': '<f4', 'fortran_order': False, 'shape': (100, 100, 100), }";
        let msg = npy_err(&npy_bytes(1, big, &f32_data(8)));
        assert!(msg.contains("4000000 bytes"), "{msg}");
        assert!(msg.contains("32 bytes of data"), "{msg}");
        let msg = npy_err(&npy_bytes(1, good, &f32_data(9)));
        assert!(msg.contains("36 bytes of data"), "{msg}");
        let huge = "{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296, 4294967296), }";
        let msg = npy_err(&npy_bytes(1, huge, &f32_data(8)));
        assert!(msg.contains("too large"), "{msg}");
        let enormous = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2, 99999999999999999999999999999999999999999), }";
        let msg = npy_err(&npy_bytes(1, enormous, &f32_data(8)));
        assert!(
            msg.contains("malformed") || msg.contains("too large"),
            "{msg}"
        );

        // Thin arrays are valid .npy but not volumes.
        let thin = "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2, 4), }";
        let msg = npy_err(&npy_bytes(1, thin, &f32_data(8)));
        assert!(msg.contains("at least 2 points"), "{msg}");
        let empty = "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 2, 4), }";
        npy_err(&npy_bytes(1, empty, &[]));
    }

    #[test]
    fn malformed_dicts_are_refused() {
        let bad_headers = [
            "",
            "not a dict",
            "{'descr': '<f4', 'fortran_order': False}",
            "{'descr': '<f4', 'fortran_order': 0, 'shape': (2, 2, 2)}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': [2, 2, 2]}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, -2, 2)}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), 'x': 1}",
            "{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2)}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2)} extra",
            "{'descr': '<f4' 'fortran_order': False, 'shape': (2, 2, 2)}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2",
            "{'descr': '<f4, 'fortran_order': False, 'shape': (2, 2, 2)}",
            "{'descr': '<f4', 'fortran_order': Maybe, 'shape': (2, 2, 2)}",
            "{1: '<f4'}",
        ];
        for h in bad_headers {
            npy_err(&npy_bytes(1, h, &f32_data(8)));
        }
        let deep = format!("{}{}", "[".repeat(10_000), "]".repeat(10_000));
        npy_err(&npy_bytes(2, &deep, &f32_data(8)));
        npy_err(&npy_bytes(1, "{'descr': '\u{e9}f4'}", &[]));
    }

    #[test]
    fn header_variants_numpy_might_write_are_accepted() {
        for h in [
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), }",
            "{'descr':'<f4','fortran_order':False,'shape':(2,2,2)}",
            "{'shape': (2L, 2L, 2L), 'descr': '<f4', 'fortran_order': False}",
            "{ 'descr' : \"<f4\" ,\n 'fortran_order' : False , 'shape' : ( 2 , 2 , 2 , ) , }",
        ] {
            assert_eq!(
                parse_header(h),
                Ok((Elem::Plain(DType::F32, Endian::Little), false, [2, 2, 2])),
                "{h}"
            );
        }
    }

    #[test]
    fn garbage_never_panics() {
        // Mutations of a valid file: every truncation and many single-byte changes.
        let dir = tempfile::tempdir().unwrap();
        let good = npy_bytes(
            1,
            "{'descr': '<i2', 'fortran_order': False, 'shape': (2, 2, 2), }",
            &[1u8; 16],
        );
        let p = dir.path().join("m.npy");
        for cut in 0..good.len() {
            fs::write(&p, &good[..cut]).unwrap();
            assert!(read_npy(&p).is_err(), "cut at {cut}");
        }
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..2000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let mut b = good.clone();
            let i = (seed % b.len() as u64) as usize;
            b[i] = (seed >> 32) as u8;
            fs::write(&p, &b).unwrap();
            let _ = read_npy(&p);
        }
    }

    #[test]
    fn descr_names_are_canonical() {
        assert_eq!(descr_name(Elem::Plain(DType::F32, Endian::Big)), ">f4");
        assert_eq!(descr_name(Elem::Plain(DType::U16, Endian::Little)), "<u2");
        assert_eq!(descr_name(Elem::Plain(DType::I32, Endian::Little)), "<i4");
        assert_eq!(descr_name(Elem::Bool), "|b1");
        assert_eq!(descr_name(Elem::F16(Endian::Little)), "<f2");
    }
}
