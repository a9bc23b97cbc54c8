//! The NetCDF-3 header (the "classic" file format specification,
//! <https://docs.unidata.ucar.edu/netcdf-c/current/file_format_specifications.html>,
//! and the CDF-5 one, <https://cucis.ece.northwestern.edu/projects/PnetCDF/CDF-5.html>):
//!
//! ```text
//! header    = magic numrecs dim_list gatt_list var_list
//! magic     = 'C' 'D' 'F' VERSION          (1 classic, 2 64-bit offset, 5 64-bit data)
//! numrecs   = NON_NEG | STREAMING
//! dim_list  = ABSENT | NC_DIMENSION nelems [dim ...]     dim  = name dim_length (0: the record dimension)
//! att_list  = ABSENT | NC_ATTRIBUTE nelems [attr ...]    attr = name nc_type nelems [values] (padded to 4)
//! var_list  = ABSENT | NC_VARIABLE  nelems [var ...]     var  = name nelems [dimid ...] vatt_list nc_type vsize begin
//! name      = nelems namestring (padded to 4)
//! ```
//!
//! All big-endian. NON_NEG (counts, lengths, dimension ids, `vsize`) is a
//! 32-bit integer in CDF-1 and CDF-2 and a 64-bit one in CDF-5; `begin`
//! is 32-bit in CDF-1 and 64-bit in CDF-2 and CDF-5; tags and `nc_type`
//! are always 32-bit.
//!
//! Every count is checked against the bytes left in the file before
//! anything it sizes is allocated (an element takes at least one byte,
//! a list entry at least eight), so a lying header costs no memory.
//!
//! The layer both NetCDF-3 readers read on (the CF reader, `mod.rs`, and
//! MINC1's, `formats/minc1.rs`): a file opened and its header parsed
//! ([`open`]), a variable's values read ([`read_values`],
//! [`small_values`]).

use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use crate::error::IoError;
use crate::shared::cf::{Packing, Value};
use crate::shared::input::open_input;

/// A NetCDF-3 external type (`nc_type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NcType {
    Byte,
    Char,
    Short,
    Int,
    Float,
    Double,
    UByte,
    UShort,
    UInt,
    Int64,
    UInt64,
}

impl NcType {
    fn from_code(code: u32, version: u8) -> Option<NcType> {
        let t = match code {
            1 => NcType::Byte,
            2 => NcType::Char,
            3 => NcType::Short,
            4 => NcType::Int,
            5 => NcType::Float,
            6 => NcType::Double,
            7 => NcType::UByte,
            8 => NcType::UShort,
            9 => NcType::UInt,
            10 => NcType::Int64,
            11 => NcType::UInt64,
            _ => return None,
        };
        // The types past double are CDF-5's.
        (code <= 6 || version == 5).then_some(t)
    }

    /// Bytes per value.
    pub(crate) fn size(self) -> u64 {
        match self {
            NcType::Byte | NcType::Char | NcType::UByte => 1,
            NcType::Short | NcType::UShort => 2,
            NcType::Int | NcType::Float | NcType::UInt => 4,
            NcType::Double | NcType::Int64 | NcType::UInt64 => 8,
        }
    }

    /// The type's name as `volray info` shows it.
    pub(crate) fn name(self) -> &'static str {
        match self {
            NcType::Byte => "int8",
            NcType::Char => "char",
            NcType::Short => "int16",
            NcType::Int => "int32",
            NcType::Float => "float32",
            NcType::Double => "float64",
            NcType::UByte => "uint8",
            NcType::UShort => "uint16",
            NcType::UInt => "uint32",
            NcType::Int64 => "int64",
            NcType::UInt64 => "uint64",
        }
    }

    pub(crate) fn is_integer(self) -> bool {
        !matches!(self, NcType::Float | NcType::Double | NcType::Char)
    }

    /// The big-endian value at the start of `b` (`b` holds `size()` bytes).
    pub(crate) fn decode(self, b: &[u8]) -> f64 {
        match self {
            NcType::Byte => f64::from(b[0] as i8),
            NcType::Char | NcType::UByte => f64::from(b[0]),
            NcType::Short => f64::from(i16::from_be_bytes([b[0], b[1]])),
            NcType::UShort => f64::from(u16::from_be_bytes([b[0], b[1]])),
            NcType::Int => f64::from(i32::from_be_bytes([b[0], b[1], b[2], b[3]])),
            NcType::UInt => f64::from(u32::from_be_bytes([b[0], b[1], b[2], b[3]])),
            NcType::Float => f64::from(f32::from_be_bytes([b[0], b[1], b[2], b[3]])),
            NcType::Double => f64::from_be_bytes(b[..8].try_into().unwrap_or([0; 8])),
            NcType::Int64 => i64::from_be_bytes(b[..8].try_into().unwrap_or([0; 8])) as f64,
            NcType::UInt64 => u64::from_be_bytes(b[..8].try_into().unwrap_or([0; 8])) as f64,
        }
    }
}

/// A dimension.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Dim {
    pub name: String,
    /// Its length; for the record dimension, the number of records.
    pub len: u64,
    pub record: bool,
}

/// A variable's header entry.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Var {
    pub name: String,
    /// Indices into [`Header::dims`], slowest first.
    pub dims: Vec<usize>,
    pub attrs: Vec<(String, Value)>,
    pub ty: NcType,
    /// Where its data start (a record variable: its part of record 0).
    pub begin: u64,
    /// Whether its first dimension is the record dimension.
    pub record: bool,
}

/// A parsed header.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Header {
    /// 1, 2 or 5.
    pub version: u8,
    pub dims: Vec<Dim>,
    pub attrs: Vec<(String, Value)>,
    pub vars: Vec<Var>,
    /// The number of records (counted from the file's length where the
    /// header says "streaming").
    pub numrecs: u64,
    /// Bytes from one record to the next.
    pub recsize: u64,
    /// The file's length.
    pub len: u64,
}

impl Header {
    /// The lengths of `var`'s dimensions.
    pub(crate) fn shape(&self, var: &Var) -> Vec<u64> {
        var.dims.iter().map(|&d| self.dims[d].len).collect()
    }

    /// The bytes of `var` in one record (record variables) or in all
    /// (others), unpadded; `None` on overflow.
    pub(crate) fn var_bytes(&self, var: &Var) -> Option<u64> {
        var.dims
            .iter()
            .skip(usize::from(var.record))
            .try_fold(var.ty.size(), |acc, &d| acc.checked_mul(self.dims[d].len))
    }
}

/// Reads the header of the NetCDF-3 file at `path` (`len` bytes).
pub(crate) fn parse(path: &Path, file: std::fs::File, len: u64) -> Result<Header, IoError> {
    let mut p = Parser {
        path,
        r: BufReader::new(file),
        at: 0,
        len,
        version: 0,
    };
    let magic = p.bytes(4, "magic")?;
    if &magic[..3] != b"CDF" || !matches!(magic[3], 1 | 2 | 5) {
        return Err(p.fail(format!(
            "magic {:?}: not NetCDF-3 (CDF followed by 1, 2 or 5)",
            String::from_utf8_lossy(&magic)
        )));
    }
    p.version = magic[3];
    let numrecs_raw = p.non_neg_raw("numrecs")?;

    // Dimensions.
    let n = p.list(0x0A, "dimension list")?;
    let mut dims: Vec<Dim> = Vec::new();
    let mut record_dim = None;
    for i in 0..n {
        let name = p.name("dimension name")?;
        let dim_len = p.non_neg("dimension length")?;
        if dim_len == 0 {
            if record_dim.is_some() {
                return Err(p.fail(format!(
                    "dimension {name}: a second record (unlimited) dimension"
                )));
            }
            record_dim = Some(i);
        }
        dims.push(Dim {
            name,
            len: dim_len,
            record: dim_len == 0,
        });
    }
    let attrs = p.attrs("global attributes")?;

    // Variables.
    let n = p.list(0x0B, "variable list")?;
    let mut vars = Vec::new();
    for _ in 0..n {
        let name = p.name("variable name")?;
        let rank = p.count(4, &format!("variable {name}: number of dimensions"))?;
        let mut ids = Vec::with_capacity(rank);
        for _ in 0..rank {
            let id = p.non_neg(&format!("variable {name}: dimension id"))?;
            let id = usize::try_from(id)
                .ok()
                .filter(|&id| id < dims.len())
                .ok_or_else(|| {
                    p.fail(format!(
                        "variable {name}: dimension id {id}, but the file has {} dimensions",
                        dims.len()
                    ))
                })?;
            ids.push(id);
        }
        if let Some(k) = ids.iter().skip(1).position(|&d| Some(d) == record_dim) {
            return Err(p.fail(format!(
                "variable {name}: the record dimension is its dimension {}, not its first",
                k + 1
            )));
        }
        let attrs = p.attrs(&format!("attributes of variable {name}"))?;
        let code = p.u32(&format!("variable {name}: type"))?;
        let ty = NcType::from_code(code, p.version).ok_or_else(|| {
            p.fail(format!(
                "variable {name}: type code {code} is not a NetCDF-{} type",
                if p.version == 5 {
                    "3 CDF-5"
                } else {
                    "3 classic"
                }
            ))
        })?;
        // vsize may be wrong for large variables (the spec says so): the
        // sizes are computed from the dimensions instead.
        let _vsize = p.non_neg(&format!("variable {name}: vsize"))?;
        let begin = if p.version == 1 {
            u64::from(p.u32(&format!("variable {name}: begin"))?)
        } else {
            p.u64(&format!("variable {name}: begin"))?
        };
        let record = ids.first().is_some_and(|&d| Some(d) == record_dim);
        vars.push(Var {
            name,
            dims: ids,
            attrs,
            ty,
            begin,
            record,
        });
    }
    let header_end = p.at;

    let mut header = Header {
        version: p.version,
        dims,
        attrs,
        vars,
        numrecs: 0,
        recsize: 0,
        len,
    };
    // The record size: the record variables' parts, each padded to 4
    // bytes, but for a single record variable, which is not padded (spec:
    // "the special case ... of only one record variable").
    let record_vars: Vec<&Var> = header.vars.iter().filter(|v| v.record).collect();
    let mut recsize: u64 = 0;
    for v in &record_vars {
        let bytes = header.var_bytes(v).ok_or_else(|| {
            IoError::invalid(
                path,
                format!("NetCDF: variable {}: its size overflows", v.name),
            )
        })?;
        let padded = if record_vars.len() == 1 {
            bytes
        } else {
            bytes.checked_add(3).map(|b| b & !3).unwrap_or(u64::MAX)
        };
        recsize = recsize.saturating_add(padded);
    }
    let streaming = match p.version {
        5 => numrecs_raw == u64::MAX,
        _ => numrecs_raw == u64::from(u32::MAX),
    };
    let first = record_vars.iter().map(|v| v.begin).min();
    let numrecs = if streaming {
        match first {
            Some(b) if recsize > 0 => len.saturating_sub(b) / recsize,
            _ => 0,
        }
    } else {
        numrecs_raw
    };
    if let (Some(b), true) = (first, recsize > 0) {
        let need = u128::from(b) + u128::from(numrecs) * u128::from(recsize);
        if need > u128::from(len) + u128::from(recsize) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NetCDF: numrecs {numrecs} records of {recsize} bytes from byte {b} need {need} bytes, the file has {len}"
                ),
            ));
        }
    }
    header.numrecs = numrecs;
    header.recsize = recsize;
    if let Some(d) = record_dim {
        header.dims[d].len = numrecs;
    }
    for v in &header.vars {
        if v.begin < header_end {
            return Err(IoError::invalid(
                path,
                format!(
                    "NetCDF: variable {}: data begin at byte {}, inside the header (which ends at {header_end})",
                    v.name, v.begin
                ),
            ));
        }
    }
    Ok(header)
}

/// A cursor over the header that knows how many bytes are left.
struct Parser<'a> {
    path: &'a Path,
    r: BufReader<std::fs::File>,
    at: u64,
    len: u64,
    version: u8,
}

impl Parser<'_> {
    fn fail(&self, reason: String) -> IoError {
        IoError::invalid(
            self.path,
            format!("NetCDF header (byte {}): {reason}", self.at),
        )
    }

    fn left(&self) -> u64 {
        self.len.saturating_sub(self.at)
    }

    /// `n` bytes, checked against what is left before allocating.
    fn bytes(&mut self, n: u64, what: &str) -> Result<Vec<u8>, IoError> {
        if n > self.left() {
            return Err(self.fail(format!(
                "{what} needs {n} bytes, {} are left in the file: truncated or not NetCDF",
                self.left()
            )));
        }
        let mut buf = vec![0u8; n as usize];
        self.r
            .read_exact(&mut buf)
            .map_err(|e| IoError::os(self.path, "read", e))?;
        self.at += n;
        Ok(buf)
    }

    fn skip_padding(&mut self, n: u64) -> Result<(), IoError> {
        let pad = (4 - n % 4) % 4;
        if pad > 0 {
            self.bytes(pad, "padding")?;
        }
        Ok(())
    }

    fn u32(&mut self, what: &str) -> Result<u32, IoError> {
        let b = self.bytes(4, what)?;
        Ok(u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u64(&mut self, what: &str) -> Result<u64, IoError> {
        let b = self.bytes(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(&b);
        Ok(u64::from_be_bytes(a))
    }

    /// A NON_NEG as stored (u32 or u64), without the sign check.
    fn non_neg_raw(&mut self, what: &str) -> Result<u64, IoError> {
        if self.version == 5 {
            self.u64(what)
        } else {
            self.u32(what).map(u64::from)
        }
    }

    /// A NON_NEG: a non-negative count or length.
    fn non_neg(&mut self, what: &str) -> Result<u64, IoError> {
        let v = self.non_neg_raw(what)?;
        let limit = if self.version == 5 {
            i64::MAX as u64
        } else {
            i32::MAX as u64
        };
        if v > limit {
            return Err(self.fail(format!("{what} {v} is negative")));
        }
        Ok(v)
    }

    /// A count of items taking at least `min_bytes` each, checked against
    /// what is left of the file.
    fn count(&mut self, min_bytes: u64, what: &str) -> Result<usize, IoError> {
        let n = self.non_neg(what)?;
        if n.saturating_mul(min_bytes) > self.left() {
            return Err(self.fail(format!(
                "{what} {n}: more than the {} bytes left in the file hold",
                self.left()
            )));
        }
        Ok(n as usize)
    }

    /// A list's tag and count: 0 for ABSENT.
    fn list(&mut self, tag: u32, what: &str) -> Result<usize, IoError> {
        let t = self.u32(what)?;
        if t == 0 {
            let n = self.non_neg_raw(what)?;
            if n != 0 {
                return Err(self.fail(format!("{what}: absent but with {n} elements")));
            }
            return Ok(0);
        }
        if t != tag {
            return Err(self.fail(format!("{what}: tag {t:#x}, expected {tag:#x} or 0")));
        }
        self.count(8, what)
    }

    fn name(&mut self, what: &str) -> Result<String, IoError> {
        let n = self.non_neg(what)?;
        let b = self.bytes(n, what)?;
        self.skip_padding(n)?;
        Ok(String::from_utf8_lossy(&b).into_owned())
    }

    fn attrs(&mut self, what: &str) -> Result<Vec<(String, Value)>, IoError> {
        let n = self.list(0x0C, what)?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let name = self.name(&format!("{what}: name"))?;
            let code = self.u32(&format!("attribute {name}: type"))?;
            let ty = NcType::from_code(code, self.version)
                .ok_or_else(|| self.fail(format!("attribute {name}: type code {code}")))?;
            let count = self.non_neg(&format!("attribute {name}: count"))?;
            let bytes = count.saturating_mul(ty.size());
            let raw = self.bytes(bytes, &format!("attribute {name}: values"))?;
            self.skip_padding(bytes)?;
            let value = if ty == NcType::Char {
                let text = String::from_utf8_lossy(&raw);
                Value::Text(text.trim_end_matches('\0').to_string())
            } else {
                Value::Numbers(
                    raw.chunks_exact(ty.size() as usize)
                        .map(|c| ty.decode(c))
                        .collect(),
                )
            };
            out.push((name, value));
        }
        Ok(out)
    }
}

/// The byte offset of C-order element `idx` of `var` (across records for
/// a record variable: record `r`'s part lies at `begin + r · recsize`), in
/// `u128` so that no lying header can wrap it.
fn element_offset(header: &Header, var: &Var, idx: u64) -> u128 {
    let size = u128::from(var.ty.size());
    if var.record {
        let per_record = (header.var_bytes(var).unwrap_or(0) / var.ty.size()).max(1);
        let (r, k) = (idx / per_record, idx % per_record);
        u128::from(var.begin) + u128::from(r) * u128::from(header.recsize) + u128::from(k) * size
    } else {
        u128::from(var.begin) + u128::from(idx) * size
    }
}

/// Checks that the elements of `var` up to C-order element `last` lie in
/// the file, before a reader allocates room for them: a header of 100
/// bytes may declare a 2048³ variable (offsets grow with the element, so
/// the last one is the one to check).
pub(crate) fn check_in_file(
    path: &Path,
    header: &Header,
    var: &Var,
    last: u64,
) -> Result<(), IoError> {
    let end = element_offset(header, var, last) + u128::from(var.ty.size());
    if end > u128::from(header.len) {
        return Err(IoError::invalid(
            path,
            format!(
                "NetCDF: variable {} of shape {:?}: its data end at byte {end}, past the end of the file ({} bytes): truncated, or a header that declares more than the file holds",
                var.name,
                header.shape(var),
                header.len
            ),
        ));
    }
    Ok(())
}

/// Reads `count` values of `var` from C-order element `first` on, in
/// the file `header` describes, decoded to `f64` and handed to `sink`
/// with their place (0 for the first); the elements may span records.
/// Reads in runs of at most 64 Ki values, so the scratch memory is small.
pub(crate) fn read_values(
    path: &Path,
    file: &mut std::fs::File,
    header: &Header,
    var: &Var,
    first: u64,
    count: usize,
    sink: &mut dyn FnMut(usize, f64),
) -> Result<(), IoError> {
    let size = var.ty.size();
    let per_record = if var.record {
        (header.var_bytes(var).unwrap_or(0) / size).max(1)
    } else {
        u64::MAX
    };
    let mut done = 0usize;
    let mut buf = Vec::new();
    while done < count {
        let idx = first + done as u64;
        // A run: to the end of the record (record variables) or of what
        // is wanted.
        let offset = element_offset(header, var, idx);
        let in_run = if var.record {
            per_record - idx % per_record
        } else {
            u64::MAX
        };
        let n = in_run.min((count - done) as u64).min(1 << 16) as usize;
        let bytes = n as u64 * size;
        if offset + u128::from(bytes) > u128::from(header.len) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NetCDF: variable {}: its data at bytes {offset}..{} lie past the end of the file ({} bytes): truncated",
                    var.name,
                    offset + u128::from(bytes),
                    header.len
                ),
            ));
        }
        buf.resize(bytes as usize, 0);
        file.seek(SeekFrom::Start(offset as u64))
            .map_err(|e| IoError::os(path, "seek in", e))?;
        file.read_exact(&mut buf)
            .map_err(|e| IoError::os(path, "read", e))?;
        for (i, c) in buf.chunks_exact(size as usize).enumerate() {
            sink(done + i, var.ty.decode(c));
        }
        done += n;
    }
    Ok(())
}

/// Opens and parses the NetCDF-3 file at `path`.
pub(crate) fn open(path: &Path) -> Result<(std::fs::File, Header), IoError> {
    let (file, len) = open_input(path)?;
    let parse_from = file.try_clone().map_err(|e| IoError::os(path, "open", e))?;
    let header = parse(path, parse_from, len)?;
    Ok((file, header))
}

/// All values of the small variable `var` (a coordinate variable, a MINC
/// scale), unpacked by `packing`; refused past `limit` values.
pub(crate) fn small_values(
    path: &Path,
    file: &mut std::fs::File,
    header: &Header,
    var: &Var,
    packing: Option<&Packing>,
    limit: u64,
) -> Result<Vec<f64>, IoError> {
    let n = header
        .shape(var)
        .iter()
        .try_fold(1u64, |a, &d| a.checked_mul(d))
        .filter(|&n| n <= limit && n.saturating_mul(var.ty.size()) <= header.len)
        .ok_or_else(|| {
            IoError::invalid(
                path,
                format!(
                    "NetCDF: variable {} of shape {:?} is larger than the file or than {limit} values",
                    var.name,
                    header.shape(var)
                ),
            )
        })?;
    let mut out = vec![0.0; n as usize];
    read_values(path, file, header, var, 0, n as usize, &mut |i, v| {
        out[i] = packing.map_or(v, |p| p.real(v));
    })?;
    Ok(out)
}
