//! Reading the samples of one Zarr array through `zarrs`: opening the
//! array (v2 or v3, whichever metadata file the directory holds), its
//! sample type, and [`read_box`], which reads any box of it. The eager
//! reader calls [`read_box`] for a whole 3-D volume; a lazy, bricked
//! reader can call it per brick.
//!
//! `zarrs` does the chunk grid, the codecs (blosc, zstd, gzip, sharding,
//! crc32c, transpose), fill values and missing chunks (read as the fill
//! value, as the Zarr specifications say). Before it decodes anything,
//! the box and the chunk (the shard, for a sharded array: the unit
//! `zarrs` may hold decoded) are checked against the memory limit, so a
//! metadata file that lies about its shapes is refused before a buffer
//! of that size exists; what `zarrs` reads and decodes is checked on the
//! way (`guard.rs`).

use std::ops::Deref;
use std::path::Path;
use std::sync::Arc;

use unsafe_cell_slice::UnsafeCellSlice;
use volray_core::Samples;
use zarrs::array::codec::BloscCodec;
use zarrs::array::codec::api::CodecError;
use zarrs::array::data_type::{
    Float32DataType, Float64DataType, Int8DataType, Int16DataType, Int32DataType, Int64DataType,
    UInt8DataType, UInt16DataType, UInt32DataType, UInt64DataType,
};
use zarrs::array::{
    Array, ArrayBytesFixedDisjointView, ArrayError, ArrayMetadata, ArrayShardedExt, ArraySubset,
};
use zarrs::convert::array_metadata_v2_to_v3;
use zarrs::filesystem::FilesystemStore;
use zarrs::plugin::ExtensionAliasesV2;
use zarrs::storage::StorageError;

use super::guard::{self, CheckedStore};
use crate::IoError;
use crate::shared::limits::check_volume_size;

/// An open Zarr array on the file system: as its metadata describes it
/// (what `volray info` shows), and, where that differs, as its chunks
/// are decoded.
pub(crate) struct ZarrArray {
    array: Array<CheckedStore>,
    /// A Zarr v2 array with a blosc compressor, opened again through v3
    /// metadata: `zarrs` builds a v2 blosc compressor itself rather than
    /// through its codec registry, so without this its chunks would skip
    /// the checked blosc codec (`guard.rs`).
    decoder: Option<Array<CheckedStore>>,
}

impl ZarrArray {
    /// The array that decodes the chunks.
    fn reader(&self) -> &Array<CheckedStore> {
        self.decoder.as_ref().unwrap_or(&self.array)
    }
}

impl Deref for ZarrArray {
    type Target = Array<CheckedStore>;

    fn deref(&self) -> &Self::Target {
        &self.array
    }
}

/// The sample types volray reads from Zarr, and how each is kept: `u8`,
/// `i8`, `u16`, `i16` and `f32` as stored, the others as `f32`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ZarrType {
    U8,
    I8,
    U16,
    I16,
    F32,
    U32,
    I32,
    U64,
    I64,
    F64,
}

impl ZarrType {
    /// The type of `array`, or an error naming the one it has.
    fn of(path: &Path, array: &Array<CheckedStore>) -> Result<Self, IoError> {
        let dt = array.data_type();
        let found = [
            (dt.is::<UInt8DataType>(), ZarrType::U8),
            (dt.is::<Int8DataType>(), ZarrType::I8),
            (dt.is::<UInt16DataType>(), ZarrType::U16),
            (dt.is::<Int16DataType>(), ZarrType::I16),
            (dt.is::<Float32DataType>(), ZarrType::F32),
            (dt.is::<UInt32DataType>(), ZarrType::U32),
            (dt.is::<Int32DataType>(), ZarrType::I32),
            (dt.is::<UInt64DataType>(), ZarrType::U64),
            (dt.is::<Int64DataType>(), ZarrType::I64),
            (dt.is::<Float64DataType>(), ZarrType::F64),
        ]
        .into_iter()
        .find_map(|(is, t)| is.then_some(t));
        found.ok_or_else(|| {
            let name = serde_json::to_value(array.metadata())
                .ok()
                .and_then(|m| m.get("data_type").or_else(|| m.get("dtype")).cloned())
                .map_or_else(|| "?".to_string(), |v| v.to_string());
            IoError::invalid(
                path,
                format!(
                    "Zarr data type {name} is not supported: volray reads (u)int8 to (u)int64, float32 and float64"
                ),
            )
        })
    }

    /// The name `volray info` shows.
    pub(crate) fn name(self) -> &'static str {
        match self {
            ZarrType::U8 => "uint8",
            ZarrType::I8 => "int8",
            ZarrType::U16 => "uint16",
            ZarrType::I16 => "int16",
            ZarrType::F32 => "float32",
            ZarrType::U32 => "uint32",
            ZarrType::I32 => "int32",
            ZarrType::U64 => "uint64",
            ZarrType::I64 => "int64",
            ZarrType::F64 => "float64",
        }
    }

    /// Bytes a value takes as stored.
    pub(crate) fn size(self) -> u64 {
        match self {
            ZarrType::U8 | ZarrType::I8 => 1,
            ZarrType::U16 | ZarrType::I16 => 2,
            ZarrType::F32 | ZarrType::U32 | ZarrType::I32 => 4,
            ZarrType::U64 | ZarrType::I64 | ZarrType::F64 => 8,
        }
    }

    /// Bytes a value takes while it is read: the stored value, plus the
    /// `f32` it becomes for the types volray does not keep.
    pub(crate) fn read_bytes(self) -> u64 {
        match self {
            ZarrType::U8 | ZarrType::I8 | ZarrType::U16 | ZarrType::I16 | ZarrType::F32 => {
                self.size()
            }
            _ => self.size() + 4,
        }
    }

    /// Bytes a value takes in memory once read.
    pub(crate) fn kept_bytes(self) -> u64 {
        self.size().min(4)
    }
}

/// One line from a `zarrs` error (some span lines), after the file.
pub(crate) fn zarr_error(path: &Path, what: &str, error: impl std::fmt::Display) -> IoError {
    let text = error.to_string().replace('\n', " ");
    IoError::invalid(path, format!("{what}: {text}"))
}

/// Opens the array at `dir` (a directory holding `zarr.json` or
/// `.zarray`) and finds its sample type. No read of its files may exceed
/// `max_memory` bytes.
pub(crate) fn open_array(dir: &Path, max_memory: u64) -> Result<(ZarrArray, ZarrType), IoError> {
    guard::install();
    let store =
        FilesystemStore::new(dir).map_err(|e| zarr_error(dir, "cannot open Zarr store", e))?;
    let store = Arc::new(CheckedStore::new(store, max_memory));
    let not_readable = |e| zarr_error(dir, "not a readable Zarr array", e);
    let array = Array::open(store.clone(), "/").map_err(not_readable)?;
    let ty = ZarrType::of(dir, &array)?;
    check_shape(dir, array.shape())?;
    check_subchunks(dir, &array)?;
    let decoder = match array.metadata() {
        ArrayMetadata::V2(v2)
            if v2
                .compressor
                .as_ref()
                .is_some_and(|c| BloscCodec::matches_name_v2(c.id())) =>
        {
            let v3 = array_metadata_v2_to_v3(v2)
                .map_err(|e| zarr_error(dir, "not a readable Zarr array", e))?;
            Some(
                Array::new_with_metadata(store, "/", ArrayMetadata::V3(v3))
                    .map_err(not_readable)?,
            )
        }
        _ => None,
    };
    Ok((ZarrArray { array, decoder }, ty))
}

/// Refuses a shape whose voxels cannot be counted in a `usize` with room
/// for 16 bytes each: a lying header (bad input), refused when the array
/// is opened, before any box of it is planned (issue 41: a 2^40-cube
/// overflowed the streamed renderer's box arithmetic).
fn check_shape(dir: &Path, shape: &[u64]) -> Result<(), IoError> {
    let voxels = shape
        .iter()
        .try_fold(1u128, |n, &d| n.checked_mul(u128::from(d)));
    match voxels {
        Some(n) if n <= (usize::MAX / 16) as u128 => Ok(()),
        _ => Err(IoError::invalid(
            dir,
            format!(
                "shape {shape:?}: {} voxels, more than this machine can address",
                voxels.map_or_else(|| "over 3.4e38".to_string(), |n| n.to_string())
            ),
        )),
    }
}

/// Refuses a sharded array whose subchunks do not tile its shards (zarrs
/// finds out only when it reads one, in its own words).
fn check_subchunks(dir: &Path, array: &Array<CheckedStore>) -> Result<(), IoError> {
    let (Some(subchunk), Ok(shard)) = (
        array.subchunk_shape(),
        array.chunk_shape(&vec![0; array.dimensionality()]),
    ) else {
        return Ok(());
    };
    let tiles = subchunk.len() == shard.len()
        && shard
            .iter()
            .zip(&subchunk)
            .all(|(s, c)| s.get() % c.get() == 0);
    if tiles {
        return Ok(());
    }
    let list = |shape: &[std::num::NonZeroU64]| {
        let sizes: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
        format!("[{}]", sizes.join(", "))
    };
    Err(IoError::invalid(
        dir,
        format!(
            "the subchunk shape {} does not divide the shard shape {} (sharding_indexed)",
            list(&subchunk),
            list(&shard)
        ),
    ))
}

/// The shape of the chunks `zarrs` decodes whole: the regular grid's
/// chunk (a shard, for a sharded array), or `None` for an irregular grid.
pub(crate) fn chunk_shape(array: &ZarrArray) -> Option<Vec<u64>> {
    let origin = vec![0; array.dimensionality()];
    let shape = array.chunk_shape(&origin).ok()?;
    Some(shape.iter().map(|n| n.get()).collect())
}

/// Reads the box `start .. start + shape` of `array` (its own axis
/// order, the last axis fastest), C order: for a box whose last three
/// axes are z, y, x, that is volray's x-fastest layout. Types volray
/// does not keep become `f32`. The box and the array's chunk are checked
/// against `max_memory` first.
pub(crate) fn read_box(
    path: &Path,
    array: &ZarrArray,
    ty: ZarrType,
    start: &[u64],
    shape: &[u64],
    max_memory: u64,
) -> Result<Samples, IoError> {
    check_volume_size(path, "Zarr box", shape, ty.read_bytes(), max_memory)?;
    // The unit `zarrs` holds decoded beside the box: a chunk, or for a
    // sharded array one inner chunk (it decodes a shard's inner chunks
    // through the shard index, one by one, into the box).
    let unit = match (array.is_sharded(), array.subchunk_shape()) {
        (true, Some(inner)) => Some(inner.iter().map(|n| n.get()).collect()),
        _ => chunk_shape(array),
    };
    if let Some(chunk) = unit {
        check_volume_size(path, "Zarr chunk shape", &chunk, ty.size(), max_memory)?;
    }
    let subset = ArraySubset::new_with_start_shape(start.to_vec(), shape.to_vec())
        .map_err(|e| zarr_error(path, "Zarr box", e))?;
    let array = array.reader();
    Ok(match ty {
        ZarrType::U8 => elements::<u8>(path, array, &subset)?.into(),
        ZarrType::I8 => elements::<i8>(path, array, &subset)?.into(),
        ZarrType::U16 => elements::<u16>(path, array, &subset)?.into(),
        ZarrType::I16 => elements::<i16>(path, array, &subset)?.into(),
        ZarrType::F32 => elements::<f32>(path, array, &subset)?.into(),
        // Wider types: f32 holds integers up to 2^24 exactly, and rounds
        // the rest to 24 significant bits, as every other reader does.
        ZarrType::U32 => widen(elements::<u32>(path, array, &subset)?, |v| v as f32),
        ZarrType::I32 => widen(elements::<i32>(path, array, &subset)?, |v| v as f32),
        ZarrType::U64 => widen(elements::<u64>(path, array, &subset)?, |v| v as f32),
        ZarrType::I64 => widen(elements::<i64>(path, array, &subset)?, |v| v as f32),
        ZarrType::F64 => widen(elements::<f64>(path, array, &subset)?, |v| v as f32),
    })
}

/// The box `subset` of `array`, decoded by `zarrs` straight into one
/// buffer of the box's size: each chunk's decoded values are written in
/// place, so the box costs its own bytes once (decoding into `zarrs`'s
/// own bytes and converting them to a `Vec<T>` held both at once: twice
/// the box, 4 GiB for a 2 GiB level).
fn elements<T: bytemuck::Pod>(
    path: &Path,
    array: &Array<CheckedStore>,
    subset: &ArraySubset,
) -> Result<Vec<T>, IoError> {
    let shape: Vec<u64> = subset.shape().to_vec();
    let count = usize::try_from(subset.num_elements())
        .map_err(|_| IoError::invalid(path, "a Zarr box larger than the address space"))?;
    let mut values = vec![T::zeroed(); count];
    let whole = ArraySubset::new_with_shape(shape.clone());
    let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut values);
    // SAFETY: `ArrayBytesFixedDisjointView::new` asks that no two views of
    // the same bytes cover overlapping subsets. This is the only view ever
    // made of `values`' bytes, and it covers the whole buffer, so it
    // overlaps no other; `values` is borrowed mutably by it until
    // `retrieve_array_subset_into` returns, so nothing else reads or writes
    // the bytes meanwhile. The bytes are `T`'s (Pod: any bytes are a valid
    // value), in native order, as `zarrs` decodes elements. Exercised by
    // every Zarr test that compares values with the writer's
    // (tests/zarr.rs, tests/zarr_write.rs).
    let mut view = unsafe {
        ArrayBytesFixedDisjointView::new(UnsafeCellSlice::new(bytes), size_of::<T>(), &shape, whole)
    }
    .map_err(|e| zarr_error(path, "Zarr box", e))?;
    array
        .retrieve_array_subset_into(subset, (&mut view).into())
        .map_err(|e| match os_error(&e) {
            // The same line either way; the system's failure told apart
            // from the chunks' bytes (the command line's exit 2, not 1).
            Some(os) => IoError::os(
                path,
                "read Zarr chunks",
                std::io::Error::new(os.kind(), os.to_string()),
            ),
            None => zarr_error(path, "cannot read Zarr chunks", e),
        })?;
    Ok(values)
}

/// The operating system's error under a failed read of chunks, where the
/// system failed (a chunk file that cannot be opened or read), and `None`
/// where the bytes did (cut, garbled, refused by `guard.rs`).
fn os_error(e: &ArrayError) -> Option<&std::io::Error> {
    match e {
        ArrayError::StorageError(StorageError::IOError(os))
        | ArrayError::CodecError(CodecError::IOError(os))
        | ArrayError::CodecError(CodecError::StorageError(StorageError::IOError(os))) => Some(os),
        _ => None,
    }
}

fn widen<T: Copy>(values: Vec<T>, to_f32: impl Fn(T) -> f32) -> Samples {
    values.into_iter().map(to_f32).collect::<Vec<f32>>().into()
}
