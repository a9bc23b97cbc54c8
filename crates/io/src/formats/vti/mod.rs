//! VTK XML image data (`.vti`): `<VTKFile type="ImageData">` with a
//! `WholeExtent`, `Origin`, `Spacing`, optional `Direction` (VTK 9), one or
//! more `Piece`s, and `PointData`/`CellData` `DataArray`s.
//!
//! Array data may be `format="ascii"` (numbers in the element),
//! `"binary"` (base64 in the element) or `"appended"` (at `offset` after
//! the `_` of `<AppendedData encoding="raw|base64">`). Binary and appended
//! data start with a block header of `header_type` words (UInt32 or
//! UInt64, in the file's `byte_order`): the byte count, or with a
//! `compressor` (`vtkZLibDataCompressor`, `vtkLZ4DataCompressor`,
//! `vtkLZMADataCompressor`) the block count, block size, last block size
//! and each block's compressed size (vtkXMLWriter); each block is one zlib
//! stream, raw LZ4 block or xz stream. VTK base64-encodes a compressed
//! array's header and data separately, an uncompressed one as one stream;
//! both are accepted either way.
//!
//! The XML part is read in `structure` (quick-xml, up to `<AppendedData>`,
//! whose raw bytes are not XML), the binary framing in `blocks`; this file
//! picks the array, decodes it in every piece, assembles the pieces and
//! sets the geometry. Every size a header declares is checked against the
//! bytes that hold it and against `--max-memory` before anything is
//! allocated, and a compressed size against its codec's largest ratio
//! (zlib, LZ4). Array choice and cell data:
//! [`crate::shared::vtk_arrays`].

mod blocks;
mod structure;

use std::io::Read;
use std::path::Path;

use volray_core::glam::{DMat3, DVec3};

use crate::dtype::{DType, bytes_to_f32};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::open_input;
use crate::shared::limits::{F32_BYTES, check_file_held, check_memory};
use crate::shared::vtk_arrays::{
    ArrayEntry, Association, cell_centres, cell_dims, no_match, not_scalar, rank, record_choice,
};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};
use blocks::{base64_block, raw_block};
use structure::{DataArray, Format, Structure, join, parse, type_name};

/// Whether the first bytes of a file, as text, start an XML file.
pub(crate) fn starts_as_xml(text: &str) -> bool {
    let text = text.trim_start();
    text.starts_with("<?xml") || text.starts_with("<VTKFile")
}

/// Whether the first bytes of a file, as text, look like VTK XML image
/// data: XML that mentions `ImageData`.
pub(crate) fn sniff_text(text: &str) -> bool {
    starts_as_xml(text) && text.contains("ImageData")
}

/// Reads the VTK XML image data file at `path` (see the module documentation).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (mut file, len) = open_input(path)?;
    // The file is held whole (its XML locates the arrays' bytes).
    check_file_held(path, len, opts.max_memory)?;
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.read_to_end(&mut bytes)
        .map_err(|e| IoError::os(path, "read", e))?;
    let mut info = FileInfo::new("");
    let s = parse(path, &bytes, &mut info)?;

    // The arrays of the first piece name the choices; every piece must
    // hold the chosen one.
    let first = s
        .pieces
        .first()
        .ok_or_else(|| IoError::invalid(path, "ImageData has no Piece: the file holds no data"))?;
    let entries: Vec<ArrayEntry> = first.arrays.iter().map(|a| a.entry.clone()).collect();
    let request = opts.array.as_deref();
    let mut best: Option<(u8, usize)> = None;
    for (i, e) in entries.iter().enumerate() {
        if let Some(r) = rank(e, request)
            && best.is_none_or(|(b, _)| r < b)
        {
            best = Some((r, i));
        }
    }
    let Some((_, chosen)) = best else {
        return Err(no_match(path, &entries, request));
    };
    let entry = entries[chosen].clone();
    if entry.components != 1 {
        return Err(not_scalar(path, &entry, &entries));
    }
    record_choice(&mut info, &entries, &entry, request);
    let cell = entry.association == Association::Cell;

    let whole_points = extent_dims(path, &s.whole, "WholeExtent")?;
    let whole = if cell {
        cell_dims(whole_points)
    } else {
        whole_points
    };
    let whole_count = whole
        .iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .ok_or_else(|| {
            IoError::invalid(
                path,
                format!(
                    "WholeExtent {} is too large: the point count overflows",
                    join(&s.whole)
                ),
            )
        })?;
    // Each piece's stored bytes and its f32 values are held together, and
    // several pieces are assembled into a copy of the whole.
    let stored = first.arrays[chosen].dtype.size() as u64;
    let copies = if s.pieces.len() > 1 { 2 } else { 1 };
    check_memory(
        path,
        &format!("WholeExtent {}", join(&s.whole)),
        whole_count as u128,
        stored + copies * F32_BYTES,
        opts.max_memory,
    )?;

    // Decode the chosen array of every piece (each bounded by the file).
    let mut blocks = Vec::with_capacity(s.pieces.len());
    let mut covered = 0usize;
    let mut dtype = None;
    for (p, piece) in s.pieces.iter().enumerate() {
        for a in 0..3 {
            if piece.extent[2 * a] < s.whole[2 * a] || piece.extent[2 * a + 1] > s.whole[2 * a + 1]
            {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "Piece {p} Extent {} lies outside WholeExtent {}",
                        join(&piece.extent),
                        join(&s.whole)
                    ),
                ));
            }
        }
        let array = piece
            .arrays
            .iter()
            .find(|a| a.entry.name == entry.name && a.entry.association == entry.association)
            .ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!(
                        "Piece {p} has no {} array \"{}\"",
                        entry.association.name(),
                        entry.name
                    ),
                )
            })?;
        if array.entry.components != 1 {
            return Err(not_scalar(path, &array.entry, &entries));
        }
        let points = extent_dims(path, &piece.extent, &format!("Piece {p} Extent"))?;
        let dims = if cell { cell_dims(points) } else { points };
        let count = dims
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
            .ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!(
                        "Piece {p} Extent {}: the point count overflows",
                        join(&piece.extent)
                    ),
                )
            })?;
        let values = decode(path, &bytes, &s, array, count)?;
        covered = covered.saturating_add(count);
        dtype = Some(array.dtype);
        blocks.push((piece.extent, dims, values));
    }
    info.stored_type = format!(
        "{} ({}-endian)",
        type_name(dtype.unwrap_or(DType::F32)),
        s.blocks.endian
    );

    let data = if blocks.len() == 1 && blocks[0].1 == whole {
        blocks.pop().map(|b| b.2).unwrap_or_default()
    } else {
        assemble(path, &s, cell, whole, whole_count, covered, &blocks)?
    };

    // World geometry: x = Origin + Direction · (index ⊙ Spacing), with the
    // index counted from 0 in extent coordinates.
    let steps = [0, 1, 2].map(|a| column(&s.direction, a) * s.spacing[a]);
    let start = DVec3::new(s.whole[0] as f64, s.whole[2] as f64, s.whole[4] as f64);
    let mut origin = s.origin;
    for a in 0..3 {
        origin += steps[a] * start[a];
    }
    if cell {
        origin = cell_centres(whole_points, steps, origin, &mut info, &entry.name);
    }
    let volume = grid_to_volume(path, whole, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Vti,
        info,
    })
}

/// Column `a` of the row-major direction matrix: the world direction of
/// index axis `a`.
fn column(d: &DMat3, a: usize) -> DVec3 {
    DVec3::new(d.row(0)[a], d.row(1)[a], d.row(2)[a])
}

/// Points per axis of an extent `x0 x1 y0 y1 z0 z1`.
fn extent_dims(path: &Path, e: &[i64; 6], what: &str) -> Result<[usize; 3], IoError> {
    let mut dims = [0usize; 3];
    for a in 0..3 {
        let n = e[2 * a + 1]
            .checked_sub(e[2 * a])
            .and_then(|d| d.checked_add(1))
            .filter(|&d| d >= 1)
            .and_then(|d| usize::try_from(d).ok())
            .ok_or_else(|| {
                IoError::invalid(path, format!("{what} {} is empty or inverted", join(e)))
            })?;
        dims[a] = n;
    }
    Ok(dims)
}

/// Places each piece's values into the whole grid, checking that the
/// pieces cover it. `covered` (the pieces' total) bounds the allocation.
fn assemble(
    path: &Path,
    s: &Structure,
    cell: bool,
    whole: [usize; 3],
    whole_count: usize,
    covered: usize,
    blocks: &[([i64; 6], [usize; 3], Vec<f32>)],
) -> Result<Vec<f32>, IoError> {
    if covered < whole_count {
        return Err(IoError::invalid(
            path,
            format!(
                "the pieces hold {covered} values but WholeExtent {} needs {whole_count}: the pieces do not cover it",
                join(&s.whole)
            ),
        ));
    }
    let mut data = vec![f32::NAN; whole_count];
    let mut seen = vec![false; whole_count];
    for (extent, dims, values) in blocks {
        // The block's first index in the whole grid (cells: as points, since
        // cell i lies between points i and i + 1).
        let off = [0, 1, 2].map(|a| (extent[2 * a] - s.whole[2 * a]) as usize);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let (x, y, z) = (off[0] + i, off[1] + j, off[2] + k);
                    if x >= whole[0] || y >= whole[1] || z >= whole[2] {
                        continue; // a degenerate axis's single cell
                    }
                    let at = x + whole[0] * (y + whole[1] * z);
                    data[at] = values[i + dims[0] * (j + dims[1] * k)];
                    seen[at] = true;
                }
            }
        }
    }
    if let Some(missing) = seen.iter().position(|&b| !b) {
        let (x, y, z) = (
            missing % whole[0],
            (missing / whole[0]) % whole[1],
            missing / (whole[0] * whole[1]),
        );
        return Err(IoError::invalid(
            path,
            format!(
                "the pieces do not cover WholeExtent {}: no {} ({x}, {y}, {z})",
                join(&s.whole),
                if cell { "cell" } else { "point" }
            ),
        ));
    }
    Ok(data)
}

/// The `count` values of `array`, converted to `f32`.
fn decode(
    path: &Path,
    bytes: &[u8],
    s: &Structure,
    array: &DataArray,
    count: usize,
) -> Result<Vec<f32>, IoError> {
    let name = &array.entry.name;
    let expected = count.checked_mul(array.dtype.size()).ok_or_else(|| {
        IoError::invalid(
            path,
            format!("DataArray \"{name}\": the byte count overflows"),
        )
    })?;
    let raw = match array.format {
        Format::Ascii => return ascii(path, bytes, array, count),
        Format::Binary => {
            let text: Vec<u8> = array
                .text
                .iter()
                .flat_map(|r| bytes[r.clone()].iter().copied())
                .filter(|b| !b.is_ascii_whitespace())
                .collect();
            base64_block(path, &text, &s.blocks, expected, name, true)?
        }
        Format::Appended => {
            let (start, base64) = s.appended.ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!("DataArray \"{name}\" is appended, but the file has no AppendedData"),
                )
            })?;
            let at = usize::try_from(array.offset)
                .ok()
                .and_then(|o| start.checked_add(o))
                .filter(|&at| at <= bytes.len())
                .ok_or_else(|| {
                    IoError::invalid(
                        path,
                        format!(
                            "DataArray \"{name}\" offset={} lies beyond the end of the file ({} bytes of appended data)",
                            array.offset,
                            bytes.len().saturating_sub(start)
                        ),
                    )
                })?;
            if base64 {
                base64_block(path, &bytes[at..], &s.blocks, expected, name, false)?
            } else {
                raw_block(path, &bytes[at..], &s.blocks, expected, name)?
            }
        }
    };
    Ok(bytes_to_f32(&raw, array.dtype, s.blocks.endian))
}

/// ASCII values: whitespace-separated numbers in the element.
fn ascii(path: &Path, bytes: &[u8], array: &DataArray, count: usize) -> Result<Vec<f32>, IoError> {
    let name = &array.entry.name;
    let len: usize = array.text.iter().map(|r| r.len()).sum();
    if count > len.div_ceil(2) {
        return Err(IoError::invalid(
            path,
            format!(
                "ascii DataArray \"{name}\" needs {count} values, but its text is only {len} bytes"
            ),
        ));
    }
    let mut out = Vec::with_capacity(count);
    for range in &array.text {
        for token in bytes[range.clone()]
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty())
        {
            if out.len() == count {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "ascii DataArray \"{name}\" holds more than the {count} values its extent needs"
                    ),
                ));
            }
            let t = String::from_utf8_lossy(token);
            let value = match array.dtype {
                DType::F16 | DType::F32 => t.parse::<f32>().ok(),
                DType::F64 => t.parse::<f64>().ok().map(|v| v as f32),
                DType::U64 => t.parse::<u64>().ok().map(|v| v as f32),
                _ => t.parse::<i64>().ok().map(|v| v as f32),
            }
            .ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!(
                        "ascii DataArray \"{name}\" value {} is \"{t}\": not a {} number",
                        out.len(),
                        array.entry.type_name
                    ),
                )
            })?;
            out.push(value);
        }
    }
    if out.len() < count {
        return Err(IoError::invalid(
            path,
            format!(
                "ascii DataArray \"{name}\" holds {} values, but its extent needs {count}",
                out.len()
            ),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_columns_are_index_axes() {
        // Row-major "0 -1 0 1 0 0 0 0 1": i runs along +y, j along -x.
        let d = DMat3::from_cols_array(&[0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]).transpose();
        assert_eq!(column(&d, 0), DVec3::Y);
        assert_eq!(column(&d, 1), -DVec3::X);
        assert_eq!(column(&d, 2), DVec3::Z);
    }
}
