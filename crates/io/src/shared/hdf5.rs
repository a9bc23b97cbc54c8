//! HDF5 files through `hdf5-pure` (pure Rust: no C library, no build
//! step): opening a file, reading attributes as numbers or text, and
//! reading a numeric dataset's rows into `f64`s after checking its size
//! against the file's length and the memory limit. Used by the HDF5
//! dataset reader and the MINC2 reader.

use std::path::Path;

use hdf5_pure::{AttrValue, DType as H5Type, Dataset, DatatypeByteOrder, File, ReadSeekSource};

use crate::error::IoError;
use crate::shared::input::open_input;
use crate::shared::limits::{check_held, count_values, format_bytes};

/// A dataset may decode to at most this many times the file's length
/// (compressed chunks; deflate inflates at most about 1032:1), or to
/// [`SMALL_FILE_ALLOWANCE`] bytes whatever the file's length.
const MAX_INFLATION: u64 = crate::shared::compress::MAX_DEFLATE_RATIO;
const SMALL_FILE_ALLOWANCE: u64 = 64 << 20;

/// Samples read per slab of rows.
const SLAB_SAMPLES: usize = 1 << 20;

/// An open HDF5 file and its length in bytes.
pub(crate) struct H5File {
    pub file: File,
    pub len: u64,
}

/// Opens the HDF5 file at `path`; a file that is not HDF5 is refused as
/// bad input, one that cannot be opened as an I/O failure.
pub(crate) fn open(path: &Path) -> Result<H5File, IoError> {
    let (handle, len) = open_input(path)?;
    let fail =
        |e: &dyn std::fmt::Display| IoError::invalid(path, format!("HDF5: cannot open: {e}"));
    let source = ReadSeekSource::new(handle).map_err(|e| fail(&e))?;
    let file = File::from_source(source).map_err(|e| fail(&e))?;
    // As libhdf5 does: a file shorter than its superblock's end-of-file
    // address was cut short, whatever parts of it still parse.
    let superblock = file.superblock();
    let eof = superblock
        .eof_address
        .saturating_add(superblock.base_address.get());
    if eof > len {
        return Err(IoError::invalid(
            path,
            format!(
                "HDF5: truncated file: {len} bytes, but its superblock says it ends at byte {eof}"
            ),
        ));
    }
    Ok(H5File { file, len })
}

/// A numeric dataset's sample type: bytes per sample and the name
/// `volray info` shows (`"int16 (big-endian)"`).
pub(crate) struct NumericType {
    pub size: usize,
    pub name: String,
}

/// The numeric type of `dataset`, or why it has none (`"type string is
/// not numeric: ..."`).
pub(crate) fn numeric_type(dataset: &Dataset) -> Result<NumericType, String> {
    let kind = dataset
        .dtype()
        .map_err(|e| format!("unreadable type: {e}"))?;
    let (size, name) = match kind {
        H5Type::I8 => (1, "int8"),
        H5Type::U8 => (1, "uint8"),
        H5Type::I16 => (2, "int16"),
        H5Type::U16 => (2, "uint16"),
        H5Type::I32 => (4, "int32"),
        H5Type::U32 => (4, "uint32"),
        H5Type::F32 => (4, "float32"),
        H5Type::I64 => (8, "int64"),
        H5Type::U64 => (8, "uint64"),
        H5Type::F64 => (8, "float64"),
        other => {
            return Err(format!(
                "type {other} is not numeric: volray reads integer and float datasets"
            ));
        }
    };
    let order = match dataset.datatype() {
        Ok(
            hdf5_pure::Datatype::FixedPoint { byte_order, .. }
            | hdf5_pure::Datatype::FloatingPoint { byte_order, .. },
        ) if size > 1 => match byte_order {
            DatatypeByteOrder::BigEndian => " (big-endian)",
            DatatypeByteOrder::LittleEndian => " (little-endian)",
            DatatypeByteOrder::Vax => " (VAX order)",
        },
        _ => "",
    };
    Ok(NumericType {
        size,
        name: format!("{name}{order}"),
    })
}

/// Whether `dataset` holds integers or floats.
pub(crate) fn is_numeric(dataset: &Dataset) -> bool {
    numeric_type(dataset).is_ok()
}

/// The shape of `dataset` as `usize`s.
pub(crate) fn shape(dataset: &Dataset) -> Result<Vec<usize>, String> {
    let shape = dataset
        .shape()
        .map_err(|e| format!("unreadable shape: {e}"))?;
    shape
        .iter()
        .map(|&n| usize::try_from(n).map_err(|_| format!("shape {shape:?} is too large")))
        .collect()
}

/// Rows of the first axis read at once for rows of `row` samples: whole
/// chunks adding up to about [`SLAB_SAMPLES`], or, where one chunk is
/// larger than that, as many rows as fit [`SLAB_SAMPLES`] (at least one),
/// so that a header's chunk size cannot make the scratch buffer large.
fn slab_rows(row: usize, chunk0: usize) -> usize {
    let row = row.max(1);
    let chunk0 = chunk0.max(1);
    if row.saturating_mul(chunk0) <= SLAB_SAMPLES {
        (SLAB_SAMPLES / row / chunk0).max(1) * chunk0
    } else {
        (SLAB_SAMPLES / row).max(1)
    }
}

/// The dataset's chunk extent along axis `axis`, 1 if not chunked.
fn chunk_along(dataset: &Dataset, axis: usize) -> usize {
    dataset
        .chunk_shape()
        .ok()
        .flatten()
        .and_then(|c| c.get(axis).copied())
        .and_then(|n| usize::try_from(n).ok())
        .unwrap_or(1)
        .max(1)
}

/// How one volume of a dataset is read: the volume is the last three
/// axes of its shape; a 3-D dataset is read in slabs of rows of its first
/// axis (whole chunks at a time), a volume of a series (a 4-D dataset,
/// `frame` chosen) as its one row of the first axis, whole.
pub(crate) struct Slabs<'d> {
    dataset: &'d Dataset,
    shape: &'d [usize],
    frames: usize,
    sample_size: usize,
    /// Rows of the volume's first axis, and samples per row.
    rows: usize,
    row: usize,
    frame: Option<usize>,
    slab: usize,
}

impl<'d> Slabs<'d> {
    /// The reading of a dataset of `shape` (3 or 4 axes; the first of 4
    /// holds `frames` volumes, of which `frame` is read) and samples of
    /// `sample_size` bytes.
    pub(crate) fn new(
        dataset: &'d Dataset,
        shape: &'d [usize],
        frames: usize,
        frame: Option<usize>,
        sample_size: usize,
    ) -> Self {
        let volume = &shape[shape.len().saturating_sub(3)..];
        let rows = volume.first().copied().unwrap_or(1);
        let row = volume
            .iter()
            .skip(1)
            .fold(1usize, |a, &n| a.saturating_mul(n));
        Slabs {
            dataset,
            shape,
            frames,
            sample_size,
            rows,
            row,
            frame,
            slab: slab_rows(row, chunk_along(dataset, 0)),
        }
    }

    /// Checks that the dataset could come out of a file of `file_len`
    /// bytes (at most [`MAX_INFLATION`] times its length, or
    /// [`SMALL_FILE_ALLOWANCE`]), and that one volume of it as f32, beside
    /// the samples held at once (stored and as f64), fits `max_memory`.
    /// Returns the samples of one volume. `what` names the shape for
    /// messages.
    pub(crate) fn check(
        &self,
        path: &Path,
        what: &str,
        file_len: u64,
        max_memory: u64,
    ) -> Result<usize, IoError> {
        let dims64: Vec<u64> = self.shape.iter().map(|&n| n as u64).collect();
        let values = count_values(path, what, &dims64)?;
        let budget = file_len
            .saturating_mul(MAX_INFLATION)
            .max(SMALL_FILE_ALLOWANCE);
        let sample_size = self.sample_size;
        let bytes = (values as u64).saturating_mul(sample_size as u64);
        if bytes > budget {
            return Err(IoError::invalid(
                path,
                format!(
                    "{what} of {sample_size}-byte samples is {bytes} bytes, more than a {file_len}-byte file can hold even compressed"
                ),
            ));
        }
        let volume = values / self.frames.max(1);
        let peak = volume as u128 * 4 + self.scratch() as u128 * (8 + sample_size as u128);
        check_held(
            path,
            what,
            volume as u128,
            peak,
            &format!("{} as f32 and an f64 slab", format_bytes(peak)),
            max_memory,
        )?;
        Ok(volume)
    }

    /// The samples held at once.
    pub(crate) fn scratch(&self) -> usize {
        match self.frame {
            Some(_) => self.rows.saturating_mul(self.row),
            None => self.row.saturating_mul(self.slab.min(self.rows)),
        }
    }

    /// Reads the volume, handing each slab to `take` with the C-order
    /// index of its first sample within the volume.
    pub(crate) fn read(&self, mut take: impl FnMut(usize, &[f64])) -> Result<(), String> {
        if let Some(frame) = self.frame {
            take(0, &self.rows_of(frame, 1, self.rows * self.row)?);
            return Ok(());
        }
        let mut first = 0;
        while first < self.rows {
            let end = (first + self.slab).min(self.rows);
            take(
                first * self.row,
                &self.rows_of(first, end - first, self.row)?,
            );
            first = end;
        }
        Ok(())
    }

    /// Rows `first..first + count` of the dataset's first axis, each of
    /// `row` samples, checked to be as many as asked for.
    fn rows_of(&self, first: usize, count: usize, row: usize) -> Result<Vec<f64>, String> {
        let values = self
            .dataset
            .read_f64_rows(first as u64, count as u64)
            .map_err(|e| format!("cannot read: {e}"))?;
        if values.len() != count * row {
            return Err(format!(
                "cannot read: rows {first}..{} gave {} values, expected {}",
                first + count,
                values.len(),
                count * row
            ));
        }
        Ok(values)
    }
}

/// Reads a whole small dataset (an attribute-like array: a slice's
/// minimum and maximum) as `f64`s, at most `max` of them.
pub(crate) fn read_small(dataset: &Dataset, max: usize) -> Result<Vec<f64>, String> {
    let n: u64 = dataset
        .shape()
        .map_err(|e| format!("unreadable shape: {e}"))?
        .iter()
        .try_fold(1u64, |a, &b| a.checked_mul(b))
        .unwrap_or(u64::MAX);
    if n > max as u64 {
        return Err(format!("holds {n} values, more than the {max} expected"));
    }
    numeric_type(dataset)?;
    let values = dataset
        .read_f64()
        .map_err(|e| format!("cannot read: {e}"))?;
    if values.len() as u64 != n {
        return Err(format!("gave {} values, expected {n}", values.len()));
    }
    Ok(values)
}

/// An attribute's values as numbers, if it is numeric.
pub(crate) fn numbers(value: &AttrValue) -> Option<Vec<f64>> {
    use AttrValue as A;
    Some(match value {
        A::F32(v) => vec![f64::from(*v)],
        A::F64(v) => vec![*v],
        A::I8(v) => vec![f64::from(*v)],
        A::I16(v) => vec![f64::from(*v)],
        A::I32(v) => vec![f64::from(*v)],
        A::I64(v) => vec![*v as f64],
        A::U8(v) => vec![f64::from(*v)],
        A::U16(v) => vec![f64::from(*v)],
        A::U32(v) => vec![f64::from(*v)],
        A::U64(v) => vec![*v as f64],
        A::F32Array(v) => v.iter().map(|&x| f64::from(x)).collect(),
        A::F64Array(v) => v.clone(),
        A::I8Array(v) => v.iter().map(|&x| f64::from(x)).collect(),
        A::I16Array(v) => v.iter().map(|&x| f64::from(x)).collect(),
        A::I32Array(v) => v.iter().map(|&x| f64::from(x)).collect(),
        A::I64Array(v) => v.iter().map(|&x| x as f64).collect(),
        A::U8Array(v) => v.iter().map(|&x| f64::from(x)).collect(),
        A::U16Array(v) => v.iter().map(|&x| f64::from(x)).collect(),
        A::U32Array(v) => v.iter().map(|&x| f64::from(x)).collect(),
        A::U64Array(v) => v.iter().map(|&x| x as f64).collect(),
        _ => return None,
    })
}

/// An attribute's text, trimmed, if it is one non-empty string.
pub(crate) fn text(value: &AttrValue) -> Option<String> {
    use AttrValue as A;
    let s = match value {
        A::String(s) | A::AsciiString(s) | A::VarLenString(s) => s.as_str(),
        A::StringSized { value, .. } | A::AsciiStringSized { value, .. } => value.as_str(),
        A::StringArray(v) | A::AsciiStringArray(v) | A::VarLenStringArray(v) if v.len() == 1 => {
            v[0].as_str()
        }
        _ => return None,
    };
    let s = s.trim_end_matches('\0').trim();
    (!s.is_empty()).then(|| s.to_string())
}

/// An attribute as `volray info` shows it: its text, or up to 16 of its
/// numbers.
pub(crate) fn shown(value: &AttrValue) -> String {
    if let Some(s) = text(value) {
        return s;
    }
    match numbers(value) {
        Some(v) if v.len() == 1 => v[0].to_string(),
        Some(v) => {
            let mut parts: Vec<String> = v.iter().take(16).map(|x| x.to_string()).collect();
            if v.len() > 16 {
                parts.push(format!("... ({} values)", v.len()));
            }
            format!("[{}]", parts.join(", "))
        }
        None => "(not shown)".into(),
    }
}

/// The attributes of an object, sorted by name (the library gives them
/// unordered); none if they cannot be read.
pub(crate) fn sorted_attrs(
    attrs: Result<std::collections::HashMap<String, AttrValue>, hdf5_pure::Error>,
) -> Vec<(String, AttrValue)> {
    let mut attrs: Vec<(String, AttrValue)> =
        attrs.map(|a| a.into_iter().collect()).unwrap_or_default();
    attrs.sort_by(|a, b| a.0.cmp(&b.0));
    attrs
}
