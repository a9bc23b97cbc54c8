//! NIfTI-1 and NIfTI-2 volumes: `.nii`, `.nii.gz` and `.hdr`/`.img` pairs;
//! and Analyze 7.5 pairs, NIfTI-1's ancestor.
//!
//! Analyze 7.5 (a 348-byte `.hdr` without NIfTI's magic, as nibabel's
//! AnalyzeImage and SPM write it) is read here as a sub-case of the NIfTI-1
//! pair, which shares its layout up to the transforms; it has its own row
//! ([`VolumeFormat::Analyze`]) so that it is named in messages and
//! `volray info`. It carries voxel sizes but no orientation: nibabel's
//! affine for it is used (`geometry.rs`), with SPM's `originator` when set,
//! and `funused1`/`funused2` as SPM's scale and offset.
//!
//! [`read`] runs in the order of the file: `source.rs` opens it (plain or
//! gzip, and the `.img` beside a `.hdr`), `header.rs` parses the 348-byte
//! NIfTI-1 or 540-byte NIfTI-2 header in either byte order, `data.rs`
//! checks what it says about the samples (type, dimensions, frames,
//! offset) and scales the values read, and `geometry.rs` places the grid
//! in the world. A gzip file is inflated as a stream, so a header that
//! lies about the data size runs into the end of the stream instead of
//! making volray allocate what it claims.
//!
//! Interpretation, following the NIfTI-1 standard (nifti1.h) and nibabel:
//! - values are `scl_slope · stored + scl_inter` when `scl_slope` is
//!   finite and non-zero (0 or NaN means "no scaling");
//! - world coordinates (RAS+, as nibabel's affine) come from the sform
//!   (`srow_x/y/z`) if `sform_code > 0`, else from the qform quaternion if
//!   `qform_code > 0` (nifti1.h "method 2"), else from `pixdim` alone
//!   ("method 1", origin at 0); they go through [`grid_to_volume`];
//! - a sheared sform (columns not orthogonal: not a rotation times a
//!   scale), which nibabel and ITK read as it is, is resampled trilinearly
//!   onto an axis-aligned grid covering the file's box, NaN outside it
//!   ([`FileInfo::nan_is_empty`]), as skewed CCP4 maps are
//!   (`shared/periodic_cell.rs`), within `max_memory`;
//! - `xyzt_units` names the length unit (m, mm, µm), which is reported, not
//!   converted;
//! - a 4-D file holds `dim[4]` time points and `--frame` picks one; a
//!   5-D file (nibabel's shape `(x, y, z, t, c)`) holds `dim[5]`
//!   components of each: nifti1.h's 5th dimension `u` is "the vector
//!   (or matrix) index" of an intent such as `NIFTI_INTENT_VECTOR` (1007)
//!   or `RGB_VECTOR` (2001), and microscopy writers (Fiji, nibabel users)
//!   put their channels there, so the components are the channels
//!   (`--channel`, `axes.rs`). Each (t, c) volume is one contiguous
//!   block in the file's own order, time fastest: block `t + dim[4]·c`.
//!   6-D and higher data (any `dim[6..]` above 1) are refused, as are
//!   complex, RGB, bit and 128-bit float samples.

mod data;
mod geometry;
mod header;
mod source;
mod spm;

use std::path::Path;

use self::data::{Layout, dim_text, scaling, too_big};
use self::geometry::{geometry, length_unit};
pub(crate) use self::header::sniff_analyze;
use self::header::{detect_version, parse_header};
use self::source::{Source, image_path};
use crate::dtype::{Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::compress::MAX_DEFLATE_RATIO;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::{F32_BYTES, check_frame_dims};
use crate::shared::mapped::{self, Plan};
use crate::shared::periodic_cell;
use crate::shared::rescale::rescale;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat, Volumes};

/// Samples decoded per read: bounds the scratch buffer beside the output.
const CHUNK_SAMPLES: usize = 1 << 16;

/// Reads the NIfTI or Analyze 7.5 file at `path` (see the module
/// documentation). Messages about an Analyze header name Analyze 7.5.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let mut analyze = false;
    read_as(path, opts, &mut analyze).map_err(|e| match e {
        IoError::Invalid { path, reason } if analyze => IoError::Invalid {
            path,
            reason: reason
                .replace("NIfTI field", "Analyze 7.5 field")
                .replace("NIfTI header", "Analyze 7.5 header")
                .replace("NIfTI magic says", "an Analyze 7.5 header says"),
        },
        other => other,
    })
}

/// [`read`], setting `analyze` once the header shows an Analyze 7.5 one.
fn read_as(path: &Path, opts: &ReadOptions, analyze: &mut bool) -> Result<Loaded, IoError> {
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
    *analyze = header.analyze.is_some();

    let layout = Layout::of(path, &header, opts)?;
    let mut info = FileInfo::new(format!("{} ({}-endian)", layout.type_name, endian));
    info.header = header
        .fields
        .iter()
        .map(|(n, v)| (n.to_string(), v.display()))
        .collect();
    info.set_volumes(Volumes::new(layout.times, layout.components), layout.picked);
    info.length_unit = length_unit(header.xyzt_units).map(str::to_string);
    info.notes.push(format!(
        "{} header, {} ({}-endian{})",
        if header.analyze.is_some() {
            "Analyze 7.5 (no NIfTI magic)"
        } else {
            version.name()
        },
        if header.single_file {
            "data in the same file"
        } else {
            "header/image pair"
        },
        endian,
        if header_source_gz { ", gzip" } else { "" }
    ));
    if layout.components > 1 {
        let (t, c) = (layout.times, layout.components);
        info.notes.push(format!(
            "5-D: {c} components (dim[5]{}) read as channels, x {t} time point{} (dim[4]); --channel picks the component, --frame the time point (this is time point {}, component {})",
            intent_name(&header),
            if t == 1 { "" } else { "s" },
            layout.picked.time_point,
            layout.picked.channel
        ));
    } else if layout.frames > 1 && opts.frame.is_none() {
        info.notes.push(format!(
            "the file holds {} volumes (dim[4]); volume 0 was read",
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
    // Kept in the file's type; scaled values are built beside them (as f32
    // at most), unless the scaling keeps an integer type.
    let scale = scaling(&header, &mut info);
    let stored = layout.dtype.stored();
    let held = stored.bytes() as u64 + if scale.is_some() { F32_BYTES } else { 0 };
    // Where the grid lies, known before any sample is read: a sheared
    // sform is resampled in memory, so it cannot be mapped.
    let (steps, origin) = geometry(path, &header, &mut info)?;
    let sheared = periodic_cell::is_skewed(steps);
    let mappable = if sheared {
        Err("the sheared grid is resampled in memory".to_string())
    } else if data_source.is_gzip() {
        Err("gzip-compressed data: store it as .nii".to_string())
    } else if scale.is_some() {
        Err("scl_slope scales the values as they are read".to_string())
    } else {
        mapped::mappable(layout.dtype, endian, frame_start)
    };
    let plan = mapped::plan(
        opts.map,
        mappable,
        check_frame_dims(
            path,
            "NIfTI field \"dim\"",
            &dims,
            layout.frames,
            held,
            opts.max_memory,
        ),
    )?;
    let count = layout.count;
    let size = layout.dtype.size();
    let data = if plan == Plan::Map {
        mapped::map_samples(&data_path, frame_start, layout.dtype, count)?
    } else {
        read_as_stored!(stored, |T| {
            let mut data: Vec<T> = Vec::with_capacity(if data_source.is_gzip() {
                count.min(CHUNK_SAMPLES)
            } else {
                count
            });
            let mut chunk = vec![0u8; count.min(CHUNK_SAMPLES) * size];
            let mut done = 0;
            let mut result = Ok(());
            while done < count && result.is_ok() {
                let n = (count - done).min(CHUNK_SAMPLES);
                let at = frame_start + (done * size) as u64;
                result = data_source.fill(&data_path, &mut chunk[..n * size], at, needed);
                T::extend(&mut data, &chunk[..n * size], layout.dtype, endian);
                done += n;
            }
            result.map(|()| data)
        })?
    };
    let data = match scale {
        Some((slope, inter)) => rescale(data, slope, inter),
        None => data,
    };
    let volume = if sheared && layout.dims.iter().all(|&n| n >= 2) {
        // nibabel and ITK take a sheared sform as it is: resampled onto an
        // axis-aligned grid over the file's own box, NaN outside it.
        let unit = info.length_unit.clone().unwrap_or_default();
        let (volume, note) = periodic_cell::resample_sheared(
            layout.dims,
            &data.to_f32_vec(),
            steps,
            origin,
            ["i", "j", "k"],
            &unit,
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "NIfTI sform (sheared)"))?;
        info.notes.push(format!(
            "the sform is sheared (not a rotation times a scale); {note}"
        ));
        info.nan_is_empty = true;
        volume
    } else {
        grid_to_volume(path, layout.dims, data, steps, origin, &mut info)?
    };
    if plan == Plan::Map {
        info.notes.push(mapped::mapped_note(&volume));
    }
    Ok(Loaded {
        volume,
        format: if header.analyze.is_some() {
            VolumeFormat::Analyze
        } else {
            VolumeFormat::Nifti
        },
        info,
    })
}

/// ", intent_code N (name)" for a header that names its intent, else "".
fn intent_name(header: &header::Header) -> String {
    let code = header.ints("intent_code").first().copied().unwrap_or(0);
    match code {
        0 => String::new(),
        1007 => ", intent_code 1007 = vector".to_string(),
        2001 => ", intent_code 2001 = RGB vector".to_string(),
        2002 => ", intent_code 2002 = RGBA vector".to_string(),
        1005 => ", intent_code 1005 = symmetric matrix".to_string(),
        1004 => ", intent_code 1004 = general matrix".to_string(),
        _ => format!(", intent_code {code}"),
    }
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
