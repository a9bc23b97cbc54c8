//! An HDF5 dataset (and so a NetCDF-4 variable, which is one) as a source
//! of boxes ([`VolumeSource`]): opened from its metadata, and read box by
//! box, each box from the bytes of the file it covers and nothing else.
//! What an out-of-core render (volray-distributed's `streamed`) and each
//! rank of an MPI render read their pieces from; the eager reader
//! (`hdf5.rs`) reads a volume that fits `--max-memory` whole.
//!
//! How a box is read depends on the dataset's storage:
//! - **chunked**, its chunks enumerated from the chunk index (B-tree v1,
//!   fixed array, extensible array, implicit, single chunk, not a B-tree
//!   v2, which `hdf5-pure` 0.47 cannot read at all: `hdf5-pure`'s
//!   `Dataset::chunks`, which reads the index and no data), unfiltered or
//!   filtered by deflate and shuffle: each chunk the box touches is read
//!   from its file address, inflated (to exactly its decoded size, no
//!   more), unshuffled, and its part of the box copied out. Scratch: one
//!   chunk, stored and decoded.
//! - **contiguous**: each row of the dataset's last axis (z, without axis
//!   names) the box covers is read from the file at its offset (a row of
//!   the box's rows along the axis before it at once where that is not
//!   much more than the box needs).
//! - anything else (compact data, no data written, chunks missing from the
//!   index so that the fill value stands in for them, other filters: fletcher32,
//!   szip, lzf, scale-offset, n-bit; non-IEEE or bit-packed types):
//!   through `hdf5-pure`'s row windows (`read_f64_rows`), which decode only
//!   the chunks the rows of the box's range along the dataset's first axis
//!   touch: those rows, whole along the other axes, a window of at most
//!   about a million samples at a time (where the first axis is time or
//!   channel, the frame's one row, read whole).
//!
//! Values are those of the eager reader exactly: the sample as a `f64`
//! (as `hdf5-pure` decodes it), rounded to `f32`, kept in the volume's
//! type; each sample placed as the dataset's axis order says
//! (`hdf5_axes.rs`: named axes, or a[x, y, z] and a[t, x, y, z]), x
//! fastest. A box of the volume is a box of the dataset over its x, y and
//! z axes, one index wide along time and channel.
//!
//! Before anything is read, the shape is checked against the file's
//! length (no more than deflate's 1032:1 of it), each chunk's address and
//! stored size against the file's end, the decoded chunk against
//! `--max-memory`; before a box is read, the box and the scratch it takes
//! against `--max-memory`.

use std::collections::HashMap;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use hdf5_pure::{ChunkIndex, Datatype, DatatypeByteOrder, FloatingPointLayout, Layout};
use volray_core::sampling::grid::GridFrame;
use volray_core::{SampleType, Volume, VolumeSource, check_box};

use super::hdf5::{Found, Opened};
use super::hdf5_axes::{Placement, each_index};
use crate::dtype::{Stored, read_as_stored};
use crate::shared::compress::{Compression, inflate_exact};
use crate::shared::hdf5::{self as h5, check_stored, slab_rows, slab_samples};
use crate::shared::limits::{check_held, format_bytes};
use crate::{FileInfo, IoError, ReadOptions};

/// HDF5's registered filter numbers read here.
const FILTER_DEFLATE: u16 = 1;
const FILTER_SHUFFLE: u16 = 2;

/// Contiguous rows of z are read a y-span at a time when the span is at
/// most this many bytes more than the box's own rows: one read in place of
/// `ny` for a box that spans most of y and z.
const SPAN_SLACK: usize = 1 << 20;

/// A fixed-point or IEEE float sample of a standard layout: its size,
/// byte order, and how its bytes become a `f64`.
#[derive(Clone, Copy)]
struct Element {
    size: usize,
    value: fn(&[u8]) -> f64,
}

macro_rules! decoder {
    ($name:ident, $t:ty, $n:expr, $from:ident) => {
        fn $name(b: &[u8]) -> f64 {
            let mut a = [0u8; $n];
            a.copy_from_slice(&b[..$n]);
            <$t>::$from(a) as f64
        }
    };
}
decoder!(u16_le, u16, 2, from_le_bytes);
decoder!(u16_be, u16, 2, from_be_bytes);
decoder!(i16_le, i16, 2, from_le_bytes);
decoder!(i16_be, i16, 2, from_be_bytes);
decoder!(u32_le, u32, 4, from_le_bytes);
decoder!(u32_be, u32, 4, from_be_bytes);
decoder!(i32_le, i32, 4, from_le_bytes);
decoder!(i32_be, i32, 4, from_be_bytes);
decoder!(u64_le, u64, 8, from_le_bytes);
decoder!(u64_be, u64, 8, from_be_bytes);
decoder!(i64_le, i64, 8, from_le_bytes);
decoder!(i64_be, i64, 8, from_be_bytes);
decoder!(f32_le, f32, 4, from_le_bytes);
decoder!(f32_be, f32, 4, from_be_bytes);
decoder!(f64_le, f64, 8, from_le_bytes);
decoder!(f64_be, f64, 8, from_be_bytes);

fn u8_value(b: &[u8]) -> f64 {
    f64::from(b[0])
}

fn i8_value(b: &[u8]) -> f64 {
    f64::from(b[0] as i8)
}

impl Element {
    /// The element of `dt`, if it is a whole-byte integer or an IEEE
    /// binary32/binary64 float in little- or big-endian order.
    fn of(dt: &Datatype) -> Option<Element> {
        let big = |order: &DatatypeByteOrder| match order {
            DatatypeByteOrder::LittleEndian => Some(false),
            DatatypeByteOrder::BigEndian => Some(true),
            _ => None,
        };
        let value: fn(&[u8]) -> f64 = match dt {
            Datatype::FixedPoint {
                size,
                byte_order,
                layout,
            } if layout.bit_offset == 0 && u32::from(layout.bit_precision) == size * 8 => {
                match (*size, layout.signed, big(byte_order)?) {
                    (1, false, _) => u8_value,
                    (1, true, _) => i8_value,
                    (2, false, false) => u16_le,
                    (2, false, true) => u16_be,
                    (2, true, false) => i16_le,
                    (2, true, true) => i16_be,
                    (4, false, false) => u32_le,
                    (4, false, true) => u32_be,
                    (4, true, false) => i32_le,
                    (4, true, true) => i32_be,
                    (8, false, false) => u64_le,
                    (8, false, true) => u64_be,
                    (8, true, false) => i64_le,
                    (8, true, true) => i64_be,
                    _ => return None,
                }
            }
            Datatype::FloatingPoint {
                size,
                byte_order,
                layout,
            } => match (*size, big(byte_order)?) {
                (4, false) if *layout == FloatingPointLayout::IEEE754_BINARY32 => f32_le,
                (4, true) if *layout == FloatingPointLayout::IEEE754_BINARY32 => f32_be,
                (8, false) if *layout == FloatingPointLayout::IEEE754_BINARY64 => f64_le,
                (8, true) if *layout == FloatingPointLayout::IEEE754_BINARY64 => f64_be,
                _ => return None,
            },
            _ => return None,
        };
        let size = match dt {
            Datatype::FixedPoint { size, .. } | Datatype::FloatingPoint { size, .. } => {
                *size as usize
            }
            _ => return None,
        };
        Some(Element { size, value })
    }
}

/// One filter of a chunk pipeline this module decodes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Filter {
    Deflate,
    /// Bytes of each element regrouped by significance (HDF5's shuffle),
    /// elements of this many bytes.
    Shuffle(usize),
}

/// One chunk as the index gives it.
#[derive(Debug, Clone, Copy)]
struct StoredChunk {
    address: u64,
    size: u64,
    /// Bit `i` set: filter `i` of the pipeline was not applied.
    mask: u32,
}

/// The chunks of a chunked dataset, by their position on the chunk grid.
struct Chunks {
    shape: Vec<usize>,
    /// Bytes of one decoded chunk.
    bytes: usize,
    filters: Vec<Filter>,
    index: HashMap<Vec<usize>, StoredChunk>,
}

/// Where a box's samples come from.
enum Storage {
    Contiguous {
        address: u64,
    },
    Chunks(Box<Chunks>),
    /// Through `hdf5-pure`'s row windows, for the reason given.
    Rows {
        reason: String,
    },
}

/// One HDF5 dataset (one volume of a 4-D series) as a source of boxes.
pub(crate) struct H5Source {
    /// The HDF5 file, and the dataset's path in it.
    path: PathBuf,
    name: String,
    file: Mutex<File>,
    file_len: u64,
    /// The dataset's shape.
    shape: Vec<usize>,
    /// Which dataset axis is x, y, z, and the volume (frame) read.
    placement: Placement,
    element: Option<Element>,
    /// Bytes of one sample in the file.
    sample_size: usize,
    stored: SampleType,
    /// What each stored value becomes, where it is not itself.
    real: Option<RealValue>,
    grid: GridFrame,
    storage: Storage,
    max_memory: u64,
}

/// Opens the dataset `path` names as a source of boxes, with what the
/// eager reader would say of it; `None` for what the eager reader reads
/// otherwise (a MINC2 file, a 2-D image or a volume one sample thick).
pub(crate) fn open(
    path: &Path,
    opts: &ReadOptions,
) -> Result<Option<(H5Source, FileInfo)>, IoError> {
    let o = match super::hdf5::open(path, opts)? {
        Found::Minc(_) => return Ok(None),
        Found::Dataset(o) => *o,
    };
    if o.dims.iter().any(|&n| n < 2) {
        return Ok(None);
    }
    from_opened(o, None, opts).map(Some)
}

/// Maps a stored sample to the value kept (CF's `scale_factor`,
/// `add_offset` and fill values, for a NetCDF-4 variable).
pub(crate) type RealValue = Arc<dyn Fn(f64) -> f64 + Send + Sync>;

/// The source of boxes of a dataset opened and placed (`hdf5.rs`'s
/// [`Opened`], or a NetCDF-4 variable's, `netcdf4.rs`), each stored value
/// through `real` where given (the volume then kept as `f32`).
pub(crate) fn from_opened(
    o: Opened,
    real: Option<RealValue>,
    opts: &ReadOptions,
) -> Result<(H5Source, FileInfo), IoError> {
    let Opened {
        file_path,
        h5,
        name,
        dataset,
        sample,
        shape,
        placement,
        dims,
        mut info,
        spacing,
        origin,
        ..
    } = o;
    let fail =
        |reason: String| IoError::invalid(&file_path, format!("HDF5 dataset \"{name}\": {reason}"));
    check_stored(
        &file_path,
        &format!("dataset shape {shape:?}"),
        &shape,
        sample.size,
        h5.len,
    )?;
    if !(spacing.is_finite() && spacing.min_element() > 0.0) {
        let e = volray_core::VolumeError::BadSpacing(spacing.x, spacing.y, spacing.z);
        return Err(IoError::volume(&file_path, e));
    }
    if !origin.is_finite() {
        let e = volray_core::VolumeError::BadOrigin(origin.x, origin.y, origin.z);
        return Err(IoError::volume(&file_path, e));
    }
    let element = dataset.datatype().ok().as_ref().and_then(Element::of);
    let total = shape.iter().product::<usize>() as u64 * sample.size as u64;
    let layout = dataset
        .layout()
        .map_err(|e| fail(format!("unreadable layout: {e}")))?;
    let storage = match (element, layout) {
        (None, _) => Storage::Rows {
            reason: format!(
                "its type ({}) is not a whole-byte integer or IEEE float",
                sample.name
            ),
        },
        (
            Some(_),
            Layout::Contiguous {
                address: Some(address),
                size,
            },
        ) => {
            let end = address.checked_add(size).filter(|&e| e <= h5.len);
            if end.is_none() {
                return Err(fail(format!(
                    "its contiguous data at byte {address} ({size} bytes) lies past the end of the {}-byte file",
                    h5.len
                )));
            }
            if size < total {
                return Err(fail(format!(
                    "its contiguous data holds {size} bytes, but shape {shape:?} of {}-byte samples needs {total}",
                    sample.size
                )));
            }
            Storage::Contiguous { address }
        }
        (Some(_), Layout::Chunked { chunk_shape, index }) => chunked(
            &dataset,
            &shape,
            chunk_shape,
            index,
            sample.size,
            h5.len,
            opts.max_memory,
        )
        .map_err(fail)?,
        (Some(_), Layout::Contiguous { address: None, .. }) => Storage::Rows {
            reason: "no data is written (every sample is the fill value)".into(),
        },
        (Some(_), Layout::Compact { .. }) => Storage::Rows {
            reason: "its data is compact (held in its header)".into(),
        },
        (Some(_), other) => Storage::Rows {
            reason: format!("its layout is {other}"),
        },
    };
    info.notes.push(match &storage {
        Storage::Contiguous { .. } => {
            "read box by box: each row of the last axis a box covers, from its place in the contiguous data"
                .to_string()
        }
        Storage::Chunks(c) => format!(
            "read box by box: the chunks of shape {:?} a box touches, from the chunk index{}",
            c.shape,
            if c.filters.is_empty() {
                String::new()
            } else {
                let names: Vec<&str> = c
                    .filters
                    .iter()
                    .map(|f| match f {
                        Filter::Deflate => "deflate",
                        Filter::Shuffle(_) => "shuffle",
                    })
                    .collect();
                format!(" ({} decoded here)", names.join(", "))
            },
        ),
        Storage::Rows { reason } => format!(
            "read box by box through hdf5-pure's row windows, the rows of the first axis a box covers: {reason}"
        ),
    });
    let file = File::open(&file_path).map_err(|e| IoError::os(&file_path, "open", e))?;
    let stored = if real.is_some() {
        SampleType::F32
    } else {
        sample.stored
    };
    Ok((
        H5Source {
            path: file_path,
            name,
            file: Mutex::new(file),
            file_len: h5.len,
            shape,
            placement,
            element,
            sample_size: sample.size,
            stored,
            real,
            grid: GridFrame {
                dims,
                origin,
                spacing,
            },
            storage,
            max_memory: opts.max_memory,
        },
        info,
    ))
}

/// The chunks of a chunked dataset (see the module docs), or the row
/// windows where this module cannot decode them.
fn chunked(
    dataset: &hdf5_pure::Dataset,
    shape: &[usize],
    chunk_shape: Vec<u64>,
    index: ChunkIndex,
    sample_size: usize,
    file_len: u64,
    max_memory: u64,
) -> Result<Storage, String> {
    if chunk_shape.len() != shape.len() || chunk_shape.contains(&0) {
        return Err(format!(
            "chunk shape {chunk_shape:?} does not fit shape {shape:?}"
        ));
    }
    // A decoded chunk and its stored bytes are held at once; `hdf5-pure`
    // decodes whole chunks in the row windows too.
    let bytes = chunk_shape
        .iter()
        .try_fold(sample_size as u128, |a, &n| a.checked_mul(u128::from(n)))
        .unwrap_or(u128::MAX);
    if bytes.saturating_mul(2) > u128::from(max_memory) {
        return Err(format!(
            "one chunk of shape {chunk_shape:?} takes {}, which with its stored bytes exceeds the memory limit of {}",
            format_bytes(bytes),
            format_bytes(u128::from(max_memory))
        ));
    }
    let bytes = bytes as usize;
    let chunk: Vec<usize> = chunk_shape.iter().map(|&n| n as usize).collect();
    let mut filters = Vec::new();
    for f in dataset.filter_pipeline() {
        filters.push(match f.id {
            FILTER_DEFLATE => Filter::Deflate,
            FILTER_SHUFFLE => Filter::Shuffle(
                f.client_data
                    .first()
                    .map(|&n| n as usize)
                    .filter(|&n| n > 0)
                    .unwrap_or(sample_size),
            ),
            _ => {
                return Ok(Storage::Rows {
                    reason: format!("its chunks are filtered by {f}, which hdf5-pure decodes"),
                });
            }
        });
    }
    if index == ChunkIndex::BTreeV2 {
        // Nor does it read one whole or by rows: the eager reader refuses
        // it too ("a version 2 B-tree chunk index cannot be enumerated").
        return Err(
            "its chunks are indexed by a version 2 B-tree (several unlimited dimensions), which hdf5-pure 0.47 cannot read: rewrite it with fixed dimensions (h5repack -l CHUNK=...)"
                .into(),
        );
    }
    let listed = dataset
        .chunks()
        .map_err(|e| format!("unreadable chunk index: {e}"))?;
    let grid: Vec<usize> = shape
        .iter()
        .zip(&chunk)
        .map(|(&n, &c)| n.div_ceil(c))
        .collect();
    let expected = grid
        .iter()
        .try_fold(1usize, |a, &n| a.checked_mul(n))
        .unwrap_or(usize::MAX);
    let mut index = HashMap::with_capacity(listed.len().min(expected));
    for c in listed {
        let on_grid = c.offset.len() == shape.len()
            && c.offset
                .iter()
                .zip(&chunk)
                .zip(shape)
                .all(|((&o, &k), &n)| o % k as u64 == 0 && o < n as u64);
        if !on_grid {
            return Err(format!(
                "the chunk index lists a chunk at offset {:?}, not on the {chunk:?} chunk grid of shape {shape:?}",
                c.offset
            ));
        }
        let end = c.address.checked_add(c.storage_size);
        if end.is_none_or(|e| e > file_len) || c.storage_size == 0 {
            return Err(format!(
                "the chunk at offset {:?} is stored at byte {} ({} bytes), past the end of the {file_len}-byte file",
                c.offset, c.address, c.storage_size
            ));
        }
        // Deflate can grow incompressible data by a few bytes per 16 KiB
        // block; twice the chunk is far beyond that.
        if c.storage_size > 2 * bytes as u64 + 4096 {
            return Err(format!(
                "the chunk at offset {:?} is stored in {} bytes, more than a chunk of {bytes} bytes can take",
                c.offset, c.storage_size
            ));
        }
        let at: Vec<usize> = c
            .offset
            .iter()
            .zip(&chunk)
            .map(|(&o, &k)| o as usize / k)
            .collect();
        let old = index.insert(
            at,
            StoredChunk {
                address: c.address,
                size: c.storage_size,
                mask: c.filter_mask,
            },
        );
        if old.is_some() {
            return Err(format!(
                "the chunk index lists the chunk at offset {:?} twice",
                c.offset
            ));
        }
    }
    if index.len() < expected {
        return Ok(Storage::Rows {
            reason: format!(
                "{} of its {expected} chunks are written, the rest hold the fill value",
                index.len()
            ),
        });
    }
    Ok(Storage::Chunks(Box::new(Chunks {
        shape: chunk,
        bytes,
        filters,
        index,
    })))
}

impl H5Source {
    fn fail(&self, reason: String) -> IoError {
        IoError::invalid(
            &self.path,
            format!("HDF5 dataset \"{}\": {reason}", self.name),
        )
    }

    /// Bytes held beside the box while it is read.
    fn scratch(&self) -> u128 {
        let n = self.shape.len();
        match &self.storage {
            Storage::Contiguous { .. } => {
                (self.shape[n - 2] * self.shape[n - 1] * self.sample_size) as u128
            }
            Storage::Chunks(c) => 2 * c.bytes as u128 + 4096,
            Storage::Rows { .. } => {
                let row = self.shape[1..].iter().product::<usize>() as u128;
                let rows = if self.placement.first_fixed().is_some() {
                    1
                } else {
                    slab_rows(row as usize, 1, slab_samples()) as u128
                };
                rows * row * (8 + self.sample_size as u128)
            }
        }
    }

    /// The box `lo..hi` (x, y, z).
    fn read(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, IoError> {
        let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let voxels = dims.iter().product::<usize>();
        let peak = voxels as u128 * self.stored.bytes() as u128 + self.scratch();
        check_held(
            &self.path,
            &format!("box {lo:?}..{hi:?} of HDF5 dataset \"{}\"", self.name),
            voxels as u128,
            peak,
            &format!(
                "{} as {} and the scratch to read it",
                format_bytes(peak),
                self.stored.name()
            ),
            self.max_memory,
        )?;
        let samples = read_as_stored!(self.stored, |T| self.samples::<T>(lo, hi))?;
        let origin = self.grid.origin
            + volray_core::glam::DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64)
                * self.grid.spacing;
        Volume::from_samples(dims, samples)
            .and_then(|v| v.with_spacing(self.grid.spacing))
            .and_then(|v| v.with_origin(origin))
            .map_err(|e| IoError::volume(&self.path, e))
    }

    /// The box's samples, x fastest.
    fn samples<T: Stored>(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Vec<T>, IoError> {
        let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let mut out = vec![T::default(); dims.iter().product()];
        let (dlo, dhi) = self.placement.dataset_box(lo, hi);
        let w = Window {
            strides: self.placement.strides(dims),
            lo: dlo,
            hi: dhi,
        };
        // The value as the eager reader keeps it, at its place in the box.
        let real = self.real.as_deref();
        let mut put = |at: usize, v: f64| {
            let v = real.map_or(v, |f| f(v));
            out[at] = T::from_f64(f64::from(v as f32));
        };
        match (&self.storage, self.element) {
            (Storage::Contiguous { address }, Some(e)) => {
                self.contiguous(*address, e, &w, &mut put)?
            }
            (Storage::Chunks(c), Some(e)) => self.chunks(c, e, &w, &mut put)?,
            _ => self.rows(&w, &mut put)?,
        }
        Ok(out)
    }

    /// Reads `buf.len()` bytes at `offset` of the file.
    fn read_at(&self, offset: u64, buf: &mut [u8]) -> Result<(), IoError> {
        let end = offset.saturating_add(buf.len() as u64);
        if end > self.file_len {
            return Err(self.fail(format!(
                "bytes {offset}..{end} lie past the end of the {}-byte file",
                self.file_len
            )));
        }
        let mut file = self.file.lock().unwrap_or_else(|p| p.into_inner());
        file.seek(SeekFrom::Start(offset))
            .map_err(|e| IoError::os(&self.path, "seek in", e))?;
        file.read_exact(buf).map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                self.fail(format!(
                    "bytes {offset}..{end} could not be read: the file is shorter than it was"
                ))
            } else {
                IoError::os(&self.path, "read", e)
            }
        })
    }

    fn contiguous(
        &self,
        address: u64,
        e: Element,
        w: &Window,
        put: &mut impl FnMut(usize, f64),
    ) -> Result<(), IoError> {
        let n = self.shape.len();
        let (a1, a2) = (n - 2, n - 1);
        let ds = c_strides(&self.shape);
        let s = e.size;
        let (ny, nz) = (w.hi[a1] - w.lo[a1], w.hi[a2] - w.lo[a2]);
        // From (.., lo, lo) to (.., hi - 1, hi - 1) of the last two axes:
        // one read per index of the others.
        let span = ((ny - 1) * self.shape[a2] + nz) * s;
        let whole_span = span <= ny * nz * s + SPAN_SLACK;
        let mut buf = vec![0u8; if whole_span { span } else { nz * s }];
        each_index(&w.lo[..a1], &w.hi[..a1], |outer| {
            let flat: usize = outer.iter().zip(&ds).map(|(&i, &d)| i * d).sum();
            let first = |y: usize| address + ((flat + y * ds[a1] + w.lo[a2]) * s) as u64;
            let at_outer: usize = (0..a1).map(|a| (outer[a] - w.lo[a]) * w.strides[a]).sum();
            if whole_span {
                self.read_at(first(w.lo[a1]), &mut buf)?;
            }
            for y in w.lo[a1]..w.hi[a1] {
                let line = if whole_span {
                    &buf[(y - w.lo[a1]) * self.shape[a2] * s..][..nz * s]
                } else {
                    self.read_at(first(y), &mut buf)?;
                    &buf[..]
                };
                let mut at = at_outer + (y - w.lo[a1]) * w.strides[a1];
                for b in line.chunks_exact(s) {
                    put(at, (e.value)(b));
                    at += w.strides[a2];
                }
            }
            Ok(())
        })
    }

    fn chunks(
        &self,
        c: &Chunks,
        e: Element,
        w: &Window,
        put: &mut impl FnMut(usize, f64),
    ) -> Result<(), IoError> {
        let n = self.shape.len();
        let last = n - 1;
        let k = &c.shape;
        // The chunk's own C-order strides, in samples.
        let cs = c_strides(k);
        let grid_lo: Vec<usize> = (0..n).map(|a| w.lo[a] / k[a]).collect();
        let grid_hi: Vec<usize> = (0..n).map(|a| (w.hi[a] - 1) / k[a] + 1).collect();
        let mut stored = Vec::new();
        each_index(&grid_lo, &grid_hi, |at| {
            let Some(chunk) = c.index.get(at) else {
                return Err(self.fail(format!(
                    "the chunk at {at:?} on the chunk grid is missing from its index"
                )));
            };
            let data = self.decode(c, chunk, at, &mut stored)?;
            let origin: Vec<usize> = (0..n).map(|a| at[a] * k[a]).collect();
            let from: Vec<usize> = (0..n).map(|a| w.lo[a].max(origin[a])).collect();
            let to: Vec<usize> = (0..n).map(|a| w.hi[a].min(origin[a] + k[a])).collect();
            each_index(&from[..last], &to[..last], |idx| {
                let row: usize = (0..last).map(|a| (idx[a] - origin[a]) * cs[a]).sum();
                let first = (row + from[last] - origin[last]) * e.size;
                let end = (row + to[last] - origin[last]) * e.size;
                let mut put_at: usize = (0..last)
                    .map(|a| (idx[a] - w.lo[a]) * w.strides[a])
                    .sum::<usize>()
                    + (from[last] - w.lo[last]) * w.strides[last];
                for b in data[first..end].chunks_exact(e.size) {
                    put(put_at, (e.value)(b));
                    put_at += w.strides[last];
                }
                Ok(())
            })
        })
    }

    /// Reads and decodes one chunk: its stored bytes into `stored`, the
    /// decoded chunk returned (exactly [`Chunks::bytes`] long).
    fn decode(
        &self,
        c: &Chunks,
        chunk: &StoredChunk,
        at: &[usize],
        stored: &mut Vec<u8>,
    ) -> Result<Vec<u8>, IoError> {
        let offset: Vec<usize> = at.iter().zip(&c.shape).map(|(&i, &k)| i * k).collect();
        stored.resize(chunk.size as usize, 0);
        self.read_at(chunk.address, stored)?;
        let mut data: Option<Vec<u8>> = None;
        for (i, f) in c.filters.iter().enumerate().rev() {
            if i < 32 && chunk.mask & (1 << i) != 0 {
                continue;
            }
            let input = data.as_deref().unwrap_or(stored);
            data = Some(match *f {
                Filter::Deflate => inflate_exact(
                    &self.path,
                    input,
                    Compression::Zlib,
                    c.bytes,
                    &format!(
                        "HDF5 dataset \"{}\": deflated chunk at offset {offset:?}",
                        self.name
                    ),
                )?,
                Filter::Shuffle(size) => unshuffle(input, size),
            });
        }
        let data = data.unwrap_or_else(|| std::mem::take(stored));
        if data.len() != c.bytes {
            return Err(self.fail(format!(
                "the chunk at offset {offset:?} holds {} bytes, but a chunk of shape {:?} is {}",
                data.len(),
                c.shape,
                c.bytes
            )));
        }
        Ok(data)
    }

    /// Through `hdf5-pure`'s row windows (see the module docs).
    fn rows(&self, w: &Window, put: &mut impl FnMut(usize, f64)) -> Result<(), IoError> {
        let n = self.shape.len();
        let last = n - 1;
        let ds = c_strides(&self.shape);
        let row = ds[0];
        let h5 = h5::open(&self.path)?;
        let dataset = h5
            .file
            .dataset(&self.name)
            .map_err(|e| self.fail(format!("cannot open: {e}")))?;
        let read = |first: usize, count: usize| -> Result<Vec<f64>, IoError> {
            let values = dataset
                .read_f64_rows(first as u64, count as u64)
                .map_err(|e| self.fail(format!("cannot read: {e}")))?;
            if values.len() != count * row {
                return Err(self.fail(format!(
                    "cannot read: rows {first}..{} gave {} values, expected {}",
                    first + count,
                    values.len(),
                    count * row
                )));
            }
            Ok(values)
        };
        let window = slab_rows(row, 1, slab_samples());
        let mut first = w.lo[0];
        while first < w.hi[0] {
            let end = (first + window).min(w.hi[0]);
            let values = read(first, end - first)?;
            let (mut lo, mut hi) = (w.lo.clone(), w.hi.clone());
            (lo[0], hi[0]) = (first, end);
            each_index(&lo[..last], &hi[..last], |idx| {
                let at: usize = (0..last).map(|a| idx[a] * ds[a]).sum::<usize>() - first * ds[0];
                let mut put_at: usize = (0..last).map(|a| (idx[a] - w.lo[a]) * w.strides[a]).sum();
                for &v in &values[at + w.lo[last]..at + w.hi[last]] {
                    put(put_at, v);
                    put_at += w.strides[last];
                }
                Ok::<(), IoError>(())
            })?;
            first = end;
        }
        Ok(())
    }
}

/// A box of the dataset (per axis `lo..hi`), and the strides, per
/// dataset axis, at which its samples go into the volume's box (x
/// fastest; 0 along time and channel).
struct Window {
    lo: Vec<usize>,
    hi: Vec<usize>,
    strides: Vec<usize>,
}

/// The C-order strides, in samples, of an array of `shape`.
fn c_strides(shape: &[usize]) -> Vec<usize> {
    let mut stride = vec![1usize; shape.len()];
    for a in (0..shape.len().saturating_sub(1)).rev() {
        stride[a] = stride[a + 1] * shape[a + 1];
    }
    stride
}

/// Undoes HDF5's shuffle filter: the first bytes of every element, then
/// the second bytes, and so on, back to whole elements; bytes past the
/// last whole element stay where they are (as H5Zshuffle leaves them).
fn unshuffle(data: &[u8], size: usize) -> Vec<u8> {
    if size <= 1 {
        return data.to_vec();
    }
    let count = data.len() / size;
    let mut out = data.to_vec();
    for b in 0..size {
        let plane = &data[b * count..(b + 1) * count];
        for (i, &v) in plane.iter().enumerate() {
            out[i * size + b] = v;
        }
    }
    out
}

impl VolumeSource for H5Source {
    fn grid(&self) -> GridFrame {
        self.grid
    }

    fn sample_type(&self) -> SampleType {
        self.stored
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
        check_box(self.grid.dims, lo, hi).map_err(|e| format!("{}: {e}", self.path.display()))?;
        self.read(lo, hi).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unshuffle_regroups_the_bytes_of_each_element_and_keeps_the_tail() {
        // Elements 0x0201, 0x0403, 0x0605 (little-endian) shuffled: low
        // bytes 01 03 05, then high bytes 02 04 06; a tail byte 07.
        let shuffled = [1, 3, 5, 2, 4, 6, 7];
        assert_eq!(unshuffle(&shuffled, 2), vec![1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(unshuffle(&shuffled, 1), shuffled.to_vec());
    }
}
