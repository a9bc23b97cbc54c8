//! MetaImage volumes (ITK's MetaIO format): `.mha` files with the data
//! after the header (`ElementDataFile = LOCAL`) and `.mhd` headers whose
//! data lies in another file, a `LIST` of files, or a numbered `%d`
//! series; read as ITK's MetaIO library reads them.
//!
//! Read: `ElementType` `MET_CHAR` to `MET_DOUBLE` (`MET_LONG` is 32-bit, as
//! in MetaIO), `BinaryDataByteOrderMSB` / `ElementByteOrderMSB`,
//! `CompressedData` (zlib, or gzip found by its magic, with or without
//! `CompressedDataSize`), `BinaryData = False` (decimal text), `HeaderSize`
//! (bytes from the start of the data file; -1: the data ends the file),
//! `NDims` 3, or 4 where `--frame` picks a time point along the 4th axis;
//! `ElementNumberOfChannels` above 1 (vector and colour images, each
//! voxel's values together) of a 3-D image: the channels, `--channel`
//! picking one (`axes.rs`).
//!
//! Geometry: index axis `a` steps by `ElementSpacing[a]` (or `ElementSize`)
//! along row `a` of `TransformMatrix` (a.k.a. `Rotation`, `Orientation`),
//! from `Offset` (a.k.a. `Origin`, `Position`): ITK's reading. Positions
//! stay in the file's physical space (LPS for images written by ITK).

mod header;

use std::path::{Path, PathBuf};

use volray_core::glam::DVec3;

use self::header::Header;
use crate::dtype::{DType, Endian};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::open_input;
use crate::shared::limits::check_frame_dims;
use crate::shared::mapped::{self, Plan};
use crate::shared::payload::{self, Encoding, FrameSelect, Layout, Region, Skip};
use crate::shared::text_header::Field;
use crate::{AxisNames, FileInfo, Loaded, ReadOptions, VolumeFormat, Volumes};

/// Whether the first bytes of a file, as text, look like a MetaImage
/// header: `ObjectType` or `NDims` among the first 4 lines' keys, in a
/// file that is not XML (see [`super::vti::sniff_text`]).
pub(crate) fn sniff_text(text: &str) -> bool {
    !super::vti::starts_as_xml(text)
        && text.lines().take(4).any(|l| {
            let key = l.split('=').next().unwrap_or("").trim();
            matches!(key, "ObjectType" | "NDims")
        })
}

/// The fields MetaIO reads for an image; any other is noted as ignored.
const KNOWN: [&str; 36] = [
    "Comment",
    "ObjectType",
    "ObjectSubType",
    "TransformType",
    "NDims",
    "Name",
    "ID",
    "ParentID",
    "AcquisitionDate",
    "CompressedData",
    "CompressedDataSize",
    "BinaryData",
    "BinaryDataByteOrderMSB",
    "ElementByteOrderMSB",
    "Color",
    "Position",
    "Offset",
    "Origin",
    "Orientation",
    "Rotation",
    "TransformMatrix",
    "CenterOfRotation",
    "DistanceUnits",
    "AnatomicalOrientation",
    "ElementSpacing",
    "DimSize",
    "HeaderSize",
    "Modality",
    "ImagePosition",
    "SequenceID",
    "ElementMin",
    "ElementMax",
    "ElementNumberOfChannels",
    "ElementSize",
    "ElementType",
    "ElementDataFile",
];

/// Reads the MetaImage file (or detached header) at `path`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (file, file_len) = open_input(path)?;
    let header = Header::read(path, file, file_len)?;
    let mut info = FileInfo::new("");
    info.header = header.written.clone();
    let notes = &mut info.notes;

    if let Some(t) = header.get("ObjectType")
        && t != "Image"
    {
        return Err(IoError::invalid(
            path,
            format!("MetaImage field ObjectType = {t}: not an image"),
        ));
    }
    let field = |name| Field::metaimage(path, name);
    let ndims = field("NDims").uint(required(path, &header, "NDims")?)?;
    // NDims 2 is an image: read, and described rather than rendered.
    if !(2..=4).contains(&ndims) {
        return Err(IoError::invalid(
            path,
            format!(
                "MetaImage field NDims = {ndims}: volray reads 3-D volumes and 4-D series of volumes (and describes 2-D images)"
            ),
        ));
    }
    let dims = field("DimSize").sizes(required(path, &header, "DimSize")?, ndims)?;
    // Several values per voxel (vector, colour: MetaIO's
    // ElementNumberOfChannels, each voxel's values together): the
    // channels, `--channel` picking one (`axes.rs`).
    let channels = match header.get("ElementNumberOfChannels") {
        Some(c) => field("ElementNumberOfChannels").uint(c)?,
        None => 1,
    };
    if channels == 0 || (channels > 1 && ndims == 4) {
        return Err(IoError::invalid(
            path,
            format!(
                "MetaImage field ElementNumberOfChannels = {channels}: volray reads 1 or more values per voxel of a 3-D image (a 4-D series of several values per voxel is not supported)"
            ),
        ));
    }
    let type_name = required(path, &header, "ElementType")?;
    let dtype = parse_type(path, type_name)?;
    let binary = flag(path, &header, "BinaryData")?.unwrap_or(true);
    let msb = match flag(path, &header, "BinaryDataByteOrderMSB")? {
        Some(b) => b,
        None => flag(path, &header, "ElementByteOrderMSB")?.unwrap_or(false),
    };
    let endian = if msb { Endian::Big } else { Endian::Little };
    let compressed = flag(path, &header, "CompressedData")?.unwrap_or(false) && binary;
    let encoding = if !binary {
        Encoding::Text
    } else if compressed {
        Encoding::Zlib
    } else {
        Encoding::Raw
    };
    info.stored_type = if dtype.size() > 1 && binary {
        format!("{type_name} ({dtype}, {endian}-endian)")
    } else {
        format!("{type_name} ({dtype})")
    };

    // The samples in file order: each voxel's channels, then x, y, z (t).
    let mut sized = dims.clone();
    if channels > 1 {
        sized.insert(0, channels);
    }
    // Every product of sizes below fits in memory once the total does.
    let total = field("DimSize").sample_count(&sized, dtype.size())?;

    // Time points along the 4th axis, or channels (`axes.rs`).
    let volumes = Volumes::new(if ndims == 4 { dims[3] } else { 1 }, channels);
    let along = format!("frames 0 to {}", volumes.time_points - 1);
    let picked = volumes.pick(
        path,
        opts,
        AxisNames {
            holder: "the file",
            time: &along,
            channel: "ElementNumberOfChannels",
        },
    )?;
    let frame = picked.time_point;
    let select = if ndims == 4 {
        notes.push(format!(
            "4-D image: volume {frame} of {} along the 4th axis read",
            volumes.time_points
        ));
        FrameSelect {
            stride: dims[0] * dims[1] * dims[2],
            count: volumes.time_points,
            index: frame,
        }
    } else if channels > 1 {
        notes.push(format!(
            "{channels} values per voxel (ElementNumberOfChannels): channel {} read",
            picked.channel
        ));
        FrameSelect {
            stride: 1,
            count: channels,
            index: picked.channel,
        }
    } else {
        FrameSelect::ALL
    };
    let frames = volumes.count();

    let geometry = Geometry::parse(path, &header, ndims, notes)?;

    // Where the data is, checked against the files before reading.
    let (files, base) = data_files(path, &header, &dims, notes)?;
    let per_file = total / files.len();
    let header_size: i64 = match header.get("HeaderSize") {
        Some(v) => v.trim().parse().map_err(|_| {
            IoError::invalid(
                path,
                format!("MetaImage field HeaderSize = {v}: not an integer"),
            )
        })?,
        None => 0,
    };
    let compressed_size = match header.get("CompressedDataSize") {
        Some(v) if compressed => {
            let n = v.trim().parse::<u64>().map_err(|_| {
                IoError::invalid(
                    path,
                    format!("MetaImage field CompressedDataSize = {v}: not a byte count"),
                )
            })?;
            if files.len() > 1 {
                notes.push(
                    "CompressedDataSize ignored: each data file is compressed on its own"
                        .to_string(),
                );
                None
            } else {
                Some(n)
            }
        }
        _ => None,
    };
    let raw_len = (per_file * dtype.size()) as u64;
    let (base, skip, data_len) = match header_size {
        n if n > 0 => (0, Skip::Forward(n as u64), 0),
        0 => (base, Skip::Forward(0), 0),
        -1 if !compressed => (base, Skip::BeforeEnd(0), raw_len),
        -1 => match compressed_size {
            Some(c) => (base, Skip::BeforeEnd(0), c),
            None => {
                return Err(IoError::invalid(
                    path,
                    "MetaImage field HeaderSize = -1 with compressed data needs CompressedDataSize to find where the data starts",
                ));
            }
        },
        n => {
            return Err(IoError::invalid(
                path,
                format!(
                    "MetaImage field HeaderSize = {n}: must be -1 (data at the end) or a byte count"
                ),
            ));
        }
    };
    let layout = Layout {
        dtype,
        endian,
        encoding,
        inflated_skip: 0,
    };
    let mut regions = Vec::with_capacity(files.len());
    for file in &files {
        let mut region =
            Region::locate(file, base, 0, skip, data_len, "MetaImage field HeaderSize")?;
        if let Some(c) = compressed_size {
            region = region.limit(c, "MetaImage field CompressedDataSize")?;
        }
        payload::check_region(&region, per_file, &layout, notes)?;
        regions.push(region);
    }
    let (data, plan) = payload::plan_frame(
        &regions,
        per_file,
        &layout,
        select,
        opts.map,
        check_frame_dims(
            path,
            "MetaImage field DimSize =",
            &sized,
            frames,
            layout.stored().bytes() as u64,
            opts.max_memory,
        ),
    )?;

    info.length_unit = geometry.unit.clone();
    // ITK's MetaIO names the modality MET_MOD_CT, MET_MOD_MR, ...
    // (metaTypes.h's MET_ModalityEnumType): kept as DICOM spells it, `CT`.
    info.modality = header
        .get("Modality")
        .map(|m| m.trim().trim_start_matches("MET_MOD_").to_string())
        .filter(|m| !m.is_empty() && m != "UNKNOWN");
    info.set_volumes(volumes, picked);
    let volume = grid_to_volume(
        path,
        [dims[0], dims[1], dims.get(2).copied().unwrap_or(1)],
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
        format: VolumeFormat::MetaImage,
        info,
    })
}

fn required<'h>(path: &Path, header: &'h Header, key: &str) -> Result<&'h str, IoError> {
    Field::metaimage(path, key).required(header.get(key))
}

/// `n` finite numbers of field `key`, if given.
fn numbers(path: &Path, header: &Header, key: &str, n: usize) -> Result<Option<Vec<f64>>, IoError> {
    let Some(value) = header.get(key) else {
        return Ok(None);
    };
    let field = Field::metaimage(path, key);
    let numbers = field.numbers(value, n)?;
    if let Some(i) = numbers.iter().position(|v| !v.is_finite()) {
        let word = value.split_whitespace().nth(i).unwrap_or_default();
        return Err(field.error(format!("\"{word}\" is not a finite number")));
    }
    Ok(Some(numbers))
}

/// A boolean field: MetaIO reads a value starting with `T`, `t` or `1` as
/// true and anything else as false.
fn flag(path: &Path, header: &Header, key: &str) -> Result<Option<bool>, IoError> {
    match header.get(key) {
        None => Ok(None),
        Some(v) if v.starts_with(['T', 't', '1']) => Ok(Some(true)),
        Some(v) if v.starts_with(['F', 'f', '0']) => Ok(Some(false)),
        Some(v) => Err(IoError::invalid(
            path,
            format!("MetaImage field {key} = {v}: expected True or False"),
        )),
    }
}

/// The sample type an `ElementType` names, with MetaIO's sizes.
fn parse_type(path: &Path, name: &str) -> Result<DType, IoError> {
    Ok(match name {
        "MET_CHAR" => DType::I8,
        "MET_UCHAR" => DType::U8,
        "MET_SHORT" => DType::I16,
        "MET_USHORT" => DType::U16,
        "MET_INT" | "MET_LONG" => DType::I32,
        "MET_UINT" | "MET_ULONG" => DType::U32,
        "MET_LONG_LONG" => DType::I64,
        "MET_ULONG_LONG" => DType::U64,
        "MET_FLOAT" => DType::F32,
        "MET_DOUBLE" => DType::F64,
        n if n.ends_with("_ARRAY") || n == "MET_FLOAT_MATRIX" => {
            return Err(IoError::invalid(
                path,
                format!(
                    "MetaImage field ElementType = {n}: array elements (several values per voxel) are not supported"
                ),
            ));
        }
        n => {
            return Err(IoError::invalid(
                path,
                format!(
                    "MetaImage field ElementType = {n}: not a numeric type (MET_CHAR, MET_UCHAR, MET_SHORT, MET_USHORT, MET_INT, MET_UINT, MET_LONG, MET_ULONG, MET_LONG_LONG, MET_ULONG_LONG, MET_FLOAT, MET_DOUBLE)"
                ),
            ));
        }
    })
}

/// The data files of the header at `path` and the byte the data starts at
/// (after the header for `LOCAL`, else 0). Each file holds an equal share.
fn data_files(
    path: &Path,
    header: &Header,
    dims: &[usize],
    notes: &mut Vec<String>,
) -> Result<(Vec<PathBuf>, u64), IoError> {
    let ndims = dims.len();
    let spec = required(path, header, "ElementDataFile")?;
    if matches!(spec, "LOCAL" | "Local" | "local") {
        return Ok((vec![path.to_path_buf()], header.data_offset));
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    let resolve = |name: &str| dir.join(name);
    let bad = |why: String| Field::metaimage(path, "ElementDataFile").error(why);

    let files = if let Some(rest) = spec.strip_prefix("LIST") {
        // MetaIO: each file holds a `fileImageDim`-D piece (default NDims-1;
        // 0 or more than NDims also mean NDims-1).
        let sub = match rest.trim() {
            "" => ndims - 1,
            w => match w.parse::<f64>() {
                Ok(d) if d >= 1.0 && d <= ndims as f64 => d as usize,
                Ok(_) => ndims - 1,
                Err(_) => return Err(bad(format!("\"{spec}\": \"{w}\" is not a dimension"))),
            },
        };
        let wanted: usize = dims[sub..].iter().product();
        if header.list.len() < wanted {
            return Err(bad(format!(
                "LIST names {} files, but {wanted} pieces of {sub}-D data are needed",
                header.list.len()
            )));
        }
        if header.list.len() > wanted {
            notes.push(format!(
                "LIST names {} files; only the first {wanted} are needed and read",
                header.list.len()
            ));
        }
        header.list[..wanted].iter().map(|n| resolve(n)).collect()
    } else if spec.contains('%') {
        // `<template> [<min> [<max> [<step>]]]`, one slice of the last axis per file.
        let w: Vec<&str> = spec.split_whitespace().collect();
        let slices = dims[ndims - 1];
        let numeric = w.len() >= 4 && w[w.len() - 3..].iter().all(|s| s.parse::<i64>().is_ok());
        let (template, nums) = if numeric {
            (w[..w.len() - 3].join(" "), &w[w.len() - 3..])
        } else {
            (w[0].to_string(), &w[1..])
        };
        let int = |s: &str| {
            s.parse::<i64>()
                .map_err(|_| bad(format!("\"{s}\" in \"{spec}\" is not an integer")))
        };
        let min = nums.first().map(|s| int(s)).transpose()?.unwrap_or(1);
        let max = match nums.get(1) {
            Some(s) => int(s)?,
            None => min.saturating_add(slices as i64 - 1),
        };
        let step = nums.get(2).map(|s| int(s)).transpose()?.unwrap_or(1);
        let count = payload::number_range(min, max, step).ok_or_else(|| {
            bad(format!(
                "{min} to {max} in steps of {step} is not a series of numbers"
            ))
        })?;
        if slices as u64 > payload::MAX_FILES {
            return Err(bad(format!(
                "{slices} numbered files: more than volray reads ({})",
                payload::MAX_FILES
            )));
        }
        if count < slices as u64 {
            return Err(bad(format!(
                "{count} numbered files, but DimSize needs {slices} slices"
            )));
        }
        (0..slices as i64)
            .map(|i| payload::format_number(&template, min + i * step).map(|n| resolve(&n)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(bad)?
    } else {
        vec![resolve(spec)]
    };
    if files.len() > 1 {
        notes.push(format!("data read from {} files", files.len()));
    }
    Ok((files, 0))
}

/// Where the samples lie, from the header's geometry fields.
struct Geometry {
    steps: [DVec3; 3],
    origin: DVec3,
    unit: Option<String>,
}

impl Geometry {
    fn parse(
        path: &Path,
        header: &Header,
        ndims: usize,
        notes: &mut Vec<String>,
    ) -> Result<Geometry, IoError> {
        let spacing = match numbers(path, header, "ElementSpacing", ndims)? {
            Some(s) => s,
            None => match numbers(path, header, "ElementSize", ndims)? {
                Some(s) => {
                    notes.push(
                        "no ElementSpacing: ElementSize used as the spacing (as MetaIO does)"
                            .to_string(),
                    );
                    s
                }
                None => vec![1.0; ndims],
            },
        };
        // MetaIO's precedence: ImagePosition over Origin over Offset over Position.
        let mut origin = vec![0.0; ndims];
        for key in ["Position", "Offset", "Origin", "ImagePosition"] {
            if let Some(o) = numbers(path, header, key, ndims)? {
                origin = o;
            }
        }
        // TransformMatrix over Rotation over Orientation; row `a` is the
        // direction of index axis `a` (ITK's MetaImageIO).
        let mut matrix: Vec<f64> = (0..ndims * ndims)
            .map(|i| if i % (ndims + 1) == 0 { 1.0 } else { 0.0 })
            .collect();
        for key in ["Orientation", "Rotation", "TransformMatrix"] {
            if let Some(m) = numbers(path, header, key, ndims * ndims)? {
                matrix = m;
            }
        }
        // A 2-D image's third axis is a unit step along z.
        let mut steps = [DVec3::Z; 3];
        for (a, step) in steps.iter_mut().enumerate().take(ndims) {
            let row = &matrix[a * ndims..a * ndims + ndims.min(3)];
            *step = DVec3::new(row[0], row[1], row.get(2).copied().unwrap_or(0.0)) * spacing[a];
        }
        if ndims == 4 {
            if (0..3).any(|a| matrix[a * 4 + 3] != 0.0) {
                notes.push(
                    "the 4th column of TransformMatrix (mixing time into space) is ignored"
                        .to_string(),
                );
            }
            if spacing[3] != 1.0 || origin[3] != 0.0 {
                notes.push(format!(
                    "4th axis spacing {} and offset {} describe the series, not space: not used",
                    spacing[3], origin[3]
                ));
            }
        }
        if let Some(c) = header
            .get("ElementToIntensityFunctionSlope")
            .or(header.get("ElementToIntensityFunctionOffset"))
        {
            notes.push(format!(
                "ElementToIntensityFunction fields (e.g. {c}) not applied, as ITK does not"
            ));
        }
        let unknown: Vec<&str> = header
            .written
            .iter()
            .map(|(k, _)| k.as_str())
            .filter(|k| {
                !KNOWN.contains(k)
                    && !matches!(
                        *k,
                        "ElementToIntensityFunctionSlope"
                            | "ElementToIntensityFunctionOffset"
                            | "ElementNBits"
                    )
            })
            .collect();
        if !unknown.is_empty() {
            notes.push(format!(
                "fields MetaIO does not read ignored: {}",
                unknown.join(", ")
            ));
        }
        let unit = header
            .get("DistanceUnits")
            .filter(|u| !u.is_empty() && !u.eq_ignore_ascii_case("unknown"))
            .map(str::to_string);
        Ok(Geometry {
            steps,
            origin: DVec3::new(origin[0], origin[1], origin.get(2).copied().unwrap_or(0.0)),
            unit,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_types() {
        let p = Path::new("t.mha");
        let cases = [
            ("MET_CHAR", DType::I8),
            ("MET_UCHAR", DType::U8),
            ("MET_SHORT", DType::I16),
            ("MET_USHORT", DType::U16),
            ("MET_INT", DType::I32),
            ("MET_UINT", DType::U32),
            ("MET_LONG", DType::I32),
            ("MET_ULONG", DType::U32),
            ("MET_LONG_LONG", DType::I64),
            ("MET_ULONG_LONG", DType::U64),
            ("MET_FLOAT", DType::F32),
            ("MET_DOUBLE", DType::F64),
        ];
        for (name, d) in cases {
            assert_eq!(parse_type(p, name).unwrap(), d, "{name}");
        }
        let err = parse_type(p, "MET_UCHAR_ARRAY").unwrap_err().to_string();
        assert!(err.contains("array elements"), "{err}");
        let err = parse_type(p, "MET_STRING").unwrap_err().to_string();
        assert!(err.contains("not a numeric type"), "{err}");
        let err = parse_type(p, "met_float").unwrap_err().to_string();
        assert!(err.contains("met_float: not a numeric type"), "{err}");
    }
}
