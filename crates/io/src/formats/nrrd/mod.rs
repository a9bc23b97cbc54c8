//! NRRD volumes (teem's "nearly raw raster data", the format of 3D Slicer
//! and teem), after the format definition at
//! teem.sourceforge.net/nrrd/format.html: `.nrrd` files with the data
//! after the header, and detached `.nhdr` headers whose `data file` names
//! one file, a `LIST` of files, or a numbered `%d` series.
//!
//! Read: every sample type but `block`; encodings `raw`, `gzip`, `bzip2`
//! (`bz2`; decoded by the `bzip2` crate's pure-Rust libbz2-rs-sys), `ascii`
//! (`text`, `txt`) and `hex`;
//! `endian`, `line skip`, `byte skip` (including -1: data at the end of a
//! raw file); 3-D files, and 4-D files whose one non-spatial axis (a
//! `space directions` entry of `none`, or a `list`, `vector`, `time`, ...
//! kind) holds several volumes: channels where its kind makes its samples
//! the components of one value (`vector`, `RGB-color`, `list`, ...),
//! `--channel` picking one, else time points, `--frame` picking one
//! (`axes.rs`). Text values
//! are read as decimal numbers whatever the type says.
//!
//! Geometry: `space directions` and `space origin` (in a 3-D space, or the
//! spatial part of a `-time` space) give each index axis's world step and
//! the first sample's position; without a space, `spacings` (or `axis
//! mins`/`axis maxs`) along world x, y, z and an origin from `axis mins`
//! (cell-centred unless `centers` says `node`, as teem and ITK assume).
//! Positions are kept in the file's space: an LPS file is not turned into
//! RAS (ITK would turn RAS into LPS); `volray info` shows the space.
//! [`write_nrrd`] writes volumes back.

mod geometry;
mod header;
mod values;
mod write;

use std::path::{Path, PathBuf};

use self::geometry::{Geometry, holds_channels};
use self::header::Header;
use self::values::required;
use crate::dtype::{DType, Endian};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::open_input;
use crate::shared::limits::check_frame_dims;
use crate::shared::mapped::{self, Plan};
use crate::shared::payload::{self, Encoding, FrameSelect, Layout, Region, Skip};
use crate::shared::text_header::Field;
use crate::{AxisNames, FileInfo, Loaded, ReadOptions, VolumeFormat, Volumes};

pub use write::write_nrrd;

/// Reads the NRRD file (or detached header) at `path`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (file, file_len) = open_input(path)?;
    let header = Header::read(path, file, file_len)?;
    let mut info = FileInfo::new("");
    info.header = header.written.clone();
    let notes = &mut info.notes;

    let field = |name| Field::nrrd(path, name);
    let dim = field("dimension").uint(required(path, &header, "dimension")?)?;
    if !(2..=4).contains(&dim) {
        return Err(field("dimension").error(format!(
            "{dim}: volray reads 3-D volumes and 4-D files of volumes (and describes 2-D images)"
        )));
    }
    let mut sizes = field("sizes").sizes(required(path, &header, "sizes")?, dim)?;
    let type_name = required(path, &header, "type")?;
    let dtype = parse_type(path, type_name)?;
    let encoding = parse_encoding(path, required(path, &header, "encoding")?)?;
    let endian = match header.get("endian") {
        Some(e) => match e.to_ascii_lowercase().as_str() {
            "little" => Endian::Little,
            "big" => Endian::Big,
            _ => {
                return Err(field("endian").error(format!("\"{e}\" is neither little nor big")));
            }
        },
        None if dtype.size() > 1 && encoding != Encoding::Text => {
            return Err(IoError::invalid(
                path,
                format!(
                    "NRRD field \"endian\" is missing: {type_name} data in {} encoding needs it",
                    required(path, &header, "encoding")?
                ),
            ));
        }
        None => Endian::Little,
    };
    info.stored_type = if dtype.size() > 1 && encoding != Encoding::Text {
        format!("{type_name} ({dtype}, {endian}-endian)")
    } else {
        format!("{type_name} ({dtype})")
    };

    // Every product of sizes below fits in memory once the total does.
    let total = field("sizes").sample_count(&sizes, dtype.size())?;

    // Which axis, if any, holds several volumes, and the geometry. A 2-D
    // image is read as one slice, described rather than rendered.
    let geometry = if dim == 2 {
        sizes.push(1);
        Geometry::image(path, &header)?
    } else {
        Geometry::parse(path, &header, &sizes, notes)?
    };
    // The 4th axis holds time points, or channels where its kind says its
    // samples are the components of one value (`vector`, `RGB-color`,
    // `list`, ...: `geometry::holds_channels`); `axes.rs` picks one.
    let frames = geometry.frame_axis.map_or(1, |f| sizes[f]);
    let kind = (geometry.frame_axis).and_then(|f| geometry.kinds.as_ref().map(|k| k[f].clone()));
    let channels = kind.as_deref().is_some_and(holds_channels);
    let volumes = if channels {
        Volumes::new(1, frames)
    } else {
        Volumes::new(frames, 1)
    };
    let along = format!(
        "{}frames 0 to {}",
        kind.as_ref()
            .map(|k| format!("kind {k}, "))
            .unwrap_or_default(),
        frames.saturating_sub(1)
    );
    let picked = volumes.pick(
        path,
        opts,
        AxisNames {
            holder: "the file",
            time: if channels { "" } else { &along },
            channel: if channels { &along } else { "" },
        },
    )?;
    let frame = picked.time_point.max(picked.channel);
    let select = match geometry.frame_axis {
        None => FrameSelect::ALL,
        Some(f) => FrameSelect {
            stride: sizes[..f].iter().product(),
            count: frames,
            index: frame,
        },
    };
    if let Some(f) = geometry.frame_axis {
        notes.push(format!(
            "4-D file: {} {frame} of {frames} along axis {f}{} read",
            if channels { "channel" } else { "volume" },
            kind.as_ref()
                .map(|k| format!(" (kind {k})"))
                .unwrap_or_default()
        ));
    }

    // Where the data is, checked against the files before reading.
    let (files, base) = data_files(path, &header, &sizes)?;
    let per_file = total / files.len();
    let line_skip = match header.get("line skip") {
        Some(v) => field("line skip").uint(v)? as u64,
        None => 0,
    };
    let byte_skip: i64 = match header.get("byte skip") {
        Some(v) => v
            .trim()
            .parse()
            .map_err(|_| field("byte skip").error(format!("\"{v}\" is not an integer")))?,
        None => 0,
    };
    let mut layout = Layout {
        dtype,
        endian,
        encoding,
        inflated_skip: 0,
    };
    let skip = match byte_skip {
        n if n >= 0 && encoding.is_compressed() => {
            layout.inflated_skip = n as u64;
            Skip::Forward(0)
        }
        n if n >= 0 => Skip::Forward(n as u64),
        n if encoding == Encoding::Raw => Skip::BeforeEnd((-(n + 1)) as u64),
        n => {
            return Err(field("byte skip").error(format!(
                "{n} (counting back from the end of the file) works with raw encoding only, not {}",
                required(path, &header, "encoding")?
            )));
        }
    };
    let data_len = (per_file * dtype.size()) as u64;
    let mut regions = Vec::with_capacity(files.len());
    for file in &files {
        let region = Region::locate(
            file,
            base,
            line_skip,
            skip,
            data_len,
            "NRRD fields \"line skip\" and \"byte skip\"",
        )?;
        payload::check_region(&region, per_file, &layout, notes)?;
        regions.push(region);
    }
    if files.len() > 1 {
        notes.push(format!(
            "data read from {} files, {per_file} samples each",
            files.len()
        ));
    }
    let (data, plan) = payload::plan_frame(
        &regions,
        per_file,
        &layout,
        select,
        opts.map,
        check_frame_dims(
            path,
            "NRRD field \"sizes\"",
            &sizes,
            frames,
            layout.stored().bytes() as u64,
            opts.max_memory,
        ),
    )?;

    let volume_dims = [
        sizes[geometry.axes[0]],
        sizes[geometry.axes[1]],
        sizes[geometry.axes[2]],
    ];
    info.length_unit = geometry.unit.clone();
    info.set_volumes(volumes, picked);
    let volume = grid_to_volume(
        path,
        volume_dims,
        data,
        geometry.steps,
        geometry.origin,
        &mut info,
    )?;
    if plan == Plan::Map {
        info.notes.push(mapped::mapped_note(&volume));
    }
    Ok(Loaded {
        volume,
        format: VolumeFormat::Nrrd,
        info,
    })
}

/// The sample type a NRRD `type` names (teem's spellings).
fn parse_type(path: &Path, name: &str) -> Result<DType, IoError> {
    let canonical = name.split_whitespace().collect::<Vec<_>>().join(" ");
    let dtype = match canonical.to_ascii_lowercase().as_str() {
        "signed char" | "int8" | "int8_t" => DType::I8,
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => DType::U8,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            DType::I16
        }
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => DType::U16,
        "int" | "signed int" | "int32" | "int32_t" => DType::I32,
        "uint" | "unsigned int" | "uint32" | "uint32_t" => DType::U32,
        "longlong"
        | "long long"
        | "long long int"
        | "signed long long"
        | "signed long long int"
        | "int64"
        | "int64_t" => DType::I64,
        "ulonglong" | "unsigned long long" | "unsigned long long int" | "uint64" | "uint64_t" => {
            DType::U64
        }
        "float" => DType::F32,
        "double" => DType::F64,
        "block" => {
            return Err(Field::nrrd(path, "type")
                .error("\"block\" samples are opaque bytes with no value to render"));
        }
        _ => {
            return Err(Field::nrrd(path, "type").error(format!(
                "unknown type \"{name}\" (known: signed char, uchar, short, ushort, int, uint, longlong, ulonglong, float, double and their synonyms)"
            )));
        }
    };
    Ok(dtype)
}

fn parse_encoding(path: &Path, name: &str) -> Result<Encoding, IoError> {
    match name.trim().to_ascii_lowercase().as_str() {
        "raw" => Ok(Encoding::Raw),
        "gz" | "gzip" => Ok(Encoding::Gzip),
        "txt" | "text" | "ascii" => Ok(Encoding::Text),
        "hex" => Ok(Encoding::Hex),
        "bz2" | "bzip2" => Ok(Encoding::Bzip2),
        _ => Err(Field::nrrd(path, "encoding").error(format!(
            "unknown encoding \"{name}\" (known: raw, gzip, bzip2, ascii, hex)"
        ))),
    }
}

/// The data files of the header at `path`, and the byte they start at
/// (after the header for attached data, else 0). Each file holds an equal
/// share of the samples.
fn data_files(
    path: &Path,
    header: &Header,
    sizes: &[usize],
) -> Result<(Vec<PathBuf>, u64), IoError> {
    let dim = sizes.len();
    let Some(spec) = header.get("data file") else {
        let offset = header.data_offset.ok_or_else(|| {
            IoError::invalid(
                path,
                "the NRRD header ends without the blank line that precedes attached data, and has no \"data file\" field",
            )
        })?;
        return Ok((vec![path.to_path_buf()], offset));
    };
    let dir = path.parent().unwrap_or(Path::new(""));
    let resolve = |name: &str| dir.join(name);
    let bad = |why: String| Field::nrrd(path, "data file").error(why);
    let parse_subdim = |word: &str| -> Result<usize, IoError> {
        word.parse::<usize>()
            .ok()
            .filter(|d| (1..=dim).contains(d))
            .ok_or_else(|| bad(format!("data file dimension \"{word}\" is not 1 to {dim}")))
    };

    let (files, subdim): (Vec<PathBuf>, usize) = if let Some(rest) = spec.strip_prefix("LIST") {
        let subdim = match rest.trim() {
            "" => dim - 1,
            w => parse_subdim(w)?,
        };
        if header.list.is_empty() {
            return Err(bad("LIST names no files after the header".to_string()));
        }
        (header.list.iter().map(|n| resolve(n)).collect(), subdim)
    } else if spec.contains('%') {
        let w: Vec<&str> = spec.split_whitespace().collect();
        if !(4..=5).contains(&w.len()) {
            return Err(bad(format!(
                "\"{spec}\": a numbered series is \"<template> <min> <max> <step> [<dimension>]\""
            )));
        }
        let int = |s: &str| {
            s.parse::<i64>()
                .map_err(|_| bad(format!("\"{s}\" in \"{spec}\" is not an integer")))
        };
        let (min, max, step) = (int(w[1])?, int(w[2])?, int(w[3])?);
        let subdim = match w.get(4) {
            Some(d) => parse_subdim(d)?,
            None => dim - 1,
        };
        let count = payload::number_range(min, max, step).ok_or_else(|| {
            bad(format!(
                "{min} to {max} in steps of {step} is not a series of numbers"
            ))
        })?;
        if count > payload::MAX_FILES {
            return Err(bad(format!(
                "{count} numbered files: more than volray reads ({})",
                payload::MAX_FILES
            )));
        }
        let expected = pieces(sizes, subdim, count);
        if expected != Some(count) {
            return Err(bad(format!(
                "{count} numbered files, but {} of {subdim}-D data are needed",
                pieces_wanted(sizes, subdim)
            )));
        }
        let names = (0..count as i64)
            .map(|i| payload::format_number(w[0], min + i * step).map(|n| resolve(&n)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(bad)?;
        (names, subdim)
    } else {
        (vec![resolve(spec)], dim)
    };
    let n = files.len() as u64;
    if pieces(sizes, subdim, n) != Some(n) {
        return Err(bad(format!(
            "{n} files, but {} of {subdim}-D data are needed",
            pieces_wanted(sizes, subdim)
        )));
    }
    Ok((files, 0))
}

/// How many files hold `subdim`-D pieces of an array of `sizes`, if
/// `files` of them fit. Pieces of the array's own dimension are equal
/// slabs along the slowest axis.
fn pieces(sizes: &[usize], subdim: usize, files: u64) -> Option<u64> {
    if subdim < sizes.len() {
        sizes[subdim..]
            .iter()
            .try_fold(1u64, |acc, &s| acc.checked_mul(s as u64))
    } else {
        let last = *sizes.last()? as u64;
        (files >= 1 && files <= last && last.is_multiple_of(files)).then_some(files)
    }
}

fn pieces_wanted(sizes: &[usize], subdim: usize) -> String {
    if subdim < sizes.len() {
        let n = sizes[subdim..]
            .iter()
            .try_fold(1u64, |acc, &s| acc.checked_mul(s as u64));
        n.map_or_else(
            || "more pieces than can be counted".to_string(),
            |n| format!("{n} pieces"),
        )
    } else {
        format!(
            "a number of slabs dividing the last axis size {}",
            sizes.last().copied().unwrap_or(0)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_synonyms() {
        let p = Path::new("t.nrrd");
        for (names, d) in [
            (&["signed char", "int8", "int8_t"][..], DType::I8),
            (&["uchar", "unsigned  char", "uint8_t"][..], DType::U8),
            (&["short", "signed short int", "int16_t"][..], DType::I16),
            (&["ushort", "unsigned short int", "uint16"][..], DType::U16),
            (&["int", "signed int", "int32"][..], DType::I32),
            (&["uint", "unsigned int", "uint32_t"][..], DType::U32),
            (
                &["longlong", "signed long long int", "int64"][..],
                DType::I64,
            ),
            (
                &["ulonglong", "unsigned long long", "uint64_t"][..],
                DType::U64,
            ),
            (&["float", "Float"][..], DType::F32),
            (&["double"][..], DType::F64),
        ] {
            for n in names {
                assert_eq!(parse_type(p, n).unwrap(), d, "{n}");
            }
        }
        assert!(
            parse_type(p, "block")
                .unwrap_err()
                .to_string()
                .contains("opaque")
        );
        assert!(
            parse_type(p, "char")
                .unwrap_err()
                .to_string()
                .contains("unknown type \"char\"")
        );
    }

    #[test]
    fn piece_counts() {
        assert_eq!(pieces(&[4, 3, 5], 2, 5), Some(5));
        assert_eq!(pieces(&[4, 3, 5], 1, 15), Some(15));
        assert_eq!(pieces(&[4, 3, 5], 3, 5), Some(5));
        assert_eq!(pieces(&[4, 3, 6], 3, 4), None);
        assert_eq!(pieces(&[4, 3, 6], 3, 3), Some(3));
        assert_eq!(pieces(&[4, 3, 6], 3, 7), None);
    }
}
