//! MRtrix images (`.mif`, `.mih` with its data file, `.mif.gz`): the
//! format of MRtrix3's diffusion-MRI tools, read with volray's own parser.
//!
//! The layout (MRtrix3 documentation, "Image file formats: MRtrix image
//! formats"): a text header, then (`.mif`) the data in the same file at
//! the offset the `file:` line gives, or (`.mih`) in the file it names:
//!
//! ```text
//! mrtrix image
//! dim: 96,96,60,65          samples along each axis
//! vox: 2.5,2.5,2.5,NaN      voxel sizes (mm)
//! layout: +1,+2,+3,+0       each axis's rank in memory (0 fastest), and its sense:
//!                           '-' stores the axis from its last sample to its first
//! datatype: Int16LE         Int8, UInt8, (U)Int16/32, Float32, Float64; LE/BE
//! transform: r11,r12,r13,t1 rows of the image-to-scanner transform (three lines)
//! scaling: offset,scale     optional: value = offset + scale · stored
//! file: . 512               the data file ('.': this one) and its byte offset
//! END
//! ```
//!
//! The world position of index (i, j, k) is `R · diag(vox) · (i, j, k) + t`
//! with the transform's rotation R (unit columns) and translation t, in
//! scanner (RAS+) millimetres; `grid_to_volume` places the grid. A fourth
//! axis (diffusion volumes, time) holds volumes: `--frame` picks one. The
//! samples are read in memory order and gathered into index order, so
//! both buffers count against `--max-memory`; values are kept as `f32`.

use std::io::{self, Read};
use std::path::{Path, PathBuf};

use volray_core::glam::DVec3;

use crate::dtype::{DType, Endian, extend_f32};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::read_samples;
use crate::shared::limits::{check_held, format_bytes};
use crate::shared::packed::open_unpacked;
use crate::shared::text_reader::{TextReader, parse_number};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Most header lines read before `END`.
const MAX_LINES: usize = 10_000;

/// Whether a file's first bytes open as an MRtrix header.
pub(crate) fn sniff_text(text: &str) -> bool {
    text.lines()
        .next()
        .is_some_and(|l| l.trim_end() == "mrtrix image")
}

/// The header's fields volray uses.
struct Header {
    dims: Vec<usize>,
    vox: Vec<f64>,
    /// Per axis: its rank in memory and whether it runs backwards.
    layout: Vec<(usize, bool)>,
    dtype: DType,
    endian: Endian,
    transform: Vec<[f64; 4]>,
    scaling: Option<(f64, f64)>,
    file: (PathBuf, u64),
}

fn list<T>(value: &str, what: &str, parse: impl Fn(&str) -> Option<T>) -> Result<Vec<T>, String> {
    value
        .split(',')
        .map(|t| parse(t.trim()).ok_or_else(|| format!("{what}: \"{}\" is not valid", t.trim())))
        .collect()
}

fn datatype(value: &str) -> Result<(DType, Endian), String> {
    let (base, endian) = if let Some(b) = value.strip_suffix("LE") {
        (b, Endian::Little)
    } else if let Some(b) = value.strip_suffix("BE") {
        (b, Endian::Big)
    } else {
        (value, Endian::Little)
    };
    let dtype =
        match base {
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
            "Bit" => return Err(
                "datatype Bit (a packed mask): not read; convert it with mrconvert -datatype uint8"
                    .into(),
            ),
            other if other.starts_with('C') => {
                return Err(format!(
                    "datatype {value} (complex): volray renders real values"
                ));
            }
            _ => return Err(format!("datatype \"{value}\": not an MRtrix data type")),
        };
    Ok((dtype, endian))
}

/// Reads the header of `path` (fields up to `END`).
fn header(path: &Path) -> Result<(Header, FileInfo), IoError> {
    let mut r = TextReader::new(path, open_unpacked(path)?.reader);
    let first = r.line("the first line, \"mrtrix image\"")?;
    if first.trim_end() != "mrtrix image" {
        return Err(r.error("an MRtrix header starts with \"mrtrix image\""));
    }
    let mut info = FileInfo::new("");
    let (mut dims, mut vox, mut layout, mut dtype, mut file) = (None, None, None, None, None);
    let mut transform = Vec::new();
    let mut scaling = None;
    for _ in 0..MAX_LINES {
        let line = r.line("END")?;
        let line = line.trim();
        if line == "END" {
            let missing = |what: &str| r.error(format!("the header ends with no {what} line"));
            let dims: Vec<usize> = dims.ok_or_else(|| missing("dim"))?;
            let n = dims.len();
            let layout = layout.unwrap_or_else(|| (0..n).map(|a| (a, false)).collect());
            let vox: Vec<f64> = vox.unwrap_or_else(|| vec![1.0; n]);
            let (dtype, endian) = dtype.ok_or_else(|| missing("datatype"))?;
            let file = file.ok_or_else(|| missing("file"))?;
            return Ok((
                Header {
                    dims,
                    vox,
                    layout,
                    dtype,
                    endian,
                    transform,
                    scaling,
                    file,
                },
                info,
            ));
        }
        let Some((key, value)) = line.split_once(':') else {
            return Err(r.error(format!("\"{line}\" is no \"key: value\" line")));
        };
        let (key, value) = (key.trim(), value.trim());
        info.header.push((key.to_string(), value.to_string()));
        let parsed: Result<(), String> = (|| {
            match key {
                "dim" => {
                    let d = list(value, "dim", |t| t.parse::<usize>().ok().filter(|&n| n > 0))?;
                    if !(3..=4).contains(&d.len()) {
                        return Err(format!("dim has {} axes: volray reads 3 or 4", d.len()));
                    }
                    dims = Some(d);
                }
                "vox" => vox = Some(list(value, "vox", parse_number)?),
                "layout" => {
                    layout = Some(list(value, "layout", |t| {
                        let (back, rank) = match t.as_bytes().first()? {
                            b'-' => (true, &t[1..]),
                            b'+' => (false, &t[1..]),
                            _ => (false, t),
                        };
                        Some((rank.parse::<usize>().ok()?, back))
                    })?)
                }
                "datatype" => dtype = Some(datatype(value)?),
                "transform" => {
                    let row = list(value, "transform", parse_number)?;
                    if row.len() != 4 || transform.len() == 3 {
                        return Err("transform: three rows of four numbers".into());
                    }
                    transform.push([row[0], row[1], row[2], row[3]]);
                }
                "scaling" => {
                    let s = list(value, "scaling", parse_number)?;
                    if s.len() != 2 || s.iter().any(|v| !v.is_finite()) {
                        return Err("scaling: offset,scale".into());
                    }
                    scaling = Some((s[0], s[1]));
                }
                "file" => {
                    if file.is_some() {
                        return Err(
                            "several file lines: volray reads images in one data file".into()
                        );
                    }
                    let mut words = value.split_whitespace();
                    let name = words.next().ok_or("file: no name")?;
                    let offset = match words.next() {
                        Some(o) => o
                            .parse::<u64>()
                            .map_err(|_| format!("file: offset \"{o}\""))?,
                        None => 0,
                    };
                    let at = if name == "." {
                        path.to_path_buf()
                    } else {
                        path.parent().unwrap_or(Path::new(".")).join(name)
                    };
                    file = Some((at, offset));
                }
                _ => {}
            }
            Ok(())
        })();
        parsed.map_err(|e| r.error(e))?;
    }
    Err(r.error(format!("no END line within {MAX_LINES} lines")))
}

/// Reads the MRtrix image at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (h, mut info) = header(path)?;
    let invalid = |reason: String| IoError::invalid(path, reason);
    let n = h.dims.len();
    if h.vox.len() != n || h.layout.len() != n {
        return Err(invalid(format!(
            "dim has {n} axes but vox {} and layout {}",
            h.vox.len(),
            h.layout.len()
        )));
    }
    let mut ranks: Vec<usize> = h.layout.iter().map(|l| l.0).collect();
    ranks.sort_unstable();
    if ranks != (0..n).collect::<Vec<_>>() {
        return Err(invalid(
            "layout: the ranks are not 0 to n-1, each once".into(),
        ));
    }
    if let Some(a) = (0..3).find(|&a| !(h.vox[a].is_finite() && h.vox[a] > 0.0)) {
        return Err(invalid(format!(
            "vox {}: {} is no voxel size",
            a + 1,
            h.vox[a]
        )));
    }
    info.stored_type = format!(
        "{} ({}-endian)",
        h.dtype.name(),
        if h.endian == Endian::Little {
            "little"
        } else {
            "big"
        }
    );
    let dims = [h.dims[0], h.dims[1], h.dims[2]];
    let frames = h.dims.get(3).copied().unwrap_or(1);
    let frame = opts.frame.unwrap_or(0);
    if frame >= frames {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the image holds {frames} volume(s) (frames 0 to {})",
                frames - 1
            ),
        ));
    }
    info.frames = frames;
    info.frame = frame;
    let total = h
        .dims
        .iter()
        .try_fold(1u64, |p, &d| p.checked_mul(d as u64));
    let total = total.ok_or_else(|| invalid("dim: too many samples to count".into()))?;
    let (data_path, offset) = &h.file;
    let opened = open_unpacked(data_path)?;
    let need = total
        .saturating_mul(h.dtype.size() as u64)
        .saturating_add(*offset);
    if need > opened.len {
        return Err(invalid(format!(
            "the header declares {} samples of {} from byte {offset} ({need} bytes), but {} is a {}",
            total,
            h.dtype.name(),
            data_path.display(),
            opened.size_phrase()
        )));
    }
    let count = dims[0] * dims[1] * dims[2];
    // Every sample in memory order, and the volume gathered from them.
    let peak = (total as u128 + count as u128) * 4;
    check_held(
        path,
        &format!(
            "dim {}",
            h.dims
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(",")
        ),
        total as u128,
        peak,
        &format!(
            "{} as f32 in memory order and as a volume",
            format_bytes(peak)
        ),
        opts.max_memory,
    )?;
    info.notes.extend(opened.note());
    let mut reader = opened.reader;
    let skipped = io::copy(&mut (&mut reader).take(*offset), &mut io::sink())
        .map_err(|e| IoError::os(data_path, "read", e))?;
    if skipped < *offset {
        return Err(invalid(format!("the data file ends before byte {offset}")));
    }
    let mut stored = Vec::with_capacity(total as usize);
    let (dtype, endian) = (h.dtype, h.endian);
    read_samples(
        data_path,
        &mut reader,
        total as usize,
        dtype.size(),
        *offset,
        |bytes, out: &mut Vec<f32>| extend_f32(out, bytes, dtype, endian),
        |v| stored.extend_from_slice(v),
    )?;

    // Memory strides from the layout: rank 0 fastest.
    let mut stride = vec![0usize; n];
    let mut step = 1;
    for rank in 0..n {
        let axis = h
            .layout
            .iter()
            .position(|l| l.0 == rank)
            .expect("ranks checked");
        stride[axis] = step;
        step *= h.dims[axis];
    }
    let at = |axis: usize, i: usize| {
        let i = if h.layout[axis].1 {
            h.dims[axis] - 1 - i
        } else {
            i
        };
        i * stride[axis]
    };
    let base = if n == 4 { at(3, frame) } else { 0 };
    let (offset_v, scale) = h.scaling.unwrap_or((0.0, 1.0));
    let mut data = Vec::with_capacity(count);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let v = stored[base + at(0, i) + at(1, j) + at(2, k)];
                data.push(if h.scaling.is_some() {
                    (offset_v + scale * f64::from(v)) as f32
                } else {
                    v
                });
            }
        }
    }
    drop(stored);
    if h.scaling.is_some() {
        info.notes.push(format!(
            "values scaled: {offset_v} + {scale} x stored (scaling)"
        ));
    }

    // World: R · diag(vox) · index + t; identity where no transform is given.
    let (columns, origin) = if h.transform.len() == 3 {
        let t = &h.transform;
        (
            [0, 1, 2].map(|c| DVec3::new(t[0][c], t[1][c], t[2][c])),
            DVec3::new(t[0][3], t[1][3], t[2][3]),
        )
    } else if h.transform.is_empty() {
        info.notes
            .push("no transform: the image's axes are the world's, from 0".into());
        ([DVec3::X, DVec3::Y, DVec3::Z], DVec3::ZERO)
    } else {
        return Err(invalid(format!(
            "{} transform line(s): the transform has three",
            h.transform.len()
        )));
    };
    let steps = [0, 1, 2].map(|a| columns[a] * h.vox[a]);
    info.length_unit = Some("mm".into());
    let volume = grid_to_volume(path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Mrtrix,
        info,
    })
}
