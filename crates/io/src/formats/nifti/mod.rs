//! NIfTI-1 and NIfTI-2 volumes: `.nii`, `.nii.gz` and `.hdr`/`.img` pairs.
//!
//! The 348-byte NIfTI-1 and 540-byte NIfTI-2 headers are parsed here (the
//! `nifti` crate reads NIfTI-1 only), in either byte order: the byte order
//! is the one in which `sizeof_hdr` reads 348 or 540, as nibabel and
//! nifti1_io decide it. A gzip file (`.nii.gz`, or any file starting with
//! the gzip magic) is inflated as a stream, so a header that lies about the
//! data size runs into the end of the stream instead of making volray
//! allocate what it claims.
//!
//! Interpretation, following the NIfTI-1 standard (nifti1.h) and nibabel:
//! - values are `scl_slope · stored + scl_inter` when `scl_slope` is
//!   finite and non-zero (0 or NaN means "no scaling");
//! - world coordinates (RAS+, as nibabel's affine) come from the sform
//!   (`srow_x/y/z`) if `sform_code > 0`, else from the qform quaternion if
//!   `qform_code > 0` (nifti1.h "method 2"), else from `pixdim` alone
//!   ("method 1", origin at 0); they go through [`grid_to_volume`];
//! - `xyzt_units` names the length unit (m, mm, µm), which is reported, not
//!   converted;
//! - a 4-D file holds `dim[4]` volumes and `--frame` picks one; 5-D and
//!   higher data (any `dim[5..]` above 1) are refused, as are complex, RGB,
//!   bit and 128-bit float samples.

use std::fs::File;
use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use flate2::read::MultiGzDecoder;
use volray_core::glam::{DMat3, DVec3};

use crate::error::IoError;
use crate::shared::dtype::{DType, Endian, extend_f32};
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::{open_input, read_exact_at};
use crate::shared::limits::{F32_BYTES, check_frame_dims};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

use crate::shared::compress::MAX_DEFLATE_RATIO;

/// Samples decoded per read: bounds the scratch buffer beside the output.
const CHUNK_SAMPLES: usize = 1 << 16;

/// The two header layouts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Version {
    Nifti1,
    Nifti2,
}

impl Version {
    fn header_len(self) -> usize {
        match self {
            Version::Nifti1 => 348,
            Version::Nifti2 => 540,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Version::Nifti1 => "NIfTI-1",
            Version::Nifti2 => "NIfTI-2",
        }
    }

    fn fields(self) -> &'static [Field] {
        match self {
            Version::Nifti1 => NIFTI1_FIELDS,
            Version::Nifti2 => NIFTI2_FIELDS,
        }
    }
}

/// How a header field is stored.
#[derive(Debug, Clone, Copy)]
enum Kind {
    /// A single byte, unsigned (`char` fields such as `dim_info`).
    U8,
    I16,
    I32,
    I64,
    F32,
    F64,
    /// A NUL-padded character array.
    Text,
}

impl Kind {
    fn size(self) -> usize {
        match self {
            Kind::U8 | Kind::Text => 1,
            Kind::I16 => 2,
            Kind::I32 | Kind::F32 => 4,
            Kind::I64 | Kind::F64 => 8,
        }
    }
}

/// One header field: name, byte offset, storage and element count.
#[derive(Debug, Clone, Copy)]
struct Field(&'static str, usize, Kind, usize);

/// The NIfTI-1 header (nifti1.h, `struct nifti_1_header`), in file order.
const NIFTI1_FIELDS: &[Field] = &[
    Field("sizeof_hdr", 0, Kind::I32, 1),
    Field("data_type", 4, Kind::Text, 10),
    Field("db_name", 14, Kind::Text, 18),
    Field("extents", 32, Kind::I32, 1),
    Field("session_error", 36, Kind::I16, 1),
    Field("regular", 38, Kind::U8, 1),
    Field("dim_info", 39, Kind::U8, 1),
    Field("dim", 40, Kind::I16, 8),
    Field("intent_p1", 56, Kind::F32, 1),
    Field("intent_p2", 60, Kind::F32, 1),
    Field("intent_p3", 64, Kind::F32, 1),
    Field("intent_code", 68, Kind::I16, 1),
    Field("datatype", 70, Kind::I16, 1),
    Field("bitpix", 72, Kind::I16, 1),
    Field("slice_start", 74, Kind::I16, 1),
    Field("pixdim", 76, Kind::F32, 8),
    Field("vox_offset", 108, Kind::F32, 1),
    Field("scl_slope", 112, Kind::F32, 1),
    Field("scl_inter", 116, Kind::F32, 1),
    Field("slice_end", 120, Kind::I16, 1),
    Field("slice_code", 122, Kind::U8, 1),
    Field("xyzt_units", 123, Kind::U8, 1),
    Field("cal_max", 124, Kind::F32, 1),
    Field("cal_min", 128, Kind::F32, 1),
    Field("slice_duration", 132, Kind::F32, 1),
    Field("toffset", 136, Kind::F32, 1),
    Field("glmax", 140, Kind::I32, 1),
    Field("glmin", 144, Kind::I32, 1),
    Field("descrip", 148, Kind::Text, 80),
    Field("aux_file", 228, Kind::Text, 24),
    Field("qform_code", 252, Kind::I16, 1),
    Field("sform_code", 254, Kind::I16, 1),
    Field("quatern_b", 256, Kind::F32, 1),
    Field("quatern_c", 260, Kind::F32, 1),
    Field("quatern_d", 264, Kind::F32, 1),
    Field("qoffset_x", 268, Kind::F32, 1),
    Field("qoffset_y", 272, Kind::F32, 1),
    Field("qoffset_z", 276, Kind::F32, 1),
    Field("srow_x", 280, Kind::F32, 4),
    Field("srow_y", 296, Kind::F32, 4),
    Field("srow_z", 312, Kind::F32, 4),
    Field("intent_name", 328, Kind::Text, 16),
    Field("magic", 344, Kind::Text, 4),
];

/// The NIfTI-2 header (nifti2.h, `struct nifti_2_header`), in file order.
const NIFTI2_FIELDS: &[Field] = &[
    Field("sizeof_hdr", 0, Kind::I32, 1),
    Field("magic", 4, Kind::Text, 8),
    Field("datatype", 12, Kind::I16, 1),
    Field("bitpix", 14, Kind::I16, 1),
    Field("dim", 16, Kind::I64, 8),
    Field("intent_p1", 80, Kind::F64, 1),
    Field("intent_p2", 88, Kind::F64, 1),
    Field("intent_p3", 96, Kind::F64, 1),
    Field("pixdim", 104, Kind::F64, 8),
    Field("vox_offset", 168, Kind::I64, 1),
    Field("scl_slope", 176, Kind::F64, 1),
    Field("scl_inter", 184, Kind::F64, 1),
    Field("cal_max", 192, Kind::F64, 1),
    Field("cal_min", 200, Kind::F64, 1),
    Field("slice_duration", 208, Kind::F64, 1),
    Field("toffset", 216, Kind::F64, 1),
    Field("slice_start", 224, Kind::I64, 1),
    Field("slice_end", 232, Kind::I64, 1),
    Field("descrip", 240, Kind::Text, 80),
    Field("aux_file", 320, Kind::Text, 24),
    Field("qform_code", 344, Kind::I32, 1),
    Field("sform_code", 348, Kind::I32, 1),
    Field("quatern_b", 352, Kind::F64, 1),
    Field("quatern_c", 360, Kind::F64, 1),
    Field("quatern_d", 368, Kind::F64, 1),
    Field("qoffset_x", 376, Kind::F64, 1),
    Field("qoffset_y", 384, Kind::F64, 1),
    Field("qoffset_z", 392, Kind::F64, 1),
    Field("srow_x", 400, Kind::F64, 4),
    Field("srow_y", 432, Kind::F64, 4),
    Field("srow_z", 464, Kind::F64, 4),
    Field("slice_code", 496, Kind::I32, 1),
    Field("xyzt_units", 500, Kind::I32, 1),
    Field("intent_code", 504, Kind::I32, 1),
    Field("intent_name", 508, Kind::Text, 16),
    Field("dim_info", 524, Kind::U8, 1),
    Field("unused_str", 525, Kind::Text, 15),
];

/// A decoded header field.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Ints(Vec<i64>),
    Floats(Vec<f64>),
    Text(String),
}

impl Value {
    fn display(&self) -> String {
        let join = |items: Vec<String>| items.join(" ");
        match self {
            Value::Ints(v) => join(v.iter().map(|x| x.to_string()).collect()),
            Value::Floats(v) => join(v.iter().map(|x| x.to_string()).collect()),
            Value::Text(s) => s.clone(),
        }
    }
}

/// The header fields volray uses, decoded; `fields` keeps all of them as
/// written, for [`FileInfo::header`].
#[derive(Debug, Clone)]
struct Header {
    /// `n+1`/`n+2` (data in the same file) or `ni1`/`ni2` (a `.hdr`/`.img` pair).
    single_file: bool,
    dim: [i64; 8],
    datatype: i64,
    bitpix: i64,
    pixdim: [f64; 8],
    vox_offset: f64,
    scl_slope: f64,
    scl_inter: f64,
    xyzt_units: i64,
    qform_code: i64,
    sform_code: i64,
    quatern: [f64; 3],
    qoffset: [f64; 3],
    srow: [[f64; 4]; 3],
    fields: Vec<(&'static str, Value)>,
}

impl Header {
    fn ints(&self, name: &str) -> &[i64] {
        match self.get(name) {
            Some(Value::Ints(v)) => v,
            _ => &[],
        }
    }

    fn get(&self, name: &str) -> Option<&Value> {
        self.fields.iter().find(|(n, _)| *n == name).map(|(_, v)| v)
    }
}

/// The byte order and layout `sizeof_hdr` (the first 4 bytes) announces.
fn detect_version(path: &Path, first4: [u8; 4]) -> Result<(Version, Endian), IoError> {
    for endian in [Endian::Little, Endian::Big] {
        let n = match endian {
            Endian::Little => i32::from_le_bytes(first4),
            Endian::Big => i32::from_be_bytes(first4),
        };
        match n {
            348 => return Ok((Version::Nifti1, endian)),
            540 => return Ok((Version::Nifti2, endian)),
            _ => {}
        }
    }
    Err(IoError::invalid(
        path,
        format!(
            "NIfTI field \"sizeof_hdr\" is {} (bytes {:02x} {:02x} {:02x} {:02x}): expected 348 (NIfTI-1) or 540 (NIfTI-2) in either byte order",
            i32::from_le_bytes(first4),
            first4[0],
            first4[1],
            first4[2],
            first4[3]
        ),
    ))
}

/// Decodes the header `bytes` (exactly `version.header_len()` of them).
fn parse_header(
    path: &Path,
    bytes: &[u8],
    version: Version,
    endian: Endian,
) -> Result<Header, IoError> {
    debug_assert_eq!(bytes.len(), version.header_len());
    let mut fields = Vec::with_capacity(version.fields().len());
    for &Field(name, offset, kind, count) in version.fields() {
        let raw = &bytes[offset..offset + kind.size() * count];
        let value = match kind {
            Kind::Text => Value::Text(text(raw)),
            Kind::U8 => Value::Ints(raw.iter().map(|&b| i64::from(b)).collect()),
            Kind::I16 | Kind::I32 | Kind::I64 => Value::Ints(
                raw.chunks_exact(kind.size())
                    .map(|c| int(c, endian))
                    .collect(),
            ),
            Kind::F32 | Kind::F64 => Value::Floats(
                raw.chunks_exact(kind.size())
                    .map(|c| float(c, endian))
                    .collect(),
            ),
        };
        fields.push((name, value));
    }
    let find = |name: &str| fields.iter().find(|(n, _)| *n == name).map(|(_, v)| v);
    let ints = |name: &str| match find(name) {
        Some(Value::Ints(v)) => v.clone(),
        _ => vec![0],
    };
    let floats = |name: &str| match find(name) {
        Some(Value::Floats(v)) => v.clone(),
        Some(Value::Ints(v)) => v.iter().map(|&x| x as f64).collect(),
        _ => vec![0.0],
    };
    let first = |v: Vec<f64>| v[0];
    let mut dim = [0i64; 8];
    dim.copy_from_slice(&ints("dim"));
    let mut pixdim = [0.0; 8];
    pixdim.copy_from_slice(&floats("pixdim"));
    let row = |name: &str| {
        let mut r = [0.0; 4];
        r.copy_from_slice(&floats(name));
        r
    };
    let magic = match find("magic") {
        Some(Value::Text(m)) => m.clone(),
        _ => String::new(),
    };
    let mut header = Header {
        single_file: true,
        dim,
        datatype: ints("datatype")[0],
        bitpix: ints("bitpix")[0],
        pixdim,
        vox_offset: first(floats("vox_offset")),
        scl_slope: first(floats("scl_slope")),
        scl_inter: first(floats("scl_inter")),
        xyzt_units: ints("xyzt_units")[0],
        qform_code: ints("qform_code")[0],
        sform_code: ints("sform_code")[0],
        quatern: ["quatern_b", "quatern_c", "quatern_d"].map(|n| first(floats(n))),
        qoffset: ["qoffset_x", "qoffset_y", "qoffset_z"].map(|n| first(floats(n))),
        srow: [row("srow_x"), row("srow_y"), row("srow_z")],
        fields,
    };
    // NIfTI-2's magic continues with \r\n\x1a\n after the NUL, which
    // catches files mangled by text-mode transfers.
    let (single, pair, stored): (&[u8], &[u8], &[u8]) = match version {
        Version::Nifti1 => (b"n+1\0", b"ni1\0", &bytes[344..348]),
        Version::Nifti2 => (b"n+2\0\r\n\x1a\n", b"ni2\0\r\n\x1a\n", &bytes[4..12]),
    };
    if stored == single {
        header.single_file = true;
    } else if stored == pair {
        header.single_file = false;
    } else if version == Version::Nifti1 && magic.is_empty() {
        return Err(IoError::invalid(
            path,
            "NIfTI field \"magic\" is empty: this is an Analyze 7.5 header, which volray does not read (convert it to NIfTI)",
        ));
    } else {
        return Err(IoError::invalid(
            path,
            format!(
                "NIfTI field \"magic\" is {:?}: expected \"{}\" (single file) or \"{}\" (header/image pair) for a {} header",
                String::from_utf8_lossy(stored),
                text(single),
                text(pair),
                version.name()
            ),
        ));
    }

    Ok(header)
}

/// A NUL-terminated character array as text, control characters shown as `?`.
fn text(raw: &[u8]) -> String {
    let end = raw.iter().position(|&b| b == 0).unwrap_or(raw.len());
    String::from_utf8_lossy(&raw[..end])
        .chars()
        .map(|c| if c.is_control() { '?' } else { c })
        .collect::<String>()
        .trim_end()
        .to_string()
}

fn int(c: &[u8], endian: Endian) -> i64 {
    let mut b = [0u8; 8];
    let n = c.len();
    match endian {
        Endian::Little => b[..n].copy_from_slice(c),
        Endian::Big => {
            for (dst, src) in b[..n].iter_mut().zip(c.iter().rev()) {
                *dst = *src;
            }
        }
    }
    // Sign-extend from the field's width.
    let shift = 64 - 8 * n as u32;
    (i64::from_le_bytes(b) << shift) >> shift
}

fn float(c: &[u8], endian: Endian) -> f64 {
    match (c.len(), endian) {
        (4, Endian::Little) => f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        (4, Endian::Big) => f64::from(f32::from_be_bytes([c[0], c[1], c[2], c[3]])),
        (_, Endian::Little) => f64::from_le_bytes(c.try_into().unwrap_or([0; 8])),
        (_, Endian::Big) => f64::from_be_bytes(c.try_into().unwrap_or([0; 8])),
    }
}

/// The sample type of NIfTI datatype `code`, or why it is refused.
fn sample_type(code: i64) -> Result<(DType, &'static str), String> {
    Ok(match code {
        2 => (DType::U8, "uint8"),
        4 => (DType::I16, "int16"),
        8 => (DType::I32, "int32"),
        16 => (DType::F32, "float32"),
        64 => (DType::F64, "float64"),
        256 => (DType::I8, "int8"),
        512 => (DType::U16, "uint16"),
        768 => (DType::U32, "uint32"),
        1024 => (DType::I64, "int64"),
        1280 => (DType::U64, "uint64"),
        _ => {
            let what = match code {
                1 => "binary (1 bit per voxel)",
                32 => "complex64",
                128 => "RGB24",
                1536 => "float128",
                1792 => "complex128",
                2048 => "complex256",
                2304 => "RGBA32",
                _ => {
                    return Err(format!(
                        "NIfTI field \"datatype\" is {code}: not a NIfTI data type"
                    ));
                }
            };
            return Err(format!(
                "NIfTI field \"datatype\" is {code} ({what}): volray reads scalar volumes of integers, float32 or float64 only"
            ));
        }
    })
}

/// Where the samples come from: the `.nii` itself, or the `.img` of a pair,
/// plain or gzip-compressed.
enum Source {
    Plain(BufReader<File>),
    Gzip(Box<MultiGzDecoder<BufReader<File>>>),
}

impl Source {
    /// Opens `path`, telling gzip from plain data by the gzip magic.
    /// Returns the source and the file's length in bytes.
    fn open(path: &Path) -> Result<(Source, u64), IoError> {
        let (mut file, len) = open_input(path)?;
        let mut magic = [0u8; 2];
        let is_gzip = len >= 2 && {
            read_exact_at(path, &mut file, &mut magic, 0, len)?;
            file.seek(SeekFrom::Start(0))
                .map_err(|e| IoError::os(path, "seek in", e))?;
            magic == [0x1f, 0x8b]
        };
        let reader = BufReader::new(file);
        let source = if is_gzip {
            Source::Gzip(Box::new(MultiGzDecoder::new(reader)))
        } else {
            Source::Plain(reader)
        };
        Ok((source, len))
    }

    fn is_gzip(&self) -> bool {
        matches!(self, Source::Gzip(_))
    }

    /// Fills `buf` from the current position. `at` is that position in the
    /// (uncompressed) data and `expected` the total the header implies,
    /// both for messages.
    fn fill(&mut self, path: &Path, buf: &mut [u8], at: u64, expected: u64) -> Result<(), IoError> {
        match self {
            Source::Plain(r) => read_exact_at(path, r, buf, at, expected),
            Source::Gzip(r) => {
                let mut done = 0;
                while done < buf.len() {
                    match r.read(&mut buf[done..]) {
                        Ok(0) => {
                            return Err(IoError::invalid(
                                path,
                                format!(
                                    "gzip data ends after {} bytes, but the NIfTI header implies at least {expected}",
                                    at + done as u64
                                ),
                            ));
                        }
                        Ok(n) => done += n,
                        Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                        Err(e) => {
                            return Err(IoError::invalid(
                                path,
                                format!(
                                    "corrupt gzip stream after {} bytes: {e}",
                                    at + done as u64
                                ),
                            ));
                        }
                    }
                }
                Ok(())
            }
        }
    }

    /// Moves `n` bytes forward from position `at`.
    fn skip(&mut self, path: &Path, n: u64, at: u64, expected: u64) -> Result<(), IoError> {
        match self {
            Source::Plain(r) => r
                .seek_relative(i64::try_from(n).unwrap_or(i64::MAX))
                .map_err(|e| IoError::os(path, "seek in", e)),
            Source::Gzip(_) => {
                let mut scratch = vec![0u8; (n as usize).min(1 << 16)];
                let mut left = n;
                while left > 0 {
                    let k = (left as usize).min(scratch.len());
                    self.fill(path, &mut scratch[..k], at + (n - left), expected)?;
                    left -= k as u64;
                }
                Ok(())
            }
        }
    }
}

/// Reads the NIfTI file at `path` (see the module documentation).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (mut source, file_len) = Source::open(path)?;
    let header_source_gz = source.is_gzip();

    // The header: 4 bytes tell the layout and byte order, then the rest.
    let mut first4 = [0u8; 4];
    source
        .fill(path, &mut first4, 0, 348)
        .map_err(|e| short_header(path, e))?;
    let (version, endian) = detect_version(path, first4)?;
    let len = version.header_len();
    let mut bytes = vec![0u8; len];
    bytes[..4].copy_from_slice(&first4);
    source
        .fill(path, &mut bytes[4..], 4, len as u64)
        .map_err(|e| short_header(path, e))?;
    let header = parse_header(path, &bytes, version, endian)?;

    let layout = Layout::of(path, &header, opts.frame)?;
    let mut info = FileInfo::new(format!("{} ({}-endian)", layout.type_name, endian));
    info.header = header
        .fields
        .iter()
        .map(|(n, v)| (n.to_string(), v.display()))
        .collect();
    info.frames = layout.frames;
    info.frame = layout.frame;
    info.length_unit = length_unit(header.xyzt_units).map(str::to_string);
    info.notes.push(format!(
        "{} header, {} ({}-endian{})",
        version.name(),
        if header.single_file {
            "data in the same file"
        } else {
            "header/image pair"
        },
        endian,
        if header_source_gz { ", gzip" } else { "" }
    ));
    if layout.frames > 1 && opts.frame.is_none() {
        info.notes.push(format!(
            "the file holds {} volumes (dim[4]); volume 0 was read (choose one with --frame)",
            layout.frames
        ));
    }
    if header.bitpix != 8 * layout.dtype.size() as i64 {
        info.notes.push(format!(
            "bitpix {} disagrees with datatype {} ({}); the datatype was used",
            header.bitpix, header.datatype, layout.type_name
        ));
    }

    // Where the samples are: after the header (and its extensions) in a
    // single file, from vox_offset in the .img of a pair.
    let data_path;
    let (mut data_source, data_len, mut pos) = if header.single_file {
        data_path = path.to_path_buf();
        (source, file_len, len as u64)
    } else {
        data_path = image_path(path)?;
        let (s, l) = Source::open(&data_path)?;
        info.notes
            .push(format!("samples read from {}", data_path.display()));
        (s, l, 0)
    };
    let mut data_start = layout.vox_offset;
    if header.single_file && data_start == 0 {
        // Some writers leave vox_offset at 0 in a single file; nifti1_io
        // then reads the data right after the header and its 4-byte
        // extension flag.
        data_start = pos + 4;
        info.notes.push(format!(
            "vox_offset 0 in a single file: data read from byte {data_start}, after the header"
        ));
    }
    if data_start < pos {
        return Err(IoError::invalid(
            path,
            format!(
                "NIfTI field \"vox_offset\" is {}: the data cannot start inside the {}-byte header",
                header.vox_offset, len
            ),
        ));
    }
    // Everything the header implies must be there: all frames for a plain
    // file (checked against its length before allocating), up to the
    // wanted frame for a gzip stream (bounded by the deflate ratio).
    let needed_all = layout
        .total_bytes(data_start)
        .ok_or_else(|| too_big(path, &header))?;
    let needed = layout
        .bytes_through_frame(data_start)
        .ok_or_else(|| too_big(path, &header))?;
    if data_source.is_gzip() {
        if needed > data_len.saturating_mul(MAX_DEFLATE_RATIO) {
            return Err(IoError::invalid(
                &data_path,
                format!(
                    "the NIfTI header implies {needed} bytes of data, more than a {data_len}-byte gzip file can hold (dim {})",
                    dim_text(&header)
                ),
            ));
        }
    } else if data_len < needed_all {
        return Err(IoError::invalid(
            &data_path,
            format!(
                "file is {data_len} bytes, but the NIfTI header (vox_offset {}, dim {}, {}) implies {needed_all}",
                header.vox_offset,
                dim_text(&header),
                layout.type_name
            ),
        ));
    }

    // Header extensions sit between the header and vox_offset in a single
    // file; their flag is the 4 bytes after the header.
    if header.single_file && data_start >= pos + 4 {
        let mut extender = [0u8; 4];
        data_source.fill(&data_path, &mut extender, pos, needed)?;
        pos += 4;
        if extender[0] != 0 {
            info.notes.push(format!(
                "header extensions ({} bytes before vox_offset) ignored",
                data_start - pos
            ));
        }
    }
    let frame_start = data_start + layout.frame_bytes * layout.frame as u64;
    data_source.skip(&data_path, frame_start - pos, pos, needed)?;

    // The samples, in bounded chunks. A gzip stream grows the output as
    // data arrives, so a lying header fails at the end of the stream.
    let mut dims = layout.dims.to_vec();
    if layout.frames > 1 {
        dims.push(layout.frames);
    }
    check_frame_dims(
        path,
        "NIfTI field \"dim\"",
        &dims,
        layout.frames,
        F32_BYTES,
        opts.max_memory,
    )?;
    let count = layout.count;
    let size = layout.dtype.size();
    let mut data = Vec::with_capacity(if data_source.is_gzip() {
        count.min(CHUNK_SAMPLES)
    } else {
        count
    });
    let mut chunk = vec![0u8; count.min(CHUNK_SAMPLES) * size];
    let mut done = 0;
    while done < count {
        let n = (count - done).min(CHUNK_SAMPLES);
        let at = frame_start + (done * size) as u64;
        data_source.fill(&data_path, &mut chunk[..n * size], at, needed)?;
        extend_f32(&mut data, &chunk[..n * size], layout.dtype, endian);
        done += n;
    }

    apply_scaling(&header, &mut data, &mut info);
    let (steps, origin) = geometry(path, &header, &mut info)?;
    let volume = grid_to_volume(path, layout.dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Nifti,
        info,
    })
}

/// A header cut short reads as a bad file, whatever the source.
fn short_header(path: &Path, e: IoError) -> IoError {
    match e {
        IoError::Truncated { read, .. } => IoError::invalid(
            path,
            format!("file ends after {read} bytes, inside the NIfTI header"),
        ),
        other => other,
    }
}

/// The `dim` field as written, for messages.
fn dim_text(header: &Header) -> String {
    header
        .ints("dim")
        .iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

fn too_big(path: &Path, header: &Header) -> IoError {
    IoError::invalid(
        path,
        format!(
            "NIfTI field \"dim\" is {}: the data size overflows",
            dim_text(header)
        ),
    )
}

/// The data layout the header describes, checked.
struct Layout {
    dims: [usize; 3],
    count: usize,
    dtype: DType,
    type_name: &'static str,
    frames: usize,
    frame: usize,
    frame_bytes: u64,
    vox_offset: u64,
}

impl Layout {
    fn of(path: &Path, header: &Header, frame: Option<usize>) -> Result<Layout, IoError> {
        let (dtype, type_name) =
            sample_type(header.datatype).map_err(|reason| IoError::invalid(path, reason))?;
        let dim = header.dim;
        let ndim = dim[0];
        if !(1..=7).contains(&ndim) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim[0]\" is {ndim}: the number of dimensions must be 1 to 7"
                ),
            ));
        }
        let ndim = ndim as usize;
        if ndim < 3 {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim[0]\" is {ndim}: volray renders 3-D volumes, not {ndim}-D images"
                ),
            ));
        }
        for (a, &d) in dim.iter().enumerate().take(ndim + 1).skip(1) {
            if d < 1 {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "NIfTI field \"dim[{a}]\" is {d}: every used dimension must be at least 1"
                    ),
                ));
            }
        }
        if let Some(a) = (5..=ndim).find(|&a| dim[a] > 1) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim[{a}]\" is {}: {ndim}-D data (beyond a 4th dimension of volumes) is not supported",
                    dim[a]
                ),
            ));
        }
        let to_usize = |a: usize| usize::try_from(dim[a]).ok();
        let dims = [1, 2, 3].map(|a| to_usize(a).unwrap_or(usize::MAX));
        if dims.iter().any(|&n| n < 2) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"dim\" gives {}x{}x{} voxels: every axis needs at least 2",
                    dim[1], dim[2], dim[3]
                ),
            ));
        }
        let frames = if ndim >= 4 {
            to_usize(4).unwrap_or(usize::MAX)
        } else {
            1
        };
        let frame_index = frame.unwrap_or(0);
        if frame_index >= frames {
            return Err(IoError::invalid(
                path,
                format!(
                    "--frame {frame_index} is out of range: the file holds {frames} volume{} (dim[4]), numbered from 0",
                    if frames == 1 { "" } else { "s" }
                ),
            ));
        }
        let count = dims[0]
            .checked_mul(dims[1])
            .and_then(|n| n.checked_mul(dims[2]))
            .ok_or_else(|| too_big(path, header))?;
        let frame_bytes = (count as u64)
            .checked_mul(dtype.size() as u64)
            .ok_or_else(|| too_big(path, header))?;
        let v = header.vox_offset;
        if !(v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v < 2f64.powi(62)) {
            return Err(IoError::invalid(
                path,
                format!("NIfTI field \"vox_offset\" is {v}: it must be a whole number of bytes"),
            ));
        }
        Ok(Layout {
            dims,
            count,
            dtype,
            type_name,
            frames,
            frame: frame_index,
            frame_bytes,
            vox_offset: v as u64,
        })
    }

    /// Bytes from the start of the data file through the last frame.
    fn total_bytes(&self, start: u64) -> Option<u64> {
        self.frame_bytes
            .checked_mul(self.frames as u64)?
            .checked_add(start)
    }

    /// Bytes from the start of the data file through the wanted frame.
    fn bytes_through_frame(&self, start: u64) -> Option<u64> {
        self.frame_bytes
            .checked_mul(self.frame as u64 + 1)?
            .checked_add(start)
    }
}

/// The `.img` (or `.img.gz`) beside a `.hdr` (or `.hdr.gz`), keeping the
/// extension's case.
fn image_path(path: &Path) -> Result<PathBuf, IoError> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let lower = name.to_ascii_lowercase();
    let stem_len = if lower.ends_with(".hdr.gz") {
        name.len() - 7
    } else if lower.ends_with(".hdr") {
        name.len() - 4
    } else {
        return Err(IoError::invalid(
            path,
            "NIfTI magic says the data is in a separate .img file, but this header's name does not end in .hdr",
        ));
    };
    // ".hdr" -> ".img" letter by letter, so ".HDR" gives ".IMG".
    let ext = &name[stem_len..];
    let img_ext: String = ext
        .chars()
        .enumerate()
        .map(|(i, c)| match i {
            1..=3 => {
                let r = char::from(b"img"[i - 1]);
                if c.is_ascii_uppercase() {
                    r.to_ascii_uppercase()
                } else {
                    r
                }
            }
            _ => c,
        })
        .collect();
    Ok(path.with_file_name(format!("{}{}", &name[..stem_len], img_ext)))
}

/// The length unit of `xyzt_units` (its low 3 bits, nifti1.h `XYZT_TO_SPACE`).
fn length_unit(xyzt_units: i64) -> Option<&'static str> {
    match xyzt_units & 0x07 {
        1 => Some("m"),
        2 => Some("mm"),
        3 => Some("um"),
        _ => None,
    }
}

/// Applies `scl_slope`/`scl_inter` (nifti1.h: `y = scl_slope · x + scl_inter`
/// unless `scl_slope` is 0; nibabel also treats a NaN or infinite slope as
/// "no scaling").
fn apply_scaling(header: &Header, data: &mut [f32], info: &mut FileInfo) {
    let (slope, inter) = (header.scl_slope, header.scl_inter);
    if slope == 0.0 || !slope.is_finite() {
        if slope != 0.0 || (inter != 0.0 && !inter.is_nan()) {
            info.notes.push(format!(
                "scl_slope {slope} means no scaling; scl_inter {inter} ignored"
            ));
        }
        return;
    }
    let inter = if inter.is_finite() {
        inter
    } else {
        info.notes
            .push(format!("scl_inter {inter} is not finite: taken as 0"));
        0.0
    };
    if slope == 1.0 && inter == 0.0 {
        return;
    }
    for v in data.iter_mut() {
        *v = (f64::from(*v) * slope + inter) as f32;
    }
    info.notes.push(format!(
        "values scaled: value = {slope} * stored + {inter} (scl_slope, scl_inter)"
    ));
}

/// The name of an sform/qform code (nifti1.h `NIFTI_XFORM_*`).
fn xform_name(code: i64) -> &'static str {
    match code {
        1 => "scanner",
        2 => "aligned",
        3 => "talairach",
        4 => "mni_152",
        5 => "template",
        _ => "unknown code",
    }
}

/// The world step per index axis and the world position of voxel (0, 0, 0).
fn geometry(path: &Path, h: &Header, info: &mut FileInfo) -> Result<([DVec3; 3], DVec3), IoError> {
    if h.sform_code > 0 {
        let steps = [0, 1, 2].map(|a| DVec3::new(h.srow[0][a], h.srow[1][a], h.srow[2][a]));
        let origin = DVec3::new(h.srow[0][3], h.srow[1][3], h.srow[2][3]);
        info.notes.push(format!(
            "world coordinates (RAS+) from the sform (sform_code {} = {}){}",
            h.sform_code,
            xform_name(h.sform_code),
            if h.qform_code > 0 {
                "; the qform was not used"
            } else {
                ""
            }
        ));
        return Ok((steps, origin));
    }
    let zooms = pixdims(path, h)?;
    if h.qform_code > 0 {
        let [b, c, d] = h.quatern;
        if !(b.is_finite() && c.is_finite() && d.is_finite()) {
            return Err(IoError::invalid(
                path,
                format!("NIfTI qform quaternion (b, c, d) = ({b}, {c}, {d}) is not finite"),
            ));
        }
        let rotation = quaternion_rotation(b, c, d);
        // pixdim[0] is qfac: -1 mirrors the k axis (nifti1_io treats any
        // negative value as -1 and anything else as 1).
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let steps = [
            rotation.x_axis * zooms[0],
            rotation.y_axis * zooms[1],
            rotation.z_axis * (zooms[2] * qfac),
        ];
        let origin = DVec3::from(h.qoffset);
        info.notes.push(format!(
            "world coordinates (RAS+) from the qform quaternion (qform_code {} = {}; sform_code 0)",
            h.qform_code,
            xform_name(h.qform_code)
        ));
        return Ok((steps, origin));
    }
    info.notes.push(
        "no sform or qform (both codes 0): voxel sizes from pixdim, origin at 0 (NIfTI method 1)"
            .to_string(),
    );
    Ok((
        [
            DVec3::X * zooms[0],
            DVec3::Y * zooms[1],
            DVec3::Z * zooms[2],
        ],
        DVec3::ZERO,
    ))
}

/// `|pixdim[1..=3]|`, which must be finite and non-zero.
fn pixdims(path: &Path, h: &Header) -> Result<[f64; 3], IoError> {
    let mut zooms = [0.0; 3];
    for (a, zoom) in zooms.iter_mut().enumerate() {
        let p = h.pixdim[a + 1];
        if !(p.is_finite() && p != 0.0) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"pixdim[{}]\" is {p}: voxel sizes must be finite and non-zero",
                    a + 1
                ),
            ));
        }
        *zoom = p.abs();
    }
    Ok(zooms)
}

/// The rotation of the unit quaternion (a, b, c, d), a = √(1 − b² − c² − d²)
/// (nifti1.h, "METHOD 2"; as nifti1_io, a vector part longer than 1 is
/// normalised and a taken as 0: a 180° rotation).
fn quaternion_rotation(b: f64, c: f64, d: f64) -> DMat3 {
    let norm2 = b * b + c * c + d * d;
    let (a, b, c, d) = if 1.0 - norm2 < 1e-7 {
        let n = norm2.sqrt();
        (0.0, b / n, c / n, d / n)
    } else {
        ((1.0 - norm2).sqrt(), b, c, d)
    };
    DMat3::from_cols(
        DVec3::new(
            a * a + b * b - c * c - d * d,
            2.0 * (b * c + a * d),
            2.0 * (b * d - a * c),
        ),
        DVec3::new(
            2.0 * (b * c - a * d),
            a * a + c * c - b * b - d * d,
            2.0 * (c * d + a * b),
        ),
        DVec3::new(
            2.0 * (b * d + a * c),
            2.0 * (c * d - a * b),
            a * a + d * d - c * c - b * b,
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_tables_tile_the_headers() {
        for version in [Version::Nifti1, Version::Nifti2] {
            let mut end = 0;
            for &Field(name, offset, kind, count) in version.fields() {
                assert_eq!(offset, end, "{name} in {}", version.name());
                end = offset + kind.size() * count;
            }
            assert_eq!(end, version.header_len());
        }
    }

    #[test]
    fn sizeof_hdr_tells_layout_and_byte_order() {
        let p = Path::new("x.nii");
        assert_eq!(
            detect_version(p, 348i32.to_le_bytes()).unwrap(),
            (Version::Nifti1, Endian::Little)
        );
        assert_eq!(
            detect_version(p, 348i32.to_be_bytes()).unwrap(),
            (Version::Nifti1, Endian::Big)
        );
        assert_eq!(
            detect_version(p, 540i32.to_be_bytes()).unwrap(),
            (Version::Nifti2, Endian::Big)
        );
        let err = detect_version(p, 349i32.to_le_bytes()).unwrap_err();
        assert!(err.to_string().contains("\"sizeof_hdr\" is 349"), "{err}");
    }

    #[test]
    fn integers_are_sign_extended_in_both_orders() {
        assert_eq!(int(&(-3i16).to_le_bytes(), Endian::Little), -3);
        assert_eq!(int(&(-3i16).to_be_bytes(), Endian::Big), -3);
        assert_eq!(int(&(40000i32).to_be_bytes(), Endian::Big), 40000);
        assert_eq!(int(&(-5i64).to_le_bytes(), Endian::Little), -5);
        assert_eq!(int(&[200u8], Endian::Big), -56);
        assert_eq!(float(&1.5f32.to_be_bytes(), Endian::Big), 1.5);
        assert_eq!(float(&(-2.25f64).to_le_bytes(), Endian::Little), -2.25);
    }

    #[test]
    fn quaternions_give_the_rotations_of_nifti1_h() {
        // Identity.
        let r = quaternion_rotation(0.0, 0.0, 0.0);
        assert!((r - DMat3::IDENTITY).abs_diff_eq(DMat3::ZERO, 1e-12));
        // 90 degrees about z: b = c = 0, d = sin 45°: x -> y, y -> -x.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let r = quaternion_rotation(0.0, 0.0, s);
        assert!((r * DVec3::X - DVec3::Y).length() < 1e-12);
        assert!((r * DVec3::Y + DVec3::X).length() < 1e-12);
        // 180 degrees about x (a = 0): y -> -y, z -> -z.
        let r = quaternion_rotation(1.0, 0.0, 0.0);
        assert!((r * DVec3::Y + DVec3::Y).length() < 1e-12);
        assert!((r * DVec3::Z + DVec3::Z).length() < 1e-12);
        // Any quaternion gives a proper rotation.
        let r = quaternion_rotation(0.3, -0.2, 0.5);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
        assert!((r * r.transpose()).abs_diff_eq(DMat3::IDENTITY, 1e-12));
    }

    #[test]
    fn datatypes() {
        assert_eq!(sample_type(512).unwrap(), (DType::U16, "uint16"));
        assert_eq!(sample_type(1280).unwrap(), (DType::U64, "uint64"));
        assert!(sample_type(128).unwrap_err().contains("RGB24"));
        assert!(sample_type(1792).unwrap_err().contains("complex128"));
        assert!(
            sample_type(3)
                .unwrap_err()
                .contains("not a NIfTI data type")
        );
    }

    #[test]
    fn image_paths_keep_case() {
        let img = |p: &str| image_path(Path::new(p)).unwrap();
        assert_eq!(img("d/brain.hdr"), PathBuf::from("d/brain.img"));
        assert_eq!(img("BRAIN.HDR"), PathBuf::from("BRAIN.IMG"));
        assert_eq!(img("b.hdr.gz"), PathBuf::from("b.img.gz"));
        assert!(image_path(Path::new("b.nii")).is_err());
    }

    #[test]
    fn units() {
        assert_eq!(length_unit(2 | 8), Some("mm"));
        assert_eq!(length_unit(3), Some("um"));
        assert_eq!(length_unit(1), Some("m"));
        assert_eq!(length_unit(0), None);
    }

    #[test]
    fn text_fields_stop_at_nul() {
        assert_eq!(text(b"n+1\0"), "n+1");
        assert_eq!(text(b"ab\x07c\0zz"), "ab?c");
    }
}
