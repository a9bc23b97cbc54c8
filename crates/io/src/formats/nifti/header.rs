//! The NIfTI-1 and NIfTI-2 headers, parsed here (the `nifti` crate reads
//! NIfTI-1 only), in either byte order: the byte order is the one in which
//! `sizeof_hdr` reads 348 or 540, as nibabel and nifti1_io decide it. Every
//! field is decoded from a table of the C structs (nifti1.h, nifti2.h), kept
//! as written for `volray info`, and the ones volray uses are gathered in a
//! [`Header`].

use std::path::Path;

use crate::dtype::Endian;
use crate::error::IoError;

/// The two header layouts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Version {
    Nifti1,
    Nifti2,
}

impl Version {
    pub(super) fn header_len(self) -> usize {
        match self {
            Version::Nifti1 => 348,
            Version::Nifti2 => 540,
        }
    }

    pub(super) fn name(self) -> &'static str {
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

/// The Analyze 7.5 header (Mayo's `dbh.h`, `struct dsr`), in file order:
/// the same 348 bytes, without NIfTI's magic and transforms. `originator`
/// is read as SPM does, five int16 (the voxel at the origin, from 1).
const ANALYZE_FIELDS: &[Field] = &[
    Field("sizeof_hdr", 0, Kind::I32, 1),
    Field("data_type", 4, Kind::Text, 10),
    Field("db_name", 14, Kind::Text, 18),
    Field("extents", 32, Kind::I32, 1),
    Field("session_error", 36, Kind::I16, 1),
    Field("regular", 38, Kind::Text, 1),
    Field("hkey_un0", 39, Kind::U8, 1),
    Field("dim", 40, Kind::I16, 8),
    Field("vox_units", 56, Kind::Text, 4),
    Field("cal_units", 60, Kind::Text, 8),
    Field("unused1", 68, Kind::I16, 1),
    Field("datatype", 70, Kind::I16, 1),
    Field("bitpix", 72, Kind::I16, 1),
    Field("dim_un0", 74, Kind::I16, 1),
    Field("pixdim", 76, Kind::F32, 8),
    Field("vox_offset", 108, Kind::F32, 1),
    Field("funused1", 112, Kind::F32, 1),
    Field("funused2", 116, Kind::F32, 1),
    Field("funused3", 120, Kind::F32, 1),
    Field("cal_max", 124, Kind::F32, 1),
    Field("cal_min", 128, Kind::F32, 1),
    Field("compressed", 132, Kind::F32, 1),
    Field("verified", 136, Kind::F32, 1),
    Field("glmax", 140, Kind::I32, 1),
    Field("glmin", 144, Kind::I32, 1),
    Field("descrip", 148, Kind::Text, 80),
    Field("aux_file", 228, Kind::Text, 24),
    Field("orient", 252, Kind::U8, 1),
    Field("originator", 253, Kind::I16, 5),
    Field("generated", 263, Kind::Text, 10),
    Field("scannum", 273, Kind::Text, 10),
    Field("patient_id", 283, Kind::Text, 10),
    Field("exp_date", 293, Kind::Text, 10),
    Field("exp_time", 303, Kind::Text, 10),
    Field("hist_un0", 313, Kind::Text, 3),
    Field("views", 316, Kind::I32, 1),
    Field("vols_added", 320, Kind::I32, 1),
    Field("start_field", 324, Kind::I32, 1),
    Field("field_skip", 328, Kind::I32, 1),
    Field("omax", 332, Kind::I32, 1),
    Field("omin", 336, Kind::I32, 1),
    Field("smax", 340, Kind::I32, 1),
    Field("smin", 344, Kind::I32, 1),
];

/// Whether `head` starts with an Analyze 7.5 header: `sizeof_hdr` 348 in
/// either byte order, no NIfTI magic at byte 344 and `dim[0]` 1 to 7 in
/// the same order.
pub(crate) fn sniff_analyze(head: &[u8]) -> bool {
    let Some(h) = head.get(..348) else {
        return false;
    };
    let first4 = [h[0], h[1], h[2], h[3]];
    let magic = &h[344..348];
    if magic == b"n+1\0" || magic == b"ni1\0" {
        return false;
    }
    [Endian::Little, Endian::Big].into_iter().any(|endian| {
        let (size, ndim) = match endian {
            Endian::Little => (
                i32::from_le_bytes(first4),
                i16::from_le_bytes([h[40], h[41]]),
            ),
            Endian::Big => (
                i32::from_be_bytes(first4),
                i16::from_be_bytes([h[40], h[41]]),
            ),
        };
        size == 348 && (1..=7).contains(&ndim)
    })
}

/// Decodes `bytes` along the field table `table`.
fn decode(bytes: &[u8], table: &[Field], endian: Endian) -> Vec<(&'static str, Value)> {
    let mut fields = Vec::with_capacity(table.len());
    for &Field(name, offset, kind, count) in table {
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
    fields
}

/// A decoded header field.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Value {
    Ints(Vec<i64>),
    Floats(Vec<f64>),
    Text(String),
}

impl Value {
    pub(super) fn display(&self) -> String {
        let join = |items: Vec<String>| items.join(" ");
        match self {
            Value::Ints(v) => join(v.iter().map(|x| x.to_string()).collect()),
            Value::Floats(v) => join(v.iter().map(|x| x.to_string()).collect()),
            Value::Text(s) => s.clone(),
        }
    }
}

/// The header fields volray uses, decoded; `fields` keeps all of them as
/// written, for [`FileInfo::header`](crate::FileInfo::header).
#[derive(Debug, Clone)]
pub(super) struct Header {
    /// `n+1`/`n+2` (data in the same file) or `ni1`/`ni2` (a `.hdr`/`.img` pair).
    pub(super) single_file: bool,
    /// An Analyze 7.5 header (no NIfTI magic): its first three
    /// `originator` int16, SPM's origin voxel counted from 1 (0 0 0 if
    /// unset). `fields` then holds the Analyze fields, the transforms
    /// are unset and `scl_slope`/`scl_inter` are SPM's `funused1`/`funused2`.
    pub(super) analyze: Option<[i64; 3]>,
    pub(super) dim: [i64; 8],
    pub(super) datatype: i64,
    pub(super) bitpix: i64,
    pub(super) pixdim: [f64; 8],
    pub(super) vox_offset: f64,
    pub(super) scl_slope: f64,
    pub(super) scl_inter: f64,
    pub(super) xyzt_units: i64,
    pub(super) qform_code: i64,
    pub(super) sform_code: i64,
    pub(super) quatern: [f64; 3],
    pub(super) qoffset: [f64; 3],
    pub(super) srow: [[f64; 4]; 3],
    pub(super) fields: Vec<(&'static str, Value)>,
}

impl Header {
    pub(super) fn ints(&self, name: &str) -> &[i64] {
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
pub(super) fn detect_version(path: &Path, first4: [u8; 4]) -> Result<(Version, Endian), IoError> {
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
pub(super) fn parse_header(
    path: &Path,
    bytes: &[u8],
    version: Version,
    endian: Endian,
) -> Result<Header, IoError> {
    debug_assert_eq!(bytes.len(), version.header_len());
    let fields = decode(bytes, version.fields(), endian);
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
        analyze: None,
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
        // Analyze 7.5: the same layout up to the transforms; always a
        // .hdr/.img pair, no orientation, SPM's origin in `originator`.
        header.single_file = false;
        header.fields = decode(bytes, ANALYZE_FIELDS, endian);
        header.xyzt_units = 0;
        header.qform_code = 0;
        header.sform_code = 0;
        let originator = [253, 255, 257].map(|at| int(&bytes[at..at + 2], endian));
        header.analyze = Some(originator);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analyze_table_tiles_its_header() {
        let mut end = 0;
        for &Field(name, offset, kind, count) in ANALYZE_FIELDS {
            assert_eq!(offset, end, "{name}");
            end = offset + kind.size() * count;
        }
        assert_eq!(end, 348);
    }

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
    fn text_fields_stop_at_nul() {
        assert_eq!(text(b"n+1\0"), "n+1");
        assert_eq!(text(b"ab\x07c\0zz"), "ab?c");
    }
}
