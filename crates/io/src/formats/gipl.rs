//! GIPL images (`.gipl`, `.gipl.gz`): Guy's Image Processing Lab format,
//! which ITK, SimpleITK and medical-imaging tools of the King's College /
//! Guy's lineage read and write, read with volray's own parser.
//!
//! The layout (ITK's `itkGiplImageIO.cxx`, checked here against files
//! SimpleITK writes): a 256-byte big-endian header, then the samples,
//! big-endian, x fastest:
//!
//! ```text
//! offset  type        field
//!    0    u16 × 4     dims (x, y, z, t)
//!    8    u16         image type: 7 i8, 8 u8, 15 i16, 16 u16, 31 u32, 32 i32, 64 f32, 65 f64
//!   10    f32 × 4     pixdim (spacing x, y, z, t)
//!   26    80 bytes    patient description
//!  106    f32 × 20    matrix (unused by ITK)
//!  186    u8, u8      flags
//!  188    f64, f64    min, max
//!  204    f64 × 4     origin (x, y, z, t)
//!  236    f32 × 4     pixval offset, calibration, interslice gap, user
//!  252    u32         magic 0xefffe9b0 (or 0x2ae389b8)
//! ```
//!
//! The format stores no direction: the axes are the world's, as ITK
//! reads them. Binary (type 1) and complex images are refused by name; a
//! fourth dimension holds volumes, `--frame` picks one.

use std::io::{self, Read};
use std::path::Path;

use volray_core::glam::DVec3;

use crate::dtype::{DType, Endian, Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::{read_exact_at, read_samples};
use crate::shared::limits::check_dims;
use crate::shared::packed::open_unpacked;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// The header's bytes.
const HEADER: usize = 256;

/// ITK's two magic numbers, at byte 252.
const MAGIC: [u32; 2] = [0xefff_e9b0, 0x2ae3_89b8];

/// Whether a file's first bytes show GIPL's magic number at byte 252.
pub(crate) fn sniff(head: &[u8]) -> bool {
    head.get(252..256)
        .is_some_and(|m| MAGIC.contains(&u32::from_be_bytes([m[0], m[1], m[2], m[3]])))
}

fn be_u16(h: &[u8], at: usize) -> u16 {
    u16::from_be_bytes([h[at], h[at + 1]])
}

fn be_f32(h: &[u8], at: usize) -> f32 {
    f32::from_be_bytes([h[at], h[at + 1], h[at + 2], h[at + 3]])
}

fn be_f64(h: &[u8], at: usize) -> f64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&h[at..at + 8]);
    f64::from_be_bytes(b)
}

/// The sample type of GIPL image type `code`, or why it is not read.
fn dtype(code: u16) -> Result<DType, String> {
    Ok(match code {
        7 => DType::I8,
        8 => DType::U8,
        15 => DType::I16,
        16 => DType::U16,
        31 => DType::U32,
        32 => DType::I32,
        64 => DType::F32,
        65 => DType::F64,
        1 => {
            return Err(
                "image type 1 (binary): not read; store it as unsigned char (type 8)".into(),
            );
        }
        144 | 160 | 192 | 193 => {
            return Err(format!(
                "image type {code} (complex): volray renders real values"
            ));
        }
        other => return Err(format!("image type {other}: not a GIPL type")),
    })
}

/// Reads the GIPL image at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let opened = open_unpacked(path)?;
    let mut info = FileInfo::new("");
    info.notes.extend(opened.note());
    let (len, packed, size) = (opened.len, opened.packing.is_some(), opened.size_phrase());
    let mut reader = opened.reader;
    let invalid = |reason: String| IoError::invalid(path, reason);
    if len < HEADER as u64 {
        return Err(invalid(format!(
            "a {size}: shorter than the {HEADER}-byte GIPL header"
        )));
    }
    let mut h = [0u8; HEADER];
    read_exact_at(path, &mut reader, &mut h, 0, HEADER as u64)
        .map_err(|_| invalid(format!("shorter than the {HEADER}-byte GIPL header")))?;
    if !sniff(&h) {
        return Err(invalid(format!(
            "no GIPL magic number at byte 252 (0x{:08x}; ITK writes 0xefffe9b0)",
            u32::from_be_bytes([h[252], h[253], h[254], h[255]])
        )));
    }
    let dims4 = [0, 1, 2, 3].map(|a| be_u16(&h, 2 * a) as usize);
    let code = be_u16(&h, 8);
    let dtype = dtype(code).map_err(invalid)?;
    let pixdim = [0, 1, 2].map(|a| f64::from(be_f32(&h, 10 + 4 * a)));
    let origin = DVec3::new(be_f64(&h, 204), be_f64(&h, 212), be_f64(&h, 220));
    info.stored_type = format!("{} (big-endian)", dtype.name());
    let description: String = (h[26..106].iter())
        .take_while(|&&b| b != 0)
        .map(|&b| {
            if b.is_ascii_graphic() || b == b' ' {
                b as char
            } else {
                '?'
            }
        })
        .collect();
    info.header = vec![
        (
            "dims".into(),
            format!("{} {} {} {}", dims4[0], dims4[1], dims4[2], dims4[3]),
        ),
        ("image type".into(), code.to_string()),
        (
            "pixdim".into(),
            format!("{} {} {}", pixdim[0], pixdim[1], pixdim[2]),
        ),
        (
            "origin".into(),
            format!("{} {} {}", origin.x, origin.y, origin.z),
        ),
        ("patient".into(), description.trim().to_string()),
    ];
    if let Some(a) = (0..3).find(|&a| !(pixdim[a].is_finite() && pixdim[a] > 0.0)) {
        return Err(invalid(format!(
            "pixdim {} is {}: a spacing must be positive",
            a + 1,
            pixdim[a]
        )));
    }
    if !origin.is_finite() {
        return Err(invalid(format!("origin {origin} is not finite")));
    }
    let dims = [dims4[0], dims4[1], dims4[2]];
    if dims.contains(&0) {
        return Err(invalid(format!(
            "dims {} x {} x {}: an axis of 0 samples",
            dims[0], dims[1], dims[2]
        )));
    }
    let frames = dims4[3].max(1);
    let frame = opts.frame.unwrap_or(0);
    if frame >= frames {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the file holds {frames} volume(s) (frames 0 to {})",
                frames - 1
            ),
        ));
    }
    info.frames = frames;
    info.frame = frame;
    let count = dims.iter().product::<usize>() as u64;
    let need = HEADER as u64 + count * frames as u64 * dtype.size() as u64;
    if need > len || (!packed && need != len) {
        return Err(invalid(format!(
            "the header declares {} x {} x {} x {frames} samples of {} ({need} bytes with the header), but the file is a {size}",
            dims[0],
            dims[1],
            dims[2],
            dtype.name()
        )));
    }
    let count = check_dims(
        path,
        "dims",
        &dims,
        dtype.stored().bytes() as u64,
        opts.max_memory,
    )?;
    let skip = frame as u64 * count as u64 * dtype.size() as u64;
    let skipped = io::copy(&mut (&mut reader).take(skip), &mut io::sink())
        .map_err(|e| IoError::os(path, "read", e))?;
    if skipped < skip {
        return Err(invalid(format!("the file ends before volume {frame}")));
    }
    let offset = HEADER as u64 + skip;
    let data = read_as_stored!(dtype.stored(), |T| {
        read_typed::<T>(path, &mut reader, count, dtype, offset)
    })?;
    let steps = [
        DVec3::X * pixdim[0],
        DVec3::Y * pixdim[1],
        DVec3::Z * pixdim[2],
    ];
    let volume = grid_to_volume(path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Gipl,
        info,
    })
}

/// `count` big-endian samples of `dtype` from `reader`, as `T`.
fn read_typed<T: Stored>(
    path: &Path,
    reader: &mut impl Read,
    count: usize,
    dtype: DType,
    offset: u64,
) -> Result<Vec<T>, IoError> {
    let mut data = Vec::with_capacity(count);
    read_samples(
        path,
        reader,
        count,
        dtype.size(),
        offset,
        |bytes, out: &mut Vec<T>| T::extend(out, bytes, dtype, Endian::Big),
        |values| data.extend_from_slice(values),
    )?;
    Ok(data)
}
