//! HDF5 files through `hdf5-pure` (pure Rust: no C library, no build
//! step): opening a file, reading attributes as numbers or text, and
//! reading a numeric dataset's rows into `f64`s after checking its size
//! against the file's length and the memory limit, refusing by name the
//! filters nothing here decodes (szip). Used by the HDF5 dataset reader,
//! the NetCDF-4 reader and the MINC2 reader.

use std::path::Path;

use hdf5_pure::{AttrValue, DType as H5Type, Dataset, DatatypeByteOrder, File, ReadSeekSource};

use volray_core::SampleType;

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

#[cfg(test)]
thread_local! {
    /// The tests' slab size in samples (the fixtures hold 60 samples, a
    /// sliver of one slab of [`SLAB_SAMPLES`]), and the slabs read since
    /// it was set: see `tests::in_slabs_of`.
    static TEST_SLABS: std::cell::Cell<(usize, usize)> =
        const { std::cell::Cell::new((SLAB_SAMPLES, 0)) };
}

/// Samples read per slab: [`SLAB_SAMPLES`], or what a test set.
pub(crate) fn slab_samples() -> usize {
    #[cfg(test)]
    return TEST_SLABS.with(|t| t.get().0);
    #[cfg(not(test))]
    SLAB_SAMPLES
}

/// Counts a slab read, for the tests.
fn slab_read() {
    #[cfg(test)]
    TEST_SLABS.with(|t| t.set((t.get().0, t.get().1 + 1)));
}

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
    /// The type a volume keeps: 8- and 16-bit integers as they are, the
    /// rest as `f32`.
    pub stored: SampleType,
}

/// The numeric type of `dataset`, or why it has none (`"type string is
/// not numeric: ..."`).
pub(crate) fn numeric_type(dataset: &Dataset) -> Result<NumericType, String> {
    let kind = dataset
        .dtype()
        .map_err(|e| format!("unreadable type: {e}"))?;
    let (size, name, stored) = match kind {
        H5Type::I8 => (1, "int8", SampleType::I8),
        H5Type::U8 => (1, "uint8", SampleType::U8),
        H5Type::I16 => (2, "int16", SampleType::I16),
        H5Type::U16 => (2, "uint16", SampleType::U16),
        H5Type::I32 => (4, "int32", SampleType::F32),
        H5Type::U32 => (4, "uint32", SampleType::F32),
        H5Type::F32 => (4, "float32", SampleType::F32),
        H5Type::I64 => (8, "int64", SampleType::F32),
        H5Type::U64 => (8, "uint64", SampleType::F32),
        H5Type::F64 => (8, "float64", SampleType::F32),
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
        stored,
    })
}

/// HDF5's filter number for szip (H5Zpublic.h's `H5Z_FILTER_SZIP`).
const FILTER_SZIP: u16 = 4;

/// Refuses, by name, a dataset whose chunks no reader here can decode:
/// szip-compressed ones (libaec's szip has no pure-Rust decoder, and
/// `hdf5-pure` reads none), with the command that rewrites them.
pub(crate) fn check_filters(dataset: &Dataset) -> Result<(), String> {
    if dataset.filters().contains(&FILTER_SZIP) {
        return Err(
            "its chunks are szip-compressed (filter 4), which volray cannot decode (no pure-Rust szip decoder): rewrite the file without it, e.g. h5repack -f NONE in.h5 out.h5 (or -f GZIP=4)"
                .into(),
        );
    }
    Ok(())
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
/// chunks adding up to about `slab` samples ([`SLAB_SAMPLES`]), or,
/// where one chunk is larger than that, as many rows as fit `slab` (at
/// least one), so that a header's chunk size cannot make the scratch
/// buffer large.
pub(crate) fn slab_rows(row: usize, chunk0: usize, slab: usize) -> usize {
    let row = row.max(1);
    let chunk0 = chunk0.max(1);
    if row.saturating_mul(chunk0) <= slab {
        (slab / row / chunk0).max(1) * chunk0
    } else {
        (slab / row).max(1)
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

/// Checks that a dataset of `shape` and samples of `sample_size` bytes
/// could come out of a file of `file_len` bytes: at most
/// [`MAX_INFLATION`] times its length, or [`SMALL_FILE_ALLOWANCE`]
/// (deflate inflates at most about 1032:1). Returns its samples. `what`
/// names the shape for messages.
pub(crate) fn check_stored(
    path: &Path,
    what: &str,
    shape: &[usize],
    sample_size: usize,
    file_len: u64,
) -> Result<usize, IoError> {
    let dims64: Vec<u64> = shape.iter().map(|&n| n as u64).collect();
    let values = count_values(path, what, &dims64)?;
    let budget = file_len
        .saturating_mul(MAX_INFLATION)
        .max(SMALL_FILE_ALLOWANCE);
    let bytes = (values as u64).saturating_mul(sample_size as u64);
    if bytes > budget {
        return Err(IoError::invalid(
            path,
            format!(
                "{what} of {sample_size}-byte samples is {bytes} bytes, more than a {file_len}-byte file can hold even compressed"
            ),
        ));
    }
    Ok(values)
}

/// How one volume of a dataset is read: in slabs of rows of its first
/// axis (whole chunks at a time), or, where the first axis is not one of
/// the volume's (a series `a[t, ...]`, `frame` chosen), as its one row of
/// the first axis, whole.
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
    /// The reading of a dataset of `shape` holding `frames` volumes, and
    /// samples of `sample_size` bytes: row `frame` of the first axis, or
    /// (`None`) all its rows.
    pub(crate) fn new(
        dataset: &'d Dataset,
        shape: &'d [usize],
        frames: usize,
        frame: Option<usize>,
        sample_size: usize,
    ) -> Self {
        let rows = shape.first().copied().unwrap_or(1);
        let row = shape
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
            slab: slab_rows(row, chunk_along(dataset, 0), slab_samples()),
        }
    }

    /// Checks that the dataset could come out of a file of `file_len`
    /// bytes (at most [`MAX_INFLATION`] times its length, or
    /// [`SMALL_FILE_ALLOWANCE`]), and that one volume of it as `kept`,
    /// beside the samples held at once (stored and as f64), fits
    /// `max_memory`. Returns the samples of one volume. `what` names the
    /// shape for messages.
    pub(crate) fn check(
        &self,
        path: &Path,
        what: &str,
        file_len: u64,
        kept: SampleType,
        max_memory: u64,
    ) -> Result<usize, IoError> {
        let sample_size = self.sample_size;
        let values = check_stored(path, what, self.shape, sample_size, file_len)?;
        let volume = values / self.frames.max(1);
        let peak = volume as u128 * kept.bytes() as u128
            + self.scratch() as u128 * (8 + sample_size as u128);
        check_held(
            path,
            what,
            volume as u128,
            peak,
            &format!("{} as {} and an f64 slab", format_bytes(peak), kept.name()),
            max_memory,
        )?;
        Ok(volume)
    }

    /// The samples held at once.
    pub(crate) fn scratch(&self) -> usize {
        match self.frame {
            Some(_) => self.row,
            None => self.row.saturating_mul(self.slab.min(self.rows)),
        }
    }

    /// Reads the volume, handing each slab to `take` with the C-order
    /// index of its first sample among those read (from the first row
    /// read: row `frame`, or row 0).
    pub(crate) fn read(&self, mut take: impl FnMut(usize, &[f64])) -> Result<(), String> {
        if let Some(frame) = self.frame {
            take(0, &self.rows_of(frame, 1, self.row)?);
            return Ok(());
        }
        let mut first = 0;
        while first < self.rows {
            let end = (first + self.slab).min(self.rows);
            slab_read();
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

#[cfg(test)]
mod tests {
    //! The readers' slabs: the fixtures (shape (4, 3, 5), 60 samples)
    //! read with the slab shrunk to a row or a few, so that a volume spans
    //! several slabs, every value checked against the fixture's content
    //! (the scripts `tests/fixtures/make_hdf5_fixtures.py` and
    //! `make_minc_fixtures.py`), so that a slab placed at the wrong offset
    //! fails.

    use super::*;
    use crate::{ReadOptions, read};
    use volray_core::Volume;

    /// Reads `file` (under `tests/fixtures/`) with slabs of at most
    /// `samples` samples (`--frame frame`), giving the volume and the
    /// slabs read.
    fn in_slabs_of(samples: usize, file: &str, frame: Option<usize>) -> (Volume, usize) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures")
            .join(file);
        let opts = ReadOptions {
            frame,
            ..ReadOptions::default()
        };
        TEST_SLABS.with(|t| t.set((samples, 0)));
        let loaded = read(&path, &opts);
        let slabs = TEST_SLABS.with(|t| t.replace((SLAB_SAMPLES, 0)).1);
        let loaded = loaded.unwrap_or_else(|e| panic!("{file}: {e}"));
        (loaded.volume, slabs)
    }

    /// Every voxel of `volume` (dims `dims`) is `want(x, y, z)` within a
    /// relative `tolerance`.
    fn check(
        what: &str,
        volume: &Volume,
        dims: [usize; 3],
        tolerance: f64,
        want: impl Fn(usize, usize, usize) -> f64,
    ) {
        assert_eq!(volume.dims(), dims, "{what}");
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let (got, want) = (f64::from(volume.get(x, y, z)), want(x, y, z));
                    assert!(
                        (got - want).abs() <= tolerance * want.abs().max(1.0),
                        "{what}: ({x}, {y}, {z}) is {got}, not {want}"
                    );
                }
            }
        }
    }

    /// Slab sizes in samples, and the slabs a volume of 4 rows of 15
    /// samples takes, contiguous and in chunks of 2 rows: one row at a
    /// time (however small the slab, at least a row; a chunk split), 2
    /// rows (a whole chunk), 3 rows (the last slab short; a chunk), and
    /// the default, one slab for all.
    const SLABS: [(usize, usize, usize); 5] = [
        (1, 4, 4),
        (15, 4, 4),
        (30, 2, 2),
        (45, 2, 2),
        (SLAB_SAMPLES, 1, 1),
    ];

    #[test]
    fn hdf5_volumes_read_in_several_slabs_hold_every_value_in_its_place() {
        // v = x + 10y + 100z at a[x, y, z], dims (4, 3, 5).
        let v = |x: usize, y: usize, z: usize| (x + 10 * y + 100 * z) as f64;
        for (samples, contiguous, chunked) in SLABS {
            let (volume, slabs) = in_slabs_of(samples, "hdf5/one.h5", None);
            check("density", &volume, [4, 3, 5], 0.0, |x, y, z| {
                v(x, y, z) + 0.5
            });
            assert_eq!(slabs, contiguous, "one.h5 in slabs of {samples}");
            let (volume, slabs) = in_slabs_of(samples, "hdf5/many.h5:/u8", None);
            check("u8", &volume, [4, 3, 5], 0.0, |x, y, z| {
                (x + 2 * y + 6 * z) as f64
            });
            assert_eq!(slabs, contiguous, "u8 in slabs of {samples}");
            let (volume, _) = in_slabs_of(samples, "hdf5/many.h5:/i16_be", None);
            check("i16_be", &volume, [4, 3, 5], 0.0, |x, y, z| -v(x, y, z));
            let (volume, _) = in_slabs_of(samples, "hdf5/many.h5:/i64", None);
            check("i64", &volume, [4, 3, 5], 0.0, |x, y, z| {
                f64::from((v(x, y, z) - 2f64.powi(40)) as f32)
            });
            let (volume, slabs) = in_slabs_of(samples, "hdf5/many.h5:/gzip_u16", None);
            check("gzip_u16", &volume, [4, 3, 5], 0.0, v);
            assert_eq!(slabs, chunked, "gzip_u16 in slabs of {samples}");
            // A volume of a series is read whole, whatever the slab.
            let (volume, slabs) = in_slabs_of(samples, "hdf5/many.h5:/series", Some(2));
            check("series", &volume, [4, 3, 5], 0.0, |x, y, z| {
                v(x, y, z) + 2000.0
            });
            assert_eq!(slabs, 0, "series");
        }
    }

    #[test]
    fn minc2_volumes_read_in_several_slabs_keep_each_slice_scaling() {
        // ramp_i16.mnc: file index (z, y, x) of shape (3, 4, 5) holds
        // x + 10y + 100z, scaled per z slice from [0, 1000] to
        // [-1 - z, 100 + 10z]; y is flipped (step -2), so volume row y is
        // file row 3 - y.
        let real = |x: usize, y: usize, z: usize| {
            let raw = (x + 10 * (3 - y) + 100 * z) as f64;
            let (lo, hi) = (-1.0 - z as f64, 100.0 + 10.0 * z as f64);
            f64::from((raw * (hi - lo) / 1000.0 + lo) as f32)
        };
        // oblique_f32.mnc: shape (4, 3, 5), unscaled x + 10z + 100y + 0.5
        // at file index (y, z, x).
        let oblique = |x: usize, z: usize, y: usize| (x + 10 * z + 100 * y) as f64 + 0.5;
        // 3 rows of 20 samples (ramp) and 4 of 15 (oblique).
        for (samples, ramp_slabs, oblique_slabs) in
            [(1, 3, 4), (20, 3, 4), (40, 2, 2), (SLAB_SAMPLES, 1, 1)]
        {
            let (volume, slabs) = in_slabs_of(samples, "minc/ramp_i16.mnc", None);
            check("ramp_i16", &volume, [5, 4, 3], 1e-6, real);
            assert_eq!(slabs, ramp_slabs, "ramp_i16 in slabs of {samples}");
            let (volume, slabs) = in_slabs_of(samples, "minc/oblique_f32.mnc", None);
            check("oblique_f32", &volume, [5, 3, 4], 0.0, oblique);
            assert_eq!(slabs, oblique_slabs, "oblique_f32 in slabs of {samples}");
        }
    }
}
