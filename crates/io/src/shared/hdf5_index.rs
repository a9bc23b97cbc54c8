//! What `hdf5-pure` 0.47 (`shared/hdf5.rs`) cannot read of an HDF5 file,
//! read through `hdf5-reader` 0.12 (pure Rust, read-only, MIT OR
//! Apache-2.0): the chunk index of a dataset whose layout message is
//! version 5 (HDF5 2.0; h5py 3.16 with `libver='latest'` writes it for
//! every filtered chunked dataset), or whose chunks a version 2 B-tree
//! indexes (two or more unlimited dimensions), and the dimension scales a
//! `DIMENSION_LIST` attribute's object references point at (NetCDF-4 from
//! netCDF-C before `_Netcdf4Dimid`).
//!
//! Routes weighed (issue 43, item 4):
//! - our own parsing where `hdf5-pure` refuses: it hides every object
//!   header (no raw messages, no object addresses, no reference or
//!   variable-length attribute values), so we would parse object headers
//!   (both versions, continuation blocks, dense attribute storage in a
//!   fractal heap), the layout message, the fixed and extensible arrays
//!   and the version 2 B-tree ourselves: thousands of lines of metadata
//!   parsing to harden against hostile files;
//! - a fallback crate, taken: `hdf5-reader` parses layout messages 1 to 5
//!   (version 5 is version 4 but for the width of a filtered chunk's
//!   size in the index records, which each index's own header states:
//!   the record or element size), walks every chunk index (the version 2
//!   B-tree's records of types 10 and 11, unfiltered and filtered chunks;
//!   depth capped, nodes visited once, every checksum verified) and
//!   exposes object addresses, raw attributes and object references. All
//!   its dependencies but its own `hdf5-core` were already built here;
//!   without its `rayon` and `lz4` features;
//! - a refusal, which stays for what neither reads (a filter only
//!   `hdf5-pure` decodes, under a layout it cannot parse): the message
//!   names the cause and `h5repack` as the way round.
//!
//! Only the index is taken from `hdf5-reader`: the chunks are read and
//! decoded as every other chunked dataset's (`formats/hdf5_lazy/chunks.rs`:
//! each address and size checked against the file, each chunk inflated to
//! exactly its size), so values are those of the other paths. Its calls
//! run under [`guarded`], a panic in it a one-line error.

use std::path::Path;

use hdf5_reader::chunk_index::{self, ChunkEntry};
use hdf5_reader::messages::HdfMessage;
use hdf5_reader::messages::layout::{ChunkIndexing, DataLayout};
use hdf5_reader::{Dataset, Hdf5File};

use crate::shared::panics::guarded;

/// The way round that every refusal of this layer names: h5repack's
/// bounds 0 and 1 (`H5F_LIBVER_EARLIEST`, `H5F_LIBVER_V18`: layout
/// message version 3, every chunk index a version 1 B-tree), which
/// `hdf5-pure` reads.
pub(crate) const REPACK: &str = "rewrite it with a layout every reader takes, e.g. h5repack --low=0 --high=1 -l CHUNK=64x64x64 -f GZIP=4 in.h5 out.h5 (or write it with h5py's libver='earliest')";

/// Chunk index entries at most: more than any dataset a file can hold
/// names (each chunk costs the index at least a few bytes of the file).
const MAX_CHUNKS: usize = 1 << 26;

/// One chunk as a chunk index lists it.
#[derive(Debug, Clone)]
pub(crate) struct Listed {
    /// The chunk's first sample, one coordinate per dataset axis.
    pub offset: Vec<u64>,
    pub address: u64,
    /// Bytes stored (the chunk's own size for an unfiltered one).
    pub size: u64,
    /// Bit `i` set: filter `i` of the pipeline was not applied.
    pub mask: u32,
}

/// A chunked dataset's chunk shape, the index's kind (for messages and
/// `volray info`) and the chunks it lists.
pub(crate) struct ChunkList {
    pub chunk_shape: Vec<u64>,
    pub kind: &'static str,
    pub chunks: Vec<Listed>,
}

/// Runs `f` on the file at `path` opened by `hdf5-reader`, a panic in it
/// an error.
fn with_file<T>(path: &Path, f: impl FnOnce(&Hdf5File) -> Result<T, String>) -> Result<T, String> {
    guarded(|| {
        let file = Hdf5File::open(path).map_err(|e| format!("hdf5-reader cannot open it: {e}"))?;
        f(&file)
    })
    .unwrap_or_else(|_| Err("hdf5-reader failed on its metadata: the file is damaged".into()))
}

/// The chunks of dataset `name` (absolute path) of the HDF5 file at
/// `path`, whose samples are `sample_size` bytes, as its chunk index
/// lists them; `Ok(None)` where the dataset is not chunked.
pub(crate) fn chunk_list(
    path: &Path,
    name: &str,
    sample_size: usize,
) -> Result<Option<ChunkList>, String> {
    with_file(path, |file| {
        let ds = file
            .dataset(name)
            .map_err(|e| format!("hdf5-reader cannot open it: {e}"))?;
        let header = file
            .get_or_parse_header(ds.address())
            .map_err(|e| format!("hdf5-reader cannot read its header: {e}"))?;
        let layout = header.messages.iter().find_map(|m| match m {
            HdfMessage::DataLayout(l) => Some(l.layout.clone()),
            _ => None,
        });
        let Some(DataLayout::Chunked {
            address,
            dims,
            chunk_indexing,
            ..
        }) = layout
        else {
            return Ok(None);
        };
        let rank = ds.ndim();
        // Layout messages before version 4 add the sample size as a last
        // chunk dimension.
        let chunk_dims: Vec<u32> = dims.iter().copied().take(rank).collect();
        if chunk_dims.len() != rank || chunk_dims.contains(&0) {
            return Err(format!(
                "its chunk dimensions {dims:?} do not fit its {rank} axes"
            ));
        }
        let kind = match &chunk_indexing {
            None => "a version 1 B-tree",
            Some(ChunkIndexing::SingleChunk { .. }) => "a single chunk",
            Some(ChunkIndexing::Implicit) => "an implicit index",
            Some(ChunkIndexing::FixedArray { .. }) => "a fixed array",
            Some(ChunkIndexing::ExtensibleArray { .. }) => "an extensible array",
            Some(ChunkIndexing::BTreeV2) => "a version 2 B-tree",
        };
        let chunk_shape: Vec<u64> = chunk_dims.iter().map(|&d| u64::from(d)).collect();
        let offset_size = file.superblock().offset_size;
        let undefined = match offset_size {
            1..=7 => (1u64 << (8 * u32::from(offset_size))) - 1,
            _ => u64::MAX,
        };
        if address == undefined {
            // No chunk written yet.
            return Ok(Some(ChunkList {
                chunk_shape,
                kind,
                chunks: Vec::new(),
            }));
        }
        let entries = entries(
            file,
            &ds,
            address,
            &chunk_dims,
            chunk_indexing.as_ref(),
            sample_size,
        )
        .map_err(|e| format!("its chunk index ({kind}) is unreadable: {e}"))?;
        if entries.len() > MAX_CHUNKS {
            return Err(format!(
                "its chunk index ({kind}) lists {} chunks, more than the {MAX_CHUNKS} read",
                entries.len()
            ));
        }
        // An unfiltered chunk's size is the chunk's: the version 2 B-tree's
        // type 10 records and an unfiltered single chunk do not store it.
        let whole = chunk_shape
            .iter()
            .try_fold(sample_size as u64, |a, &n| a.checked_mul(n))
            .ok_or_else(|| format!("its chunk shape {chunk_shape:?} is too large"))?;
        let chunks = entries
            .into_iter()
            .map(|e| Listed {
                size: if e.size == 0 { whole } else { e.size },
                offset: e.offsets,
                address: e.address,
                mask: e.filter_mask,
            })
            .collect();
        Ok(Some(ChunkList {
            chunk_shape,
            kind,
            chunks,
        }))
    })
}

/// The entries of the chunk index at `address` (see [`chunk_list`]).
fn entries(
    file: &Hdf5File,
    ds: &Dataset,
    address: u64,
    chunk_dims: &[u32],
    indexing: Option<&ChunkIndexing>,
    sample_size: usize,
) -> Result<Vec<ChunkEntry>, hdf5_reader::error::Error> {
    let storage = file.storage();
    let (os, ls) = (file.superblock().offset_size, file.superblock().length_size);
    let shape = ds.shape();
    let rank = shape.len();
    match indexing {
        None => Err(hdf5_reader::error::Error::InvalidData(
            "a version 1 B-tree is read by hdf5-pure, not here".into(),
        )),
        Some(ChunkIndexing::SingleChunk {
            filtered_size,
            filters,
        }) => Ok(vec![chunk_index::single_chunk_entry(
            address,
            *filtered_size,
            *filters,
            rank,
        )]),
        Some(ChunkIndexing::Implicit) => chunk_index::collect_implicit_chunk_entries(
            address,
            shape,
            chunk_dims,
            sample_size,
            None,
            storage.len(),
        ),
        Some(ChunkIndexing::FixedArray { .. }) => {
            hdf5_reader::fixed_array::collect_fixed_array_chunk_entries_storage(
                storage, address, os, ls, shape, chunk_dims, None,
            )
        }
        Some(ChunkIndexing::ExtensibleArray { .. }) => {
            hdf5_reader::extensible_array::collect_extensible_array_chunk_entries_storage(
                storage,
                address,
                os,
                ls,
                shape,
                ds.max_dims(),
                chunk_dims,
                None,
            )
        }
        Some(ChunkIndexing::BTreeV2) => chunk_index::collect_v2_chunk_entries_storage(
            storage,
            address,
            os,
            ls,
            rank as u32,
            chunk_dims,
            None,
        ),
    }
}

/// The dimension scales the `DIMENSION_LIST` attribute of each dataset
/// of `names` (absolute paths) points at, one per axis, each named by its
/// link name among `candidates` (absolute paths of the datasets that may
/// be scales): for each dataset, `None` where it has no such attribute,
/// or an axis has no scale or one outside `candidates`. The file opened
/// once, each candidate once.
pub(crate) fn dimension_lists(
    path: &Path,
    names: &[String],
    candidates: &[String],
) -> Result<Vec<Option<Vec<String>>>, String> {
    with_file(path, |file| {
        let addresses: Vec<(u64, &str)> = candidates
            .iter()
            .filter_map(|c| {
                let d = file.dataset(c).ok()?;
                Some((d.address(), c.rsplit('/').next().unwrap_or(c)))
            })
            .collect();
        names
            .iter()
            .map(|name| {
                let scales =
                    scales_of(file, name).map_err(|e| format!("dataset \"{name}\": {e}"))?;
                Ok(scales.and_then(|s| {
                    s.iter()
                        .map(|a| {
                            addresses
                                .iter()
                                .find(|(at, _)| at == a)
                                .map(|(_, n)| n.to_string())
                        })
                        .collect()
                }))
            })
            .collect()
    })
}

/// The object header addresses of the first scale attached to each axis
/// of dataset `name`, from its `DIMENSION_LIST`; `None` without one, or
/// with an axis that has none.
fn scales_of(file: &Hdf5File, name: &str) -> Result<Option<Vec<u64>>, String> {
    let ds = file
        .dataset(name)
        .map_err(|e| format!("hdf5-reader cannot open it: {e}"))?;
    let Ok(list) = ds.attribute("DIMENSION_LIST") else {
        return Ok(None);
    };
    let rank = ds.ndim();
    // One variable-length sequence per axis, each stored as a 4-byte
    // length, a global heap collection's address and a 4-byte index (the
    // format's "Variable-length" datatype); each sequence of object
    // references, an object header's address each (H5DS, "Dimension
    // Scales" specification 1.0).
    let each = ds.vlen_reference_size();
    let os = usize::from(file.superblock().offset_size);
    if list.raw_data.len() != rank * each || os == 0 || os > 8 {
        return Err(format!(
            "its DIMENSION_LIST holds {} bytes, not {rank} sequences of {each}",
            list.raw_data.len()
        ));
    }
    let mut scales = Vec::with_capacity(rank);
    for axis in list.raw_data.chunks_exact(each) {
        let refs = ds
            .resolve_vlen_reference_bytes(axis, os)
            .map_err(|e| format!("its DIMENSION_LIST is unreadable: {e}"))?;
        // The first scale attached names the axis (netCDF-C attaches one).
        let Some(first) = refs.get(..os) else {
            return Ok(None);
        };
        let mut address = [0u8; 8];
        address[..os].copy_from_slice(first);
        scales.push(u64::from_le_bytes(address));
    }
    Ok(Some(scales))
}
