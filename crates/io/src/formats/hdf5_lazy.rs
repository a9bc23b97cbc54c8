//! An HDF5 dataset (and so a NetCDF-4 variable, which is one) as a source
//! of boxes ([`VolumeSource`]): opened from its metadata, and read box by
//! box, each box from the bytes of the file it covers and nothing else.
//! What an out-of-core render (volray-distributed's `streamed`) and each
//! rank of an MPI render read their pieces from; the eager reader
//! (`hdf5.rs`) reads a volume that fits `--max-memory` whole.
//!
//! How a box is read depends on the dataset's storage:
//! - **chunked**, its chunks enumerated from the chunk index (B-tree v1,
//!   fixed array, extensible array, implicit, single chunk by `hdf5-pure`;
//!   a version 2 B-tree, and any index under a layout message of version
//!   5 (HDF5 2.0), which `hdf5-pure` 0.47 cannot read, by `hdf5-reader`:
//!   `shared/hdf5_index.rs`, the eager reader then reading the whole
//!   volume as one box here), unfiltered or
//!   filtered by deflate, shuffle, Fletcher-32 (checked) and LZF
//!   (`hdf5_lazy/chunks.rs`): each chunk the box touches is read from its
//!   file address, decoded (to exactly its decoded size, no more), and its
//!   part of the box copied out; a chunk never written (missing from the
//!   index) gives the dataset's fill value. Along a time or channel axis a
//!   box touches the chunks of its own frame only. Scratch: one chunk,
//!   stored and decoded.
//! - **contiguous**: each row of the dataset's last axis (z, without axis
//!   names) the box covers is read from the file at its offset (a row of
//!   the box's rows along the axis before it at once where that is not
//!   much more than the box needs).
//! - **no data written**: every sample is the fill value.
//! - anything else (compact data, other filters: scale-offset, n-bit;
//!   non-IEEE or bit-packed types): through `hdf5-pure`'s row windows
//!   (`read_f64_rows`, the dataset opened once), which decode only the
//!   chunks the rows of the box's range along the dataset's first axis
//!   touch: those rows, whole along the other axes, a window of at most
//!   about a million samples at a time (where the first axis is time or
//!   channel, the frame's one row, read whole).
//!
//! Values are those of the eager reader exactly: the sample as a `f64`
//! (as `hdf5-pure` decodes it, `hdf5_lazy/element.rs`), rounded to `f32`,
//! kept in the volume's type; each sample placed as the dataset's axis
//! order says (`hdf5_axes.rs`: named axes, or a[x, y, z] and a[t, x, y,
//! z]), x fastest. A box of the volume is a box of the dataset over its x,
//! y and z axes, one index wide along time and channel. An axis whose
//! coordinate decreases (a NetCDF-4 latitude from north to south) runs
//! backwards in the file: the box is read from the mirrored range and
//! flipped, as the eager reader flips the whole volume.
//!
//! Before anything is read, the shape is checked against the file's
//! length (no more than deflate's 1032:1 of it), each chunk's address and
//! stored size against the file's end, the decoded chunk against
//! `--max-memory`; before a box is read, the box and the scratch it takes
//! against `--max-memory`.

mod chunks;
mod element;

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use hdf5_pure::{ChunkIndex, Dataset, Layout};
use volray_core::sampling::grid::GridFrame;
use volray_core::{SampleType, SourceError, Volume, VolumeSource, check_box};

use super::hdf5_axes::{Opened, Placement, each_index};
use crate::dtype::{Stored, read_as_stored};
use crate::shared::hdf5::{self as h5, check_stored, slab_rows, slab_samples};
use crate::shared::hdf5_index::{self, Listed, REPACK};
use crate::shared::limits::{check_held, format_bytes};
use crate::{FileInfo, IoError, ReadOptions};
use chunks::{Chunks, Indexed, StoredChunk};
use element::Element;

/// Contiguous rows of z are read a y-span at a time when the span is at
/// most this many bytes more than the box's own rows: one read in place of
/// `ny` for a box that spans most of y and z.
const SPAN_SLACK: usize = 1 << 20;

/// Where a box's samples come from.
enum Storage {
    Contiguous {
        address: u64,
    },
    Chunks(Box<Chunks>),
    /// No data written: every sample is this (the fill value).
    Fill(f64),
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
    /// The volume's axes (x, y, z) that run backwards in the file.
    flip: [bool; 3],
    storage: Storage,
    /// The file as `hdf5-pure` opened it for the row windows, once.
    rows: Mutex<Option<Arc<h5::H5File>>>,
    max_memory: u64,
}

/// Maps a stored sample to the value kept (CF's `scale_factor`,
/// `add_offset` and fill values, for a NetCDF-4 variable).
pub(crate) type RealValue = Arc<dyn Fn(f64) -> f64 + Send + Sync>;

/// The source of boxes of a dataset opened and placed (`hdf5.rs`'s
/// [`Opened`], or a NetCDF-4 variable's, `netcdf4.rs`), each stored value
/// through `real` where given (the volume then kept as `f32`), the
/// volume's axes `flip` says run backwards in the file (the grid's origin
/// `o.origin` that of the volume flipped, as the eager reader places it).
pub(crate) fn from_opened(
    o: Opened,
    real: Option<RealValue>,
    flip: [bool; 3],
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
    // What hdf5-pure cannot read (a layout message of version 5, a version
    // 2 B-tree chunk index) is indexed through hdf5-reader instead.
    let layout = match dataset.layout() {
        Ok(Layout::Chunked {
            index: ChunkIndex::BTreeV2,
            ..
        }) => Err("hdf5-pure 0.47 cannot read a version 2 B-tree chunk index".to_string()),
        Ok(layout) => Ok(layout),
        Err(e) => Err(
            match e.to_string().split("invalid data layout version: ").nth(1) {
                Some(v) => format!(
                    "its layout message is of version {v} (HDF5 2.0), which hdf5-pure 0.47 cannot read"
                ),
                None => format!("hdf5-pure 0.47 cannot read its layout message ({e})"),
            },
        ),
    };
    let storage = match (element, layout) {
        (_, Err(why)) => {
            let (storage, note) = beyond_hdf5_pure(
                &file_path,
                &name,
                &dataset,
                element,
                &shape,
                sample.size,
                h5.len,
                opts.max_memory,
                &why,
            )
            .map_err(fail)?;
            info.notes.push(note);
            storage
        }
        (None, _) => Storage::Rows {
            reason: format!(
                "its type ({}) is not a whole-byte integer or IEEE float",
                sample.name
            ),
        },
        (
            Some(_),
            Ok(Layout::Contiguous {
                address: Some(address),
                size,
            }),
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
        (Some(_), Ok(Layout::Chunked { chunk_shape, .. })) => {
            let listed = || {
                let chunks = dataset
                    .chunks()
                    .map_err(|e| format!("unreadable chunk index: {e}"))?;
                Ok(chunks
                    .into_iter()
                    .map(|c| Listed {
                        offset: c.offset,
                        address: c.address,
                        size: c.storage_size,
                        mask: c.filter_mask,
                    })
                    .collect())
            };
            match chunks::index(
                &dataset,
                &shape,
                chunk_shape,
                listed,
                sample.size,
                h5.len,
                opts.max_memory,
            )
            .map_err(fail)?
            {
                Indexed::Chunks(c) => Storage::Chunks(c),
                Indexed::Rows(reason) => Storage::Rows { reason },
            }
        }
        (Some(_), Ok(Layout::Contiguous { address: None, .. })) => Storage::Fill(
            dataset
                .fill_value::<f64>()
                .map_err(|e| fail(format!("unreadable fill value: {e}")))?
                .unwrap_or(0.0),
        ),
        (Some(_), Ok(Layout::Compact { .. })) => Storage::Rows {
            reason: "its data is compact (held in its header)".into(),
        },
        (Some(_), Ok(other)) => Storage::Rows {
            reason: format!("its layout is {other}"),
        },
    };
    info.notes.push(match &storage {
        Storage::Contiguous { .. } => {
            "read box by box: each row of the last axis a box covers, from its place in the contiguous data"
                .to_string()
        }
        Storage::Chunks(c) => c.describe(),
        Storage::Fill(v) => format!(
            "read box by box: no data is written, every sample is the fill value {v}"
        ),
        Storage::Rows { reason } => format!(
            "read box by box through hdf5-pure's row windows, the rows of the first axis a box covers: {reason}"
        ),
    });
    let flipped: Vec<&str> = (0..3)
        .filter(|&a| flip[a])
        .map(|a| ["x", "y", "z"][a])
        .collect();
    if !flipped.is_empty() {
        info.notes.push(format!(
            "each box read from the file's mirrored range along {} (its coordinate decreases) and flipped, as the whole volume is",
            flipped.join(", ")
        ));
    }
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
            flip,
            storage,
            rows: Mutex::new(None),
            max_memory: opts.max_memory,
        },
        info,
    ))
}

/// The storage of a dataset `hdf5-pure` cannot index (`why`: its layout
/// message, or its chunk index), from the chunk index `hdf5-reader` lists
/// (`shared/hdf5_index.rs`), with the note that says so; refused, naming
/// the cause and `h5repack`, where its chunks need a decoder only
/// `hdf5-pure` has, or it is not chunked.
#[allow(clippy::too_many_arguments)]
fn beyond_hdf5_pure(
    path: &Path,
    name: &str,
    dataset: &Dataset,
    element: Option<Element>,
    shape: &[usize],
    sample_size: usize,
    file_len: u64,
    max_memory: u64,
    why: &str,
) -> Result<(Storage, String), String> {
    if element.is_none() {
        return Err(format!(
            "{why}, and its type is one only hdf5-pure decodes: {REPACK}"
        ));
    }
    let Some(list) = hdf5_index::chunk_list(path, name, sample_size)
        .map_err(|e| format!("{why}, and {e}: {REPACK}"))?
    else {
        return Err(format!("{why}, and it is not chunked: {REPACK}"));
    };
    let kind = list.kind;
    let chunks = list.chunks;
    match chunks::index(
        dataset,
        shape,
        list.chunk_shape,
        || Ok(chunks),
        sample_size,
        file_len,
        max_memory,
    )? {
        Indexed::Chunks(c) => Ok((
            Storage::Chunks(c),
            format!(
                "{why}: its chunk index ({kind}) listed through hdf5-reader, its chunks read and decoded here"
            ),
        )),
        Indexed::Rows(reason) => Err(format!("{why}, and {reason}: {REPACK}")),
    }
}

/// Whether `hdf5-pure` cannot read `dataset`'s samples itself (a layout
/// message of version 5, a version 2 B-tree chunk index): the eager
/// reader then reads the whole volume through the source of boxes.
pub(crate) fn beyond_pure(dataset: &Dataset) -> bool {
    matches!(
        dataset.layout(),
        Err(_)
            | Ok(Layout::Chunked {
                index: ChunkIndex::BTreeV2,
                ..
            })
    )
}

impl H5Source {
    /// The whole volume, each stored value through `real` where given
    /// (then kept as `f32`): the eager reader's read of a dataset
    /// [`beyond_pure`]. Held to `--max-memory` as a box is.
    pub(crate) fn whole(
        &self,
        real: Option<&dyn Fn(f64) -> f64>,
    ) -> Result<volray_core::Samples, IoError> {
        let hi = self.grid.dims;
        let kept = if real.is_some() {
            SampleType::F32
        } else {
            self.stored
        };
        self.check_box([0; 3], hi, kept)?;
        read_as_stored!(kept, |T| self.samples::<T>([0; 3], hi, real))
    }

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
            Storage::Chunks(c) => c.largest as u128 + 2 * c.bytes as u128,
            Storage::Fill(_) => 0,
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

    /// Checks that the box `lo..hi` as `kept`, beside the scratch to read
    /// it, fits `--max-memory`.
    fn check_box(&self, lo: [usize; 3], hi: [usize; 3], kept: SampleType) -> Result<(), IoError> {
        let voxels = (0..3).map(|a| hi[a] - lo[a]).product::<usize>();
        let peak = voxels as u128 * kept.bytes() as u128 + self.scratch();
        check_held(
            &self.path,
            &format!("box {lo:?}..{hi:?} of HDF5 dataset \"{}\"", self.name),
            voxels as u128,
            peak,
            &format!(
                "{} as {} and the scratch to read it",
                format_bytes(peak),
                kept.name()
            ),
            self.max_memory,
        )
    }

    /// The box `lo..hi` (x, y, z).
    fn read(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, IoError> {
        let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        self.check_box(lo, hi, self.stored)?;
        // The file's range of the box: mirrored along a flipped axis.
        let n = self.grid.dims;
        let file_lo: [usize; 3] =
            std::array::from_fn(|a| if self.flip[a] { n[a] - hi[a] } else { lo[a] });
        let file_hi: [usize; 3] =
            std::array::from_fn(|a| if self.flip[a] { n[a] - lo[a] } else { hi[a] });
        let real = self.real.as_deref().map(|f| f as &dyn Fn(f64) -> f64);
        let samples = read_as_stored!(self.stored, |T| self
            .samples::<T>(file_lo, file_hi, real)
            .map(|mut v| {
                for a in (0..3).filter(|&a| self.flip[a]) {
                    flip_axis(&mut v, dims, a);
                }
                v
            }))?;
        let origin = self.grid.origin
            + volray_core::glam::DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64)
                * self.grid.spacing;
        Volume::from_samples(dims, samples)
            .and_then(|v| v.with_spacing(self.grid.spacing))
            .and_then(|v| v.with_origin(origin))
            .map_err(|e| IoError::volume(&self.path, e))
    }

    /// The box's samples, x fastest.
    fn samples<T: Stored>(
        &self,
        lo: [usize; 3],
        hi: [usize; 3],
        real: Option<&dyn Fn(f64) -> f64>,
    ) -> Result<Vec<T>, IoError> {
        let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let mut out = vec![T::default(); dims.iter().product()];
        let (dlo, dhi) = self.placement.dataset_box(lo, hi);
        let w = Window {
            strides: self.placement.strides(dims),
            lo: dlo,
            hi: dhi,
        };
        // The value as the eager reader keeps it, at its place in the box.
        let mut put = |at: usize, v: f64| {
            let v = real.map_or(v, |f| f(v));
            out[at] = T::from_f64(f64::from(v as f32));
        };
        match (&self.storage, self.element) {
            (Storage::Contiguous { address }, Some(e)) => {
                self.contiguous(*address, e, &w, &mut put)?
            }
            (Storage::Chunks(c), Some(e)) => self.chunks(c, e, &w, &mut put)?,
            (Storage::Fill(v), _) => fill(&w, *v, &mut put),
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
        each_index(&grid_lo, &grid_hi, |at| {
            let origin: Vec<usize> = (0..n).map(|a| at[a] * k[a]).collect();
            let from: Vec<usize> = (0..n).map(|a| w.lo[a].max(origin[a])).collect();
            let to: Vec<usize> = (0..n).map(|a| w.hi[a].min(origin[a] + k[a])).collect();
            let Some(chunk) = c.index.get(at) else {
                // Never written: the fill value.
                let part = Window {
                    lo: from,
                    hi: to,
                    strides: w.strides.clone(),
                };
                fill_part(w, &part, c.fill, put);
                return Ok(());
            };
            let data = self.decode(c, chunk, at)?;
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

    /// Reads and decodes one chunk (exactly [`Chunks::bytes`] long).
    fn decode(&self, c: &Chunks, chunk: &StoredChunk, at: &[usize]) -> Result<Vec<u8>, IoError> {
        let mut stored = vec![0u8; chunk.size as usize];
        self.read_at(chunk.address, &mut stored)?;
        c.decode(&self.path, &self.name, at, chunk, stored)
    }

    /// Through `hdf5-pure`'s row windows (see the module docs).
    fn rows(&self, w: &Window, put: &mut impl FnMut(usize, f64)) -> Result<(), IoError> {
        let n = self.shape.len();
        let last = n - 1;
        let ds = c_strides(&self.shape);
        let row = ds[0];
        let h5 = {
            let mut opened = self.rows.lock().unwrap_or_else(|p| p.into_inner());
            match &*opened {
                Some(h5) => Arc::clone(h5),
                None => Arc::clone(opened.insert(Arc::new(h5::open(&self.path)?))),
            }
        };
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

/// Puts `value` at every sample of the box `w`.
fn fill(w: &Window, value: f64, put: &mut impl FnMut(usize, f64)) {
    fill_part(w, w, value, put);
}

/// Puts `value` at every sample of `part`, a box within the box `w`.
fn fill_part(w: &Window, part: &Window, value: f64, put: &mut impl FnMut(usize, f64)) {
    let _ = each_index::<()>(&part.lo, &part.hi, |idx| {
        let at: usize = (0..idx.len())
            .map(|a| (idx[a] - w.lo[a]) * w.strides[a])
            .sum();
        put(at, value);
        Ok(())
    });
}

/// Reverses the x-fastest samples of a box of `dims` along `axis`.
fn flip_axis<T>(data: &mut [T], dims: [usize; 3], axis: usize) {
    let inner: usize = dims[..axis].iter().product();
    let n = dims[axis];
    for block in data.chunks_exact_mut(inner * n) {
        for i in 0..n / 2 {
            let (front, back) = block.split_at_mut((n - 1 - i) * inner);
            front[i * inner..(i + 1) * inner].swap_with_slice(&mut back[..inner]);
        }
    }
}

impl VolumeSource for H5Source {
    fn grid(&self) -> GridFrame {
        self.grid
    }

    fn sample_type(&self) -> SampleType {
        self.stored
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        check_box(self.grid.dims, lo, hi).map_err(|e| e.prefixed(self.path.display()))?;
        Ok(self.read(lo, hi)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flip_axis_reverses_one_axis_of_an_x_fastest_box() {
        // dims (3, 2, 2): value x + 10y + 100z.
        let dims = [3, 2, 2];
        let at = |x: usize, y: usize, z: usize| x + 3 * (y + 2 * z);
        let v: Vec<usize> = (0..12)
            .map(|i| i % 3 + 10 * (i / 3 % 2) + 100 * (i / 6))
            .collect();
        for axis in 0..3 {
            let mut f = v.clone();
            flip_axis(&mut f, dims, axis);
            for z in 0..2 {
                for y in 0..2 {
                    for x in 0..3 {
                        let mut p = [x, y, z];
                        p[axis] = dims[axis] - 1 - p[axis];
                        assert_eq!(f[at(x, y, z)], v[at(p[0], p[1], p[2])], "axis {axis}");
                    }
                }
            }
        }
    }
}
