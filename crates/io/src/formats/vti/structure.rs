//! The XML part of a `.vti` file: `VTKFile`, `ImageData`, `Piece`,
//! `PointData`/`CellData` and `DataArray` elements, parsed with quick-xml up
//! to `<AppendedData>`, whose raw bytes are not XML. Array data is not
//! decoded here: a `DataArray` keeps the file ranges of its text.

use std::ops::Range;
use std::path::Path;

use quick_xml::events::{BytesStart, Event};
use volray_core::glam::{DMat3, DVec3};

use super::blocks::BlockFormat;
use crate::FileInfo;
use crate::dtype::{DType, Endian};
use crate::error::IoError;
use crate::shared::compress::Compression;
use crate::shared::vtk_arrays::{ArrayEntry, Association};

/// Where an array's values are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Format {
    Ascii,
    Binary,
    Appended,
}

/// One `DataArray` element.
#[derive(Debug, Clone)]
pub(super) struct DataArray {
    pub entry: ArrayEntry,
    pub dtype: DType,
    pub format: Format,
    pub offset: u64,
    /// The element's text, as ranges of the file (ASCII and base64 data).
    pub text: Vec<Range<usize>>,
}

/// One `Piece` and its arrays.
#[derive(Debug, Clone)]
pub(super) struct Piece {
    pub extent: [i64; 6],
    pub arrays: Vec<DataArray>,
}

/// The file's structure, from the XML part.
pub(super) struct Structure {
    /// How binary data is framed.
    pub blocks: BlockFormat,
    pub whole: [i64; 6],
    pub origin: DVec3,
    pub spacing: DVec3,
    /// Row-major, as the `Direction` attribute lists it.
    pub direction: DMat3,
    pub pieces: Vec<Piece>,
    /// Where appended data starts (the byte after `_`) and whether it is base64.
    pub appended: Option<(usize, bool)>,
}

pub(super) fn join<T: ToString>(v: &[T]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The XML attributes of `e` as (name, value) pairs.
fn attributes(path: &Path, e: &BytesStart) -> Result<Vec<(String, String)>, IoError> {
    let mut out = Vec::new();
    for attr in e.attributes() {
        let attr =
            attr.map_err(|err| IoError::invalid(path, format!("bad XML attribute: {err}")))?;
        let key = attr.key.into_inner().to_string();
        let value = attr
            .normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .map_err(|err| IoError::invalid(path, format!("bad XML attribute {key}: {err}")))?
            .into_owned();
        out.push((key, value));
    }
    Ok(out)
}

fn get<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// `n` numbers of attribute `key` of `element`.
fn numbers<T: std::str::FromStr + Copy + Default, const N: usize>(
    path: &Path,
    attrs: &[(String, String)],
    element: &str,
    key: &str,
) -> Result<Option<[T; N]>, IoError> {
    let Some(text) = get(attrs, key) else {
        return Ok(None);
    };
    let bad = || {
        IoError::invalid(
            path,
            format!("{element} attribute {key}=\"{text}\": expected {N} numbers"),
        )
    };
    let parts: Vec<T> = text
        .split_ascii_whitespace()
        .map(|t| t.parse().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    if parts.len() != N {
        return Err(bad());
    }
    let mut out = [T::default(); N];
    out.copy_from_slice(&parts);
    Ok(Some(out))
}

/// The sample type of an XML type name.
fn sample_type(name: &str) -> Option<DType> {
    Some(match name {
        "Int8" => DType::I8,
        "UInt8" => DType::U8,
        "Int16" => DType::I16,
        "UInt16" => DType::U16,
        "Int32" => DType::I32,
        "UInt32" => DType::U32,
        "Int64" => DType::I64,
        "UInt64" => DType::U64,
        "Float32" => DType::F32,
        "Float64" => DType::F64,
        _ => return None,
    })
}

pub(super) fn type_name(d: DType) -> &'static str {
    match d {
        DType::I8 => "Int8",
        DType::U8 => "UInt8",
        DType::I16 => "Int16",
        DType::U16 => "UInt16",
        DType::I32 => "Int32",
        DType::U32 => "UInt32",
        DType::I64 => "Int64",
        DType::U64 => "UInt64",
        DType::F16 => "Float16",
        DType::F32 => "Float32",
        DType::F64 => "Float64",
    }
}

/// Parses the XML part of the file (everything before the appended data).
pub(super) fn parse(path: &Path, bytes: &[u8], info: &mut FileInfo) -> Result<Structure, IoError> {
    let mut reader = quick_xml::Reader::from_reader(bytes);
    let mut s = Structure {
        blocks: BlockFormat {
            endian: Endian::Little,
            word: 4,
            compressed: None,
        },
        whole: [0; 6],
        origin: DVec3::ZERO,
        spacing: DVec3::ONE,
        direction: DMat3::IDENTITY,
        pieces: Vec::new(),
        appended: None,
    };
    let mut seen_root = false;
    let mut seen_image = false;
    let mut section: Option<(Association, Option<String>)> = None;
    let mut current: Option<DataArray> = None;
    // Elements open inside the current DataArray (<InformationKey>,
    // <Value>): their text is not array data.
    let mut nested = 0usize;
    loop {
        let before = reader.buffer_position() as usize;
        let event = reader.read_event().map_err(|e| {
            IoError::invalid(
                path,
                format!("XML error near byte {}: {e}", reader.error_position()),
            )
        })?;
        match event {
            Event::Start(_) if current.is_some() => nested += 1,
            Event::End(_) if current.is_some() && nested > 0 => nested -= 1,
            Event::Empty(_) if current.is_some() => {}
            Event::Start(ref e) | Event::Empty(ref e) => {
                let empty = matches!(event, Event::Empty(_));
                let name = e.name().into_inner().to_string();
                let attrs = attributes(path, e)?;
                match name.as_str() {
                    "VTKFile" => {
                        seen_root = true;
                        root(path, &attrs, &mut s, info)?;
                    }
                    "ImageData" => {
                        seen_image = true;
                        image(path, &attrs, &mut s, info)?;
                    }
                    "Piece" => {
                        let extent = numbers::<i64, 6>(path, &attrs, "Piece", "Extent")?
                            .ok_or_else(|| IoError::invalid(path, "Piece has no Extent"))?;
                        info.header.push(("Piece Extent".into(), join(&extent)));
                        s.pieces.push(Piece {
                            extent,
                            arrays: Vec::new(),
                        });
                    }
                    "PointData" | "CellData" => {
                        let assoc = if name == "PointData" {
                            Association::Point
                        } else {
                            Association::Cell
                        };
                        let scalars = get(&attrs, "Scalars").map(str::to_string);
                        if let Some(sc) = &scalars {
                            info.header.push((format!("{name} Scalars"), sc.clone()));
                        }
                        section = (!empty).then_some((assoc, scalars));
                    }
                    "DataArray" => {
                        if let Some((assoc, scalars)) = &section {
                            let array = data_array(path, &attrs, *assoc, scalars.as_deref(), info)?;
                            if empty {
                                push_array(path, &mut s, array)?;
                            } else {
                                current = Some(array);
                            }
                        }
                    }
                    "AppendedData" => {
                        let encoding = get(&attrs, "encoding").unwrap_or("raw");
                        info.header
                            .push(("AppendedData encoding".into(), encoding.to_string()));
                        let base64 = match encoding {
                            "raw" => false,
                            "base64" => true,
                            other => {
                                return Err(IoError::invalid(
                                    path,
                                    format!(
                                        "AppendedData encoding=\"{other}\": expected raw or base64"
                                    ),
                                ));
                            }
                        };
                        // The data starts after the first '_' past the tag.
                        let from = reader.buffer_position() as usize;
                        let underscore = bytes[from.min(bytes.len())..]
                            .iter()
                            .position(|&b| b == b'_')
                            .ok_or_else(|| {
                                IoError::invalid(
                                    path,
                                    "AppendedData has no '_' marking the start of its data",
                                )
                            })?;
                        s.appended = Some((from + underscore + 1, base64));
                        break;
                    }
                    _ => {}
                }
            }
            Event::Text(_) if nested == 0 => {
                if let Some(array) = current.as_mut() {
                    array.text.push(before..reader.buffer_position() as usize);
                }
            }
            Event::End(ref e) => match e.name().into_inner() {
                "DataArray" => {
                    if let Some(array) = current.take() {
                        push_array(path, &mut s, array)?;
                    }
                }
                "PointData" | "CellData" => section = None,
                _ => {}
            },
            Event::Eof => break,
            _ => {}
        }
    }
    if !seen_root {
        return Err(IoError::invalid(
            path,
            "no <VTKFile> element: not a VTK XML file",
        ));
    }
    if !seen_image {
        return Err(IoError::invalid(
            path,
            "no <ImageData> element in the VTKFile",
        ));
    }
    Ok(s)
}

fn push_array(path: &Path, s: &mut Structure, array: DataArray) -> Result<(), IoError> {
    let piece = s.pieces.last_mut().ok_or_else(|| {
        IoError::invalid(
            path,
            format!("DataArray \"{}\" outside a Piece", array.entry.name),
        )
    })?;
    piece.arrays.push(array);
    Ok(())
}

/// The `<VTKFile>` attributes.
fn root(
    path: &Path,
    attrs: &[(String, String)],
    s: &mut Structure,
    info: &mut FileInfo,
) -> Result<(), IoError> {
    for (k, v) in attrs {
        info.header.push((format!("VTKFile {k}"), v.clone()));
    }
    let kind = get(attrs, "type").unwrap_or("");
    if kind != "ImageData" {
        return Err(IoError::invalid(
            path,
            format!("VTKFile type=\"{kind}\": volray reads ImageData (.vti) files only"),
        ));
    }
    s.blocks.endian = match get(attrs, "byte_order") {
        Some("LittleEndian") => Endian::Little,
        Some("BigEndian") => Endian::Big,
        None => {
            info.notes
                .push("no byte_order given: little-endian assumed".to_string());
            Endian::Little
        }
        Some(other) => {
            return Err(IoError::invalid(
                path,
                format!("VTKFile byte_order=\"{other}\": expected LittleEndian or BigEndian"),
            ));
        }
    };
    // Files before version 1.0 have no header_type: their headers are UInt32.
    s.blocks.word = match get(attrs, "header_type") {
        None | Some("UInt32") => 4,
        Some("UInt64") => 8,
        Some(other) => {
            return Err(IoError::invalid(
                path,
                format!("VTKFile header_type=\"{other}\": expected UInt32 or UInt64"),
            ));
        }
    };
    s.blocks.compressed = match get(attrs, "compressor") {
        None | Some("") => None,
        Some("vtkZLibDataCompressor") => Some(Compression::Zlib),
        Some("vtkLZ4DataCompressor") => Some(Compression::Lz4Block),
        Some("vtkLZMADataCompressor") => Some(Compression::Xz),
        Some(other) => {
            return Err(IoError::invalid(
                path,
                format!(
                    "VTKFile compressor=\"{other}\": volray reads uncompressed, vtkZLibDataCompressor, vtkLZ4DataCompressor and vtkLZMADataCompressor data (re-save with one of them)"
                ),
            ));
        }
    };
    Ok(())
}

/// The `<ImageData>` attributes.
fn image(
    path: &Path,
    attrs: &[(String, String)],
    s: &mut Structure,
    info: &mut FileInfo,
) -> Result<(), IoError> {
    for (k, v) in attrs {
        info.header.push((format!("ImageData {k}"), v.clone()));
    }
    s.whole = numbers::<i64, 6>(path, attrs, "ImageData", "WholeExtent")?
        .ok_or_else(|| IoError::invalid(path, "ImageData has no WholeExtent"))?;
    if let Some(o) = numbers::<f64, 3>(path, attrs, "ImageData", "Origin")? {
        s.origin = DVec3::from(o);
    }
    if let Some(sp) = numbers::<f64, 3>(path, attrs, "ImageData", "Spacing")? {
        s.spacing = DVec3::from(sp);
        if !(s.spacing.is_finite()
            && s.spacing.x != 0.0
            && s.spacing.y != 0.0
            && s.spacing.z != 0.0)
        {
            return Err(IoError::invalid(
                path,
                format!(
                    "ImageData Spacing=\"{}\": spacings must be finite and non-zero",
                    join(&sp)
                ),
            ));
        }
    }
    if let Some(d) = numbers::<f64, 9>(path, attrs, "ImageData", "Direction")? {
        // Row-major in the file; from_cols_array takes columns, so transpose.
        s.direction = DMat3::from_cols_array(&d).transpose();
    }
    Ok(())
}

/// A `<DataArray>` element's description.
fn data_array(
    path: &Path,
    attrs: &[(String, String)],
    assoc: Association,
    scalars: Option<&str>,
    info: &mut FileInfo,
) -> Result<DataArray, IoError> {
    let name = get(attrs, "Name").unwrap_or("").to_string();
    let summary: Vec<String> = attrs
        .iter()
        .filter(|(k, _)| !k.starts_with("Range"))
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    let section = match assoc {
        Association::Point => "PointData",
        Association::Cell => "CellData",
    };
    info.header
        .push((format!("{section} DataArray"), summary.join(" ")));
    let type_attr = get(attrs, "type").unwrap_or("");
    let dtype = sample_type(type_attr).ok_or_else(|| {
        IoError::invalid(
            path,
            format!(
                "DataArray \"{name}\" type=\"{type_attr}\": volray reads Int8..Int64, UInt8..UInt64, Float32 and Float64"
            ),
        )
    })?;
    let components = match get(attrs, "NumberOfComponents") {
        None => 1,
        Some(c) => c
            .trim()
            .parse::<usize>()
            .ok()
            .filter(|&c| (1..=1024).contains(&c))
            .ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!("DataArray \"{name}\" NumberOfComponents=\"{c}\": expected 1 to 1024"),
                )
            })?,
    };
    let format = match get(attrs, "format").unwrap_or("ascii") {
        "ascii" => Format::Ascii,
        "binary" => Format::Binary,
        "appended" => Format::Appended,
        other => {
            return Err(IoError::invalid(
                path,
                format!(
                    "DataArray \"{name}\" format=\"{other}\": expected ascii, binary or appended"
                ),
            ));
        }
    };
    let offset = match (format, get(attrs, "offset")) {
        (Format::Appended, Some(o)) => o.trim().parse::<u64>().map_err(|_| {
            IoError::invalid(
                path,
                format!("DataArray \"{name}\" offset=\"{o}\": not a byte offset"),
            )
        })?,
        (Format::Appended, None) => {
            return Err(IoError::invalid(
                path,
                format!("appended DataArray \"{name}\" has no offset"),
            ));
        }
        _ => 0,
    };
    Ok(DataArray {
        entry: ArrayEntry {
            active_scalars: scalars == Some(name.as_str()),
            name,
            association: assoc,
            components,
            type_name: type_attr.to_string(),
        },
        dtype,
        format,
        offset,
        text: Vec::new(),
    })
}
