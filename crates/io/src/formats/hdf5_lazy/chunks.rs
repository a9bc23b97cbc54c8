//! The chunks of a chunked HDF5 dataset as the box-by-box reader reads
//! them: the chunk index enumerated once (`hdf5-pure`'s `Dataset::chunks`,
//! which reads the index and no data; `hdf5-reader`'s walk of an index
//! `hdf5-pure` cannot read, `shared/hdf5_index.rs`), each entry checked against the
//! chunk grid and the file's end; the filter pipeline recognised; and each
//! chunk a box touches decoded here, the filters undone in the reverse of
//! their order in the pipeline (the HDF5 format's "Filter Pipeline
//! Message"), a filter the chunk's mask says was skipped left out:
//! - deflate (filter 1): zlib, inflated to exactly its decoded size;
//! - shuffle (2): the bytes of each element regrouped (H5Zshuffle.c);
//! - Fletcher-32 (3): the checksum the last 4 bytes hold (little-endian)
//!   verified over the rest, a chunk that fails it refused naming the file,
//!   dataset and chunk (H5Zfletcher32.c, H5checksum.c);
//! - LZF (32000, h5py's): liblzf's raw token stream, no header, decoded
//!   to exactly its decoded size (`shared/compress.rs`).
//!
//! A chunk the index does not list was never written: its samples are the
//! dataset's fill value (its fill value message; 0 where it sets none), as
//! libhdf5 and `hdf5-pure` read them. Any other filter (scale-offset,
//! n-bit, a third party's) leaves the dataset to `hdf5-pure`'s row
//! windows; szip is refused by name before this (`shared/hdf5.rs`).

use std::collections::HashMap;
use std::path::Path;

use hdf5_pure::Dataset;

use crate::IoError;
use crate::shared::compress::{Compression, inflate_exact};
use crate::shared::hdf5_index::Listed;
use crate::shared::limits::format_bytes;

/// HDF5's registered filter numbers decoded here (H5Zpublic.h; 32000 is
/// h5py's LZF, registered with The HDF Group).
const FILTER_DEFLATE: u16 = 1;
const FILTER_SHUFFLE: u16 = 2;
const FILTER_FLETCHER32: u16 = 3;
const FILTER_LZF: u16 = 32000;

/// One filter of a chunk pipeline this module decodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Filter {
    Deflate,
    /// Bytes of each element regrouped by significance (HDF5's shuffle),
    /// elements of this many bytes.
    Shuffle(usize),
    Fletcher32,
    Lzf,
}

impl Filter {
    fn name(self) -> &'static str {
        match self {
            Filter::Deflate => "deflate",
            Filter::Shuffle(_) => "shuffle",
            Filter::Fletcher32 => "fletcher32",
            Filter::Lzf => "lzf",
        }
    }
}

/// One chunk as the index gives it.
#[derive(Debug, Clone, Copy)]
pub(super) struct StoredChunk {
    pub address: u64,
    pub size: u64,
    /// Bit `i` set: filter `i` of the pipeline was not applied.
    pub mask: u32,
}

/// The chunks of a chunked dataset, by their position on the chunk grid.
pub(super) struct Chunks {
    pub shape: Vec<usize>,
    /// Bytes of one decoded chunk.
    pub bytes: usize,
    /// The largest stored chunk, in bytes.
    pub largest: usize,
    filters: Vec<Filter>,
    pub index: HashMap<Vec<usize>, StoredChunk>,
    /// Chunks on the grid, and the value of every sample of one the index
    /// does not list.
    pub expected: usize,
    pub fill: f64,
}

/// What a chunked dataset is read through.
pub(super) enum Indexed {
    /// Its chunks, decoded here.
    Chunks(Box<Chunks>),
    /// `hdf5-pure`'s row windows, for the reason given.
    Rows(String),
}

/// The chunks of a chunked dataset of `shape` (see the module docs), as
/// `listed` gives them (`hdf5-pure`'s enumeration, or `hdf5-reader`'s for
/// an index `hdf5-pure` cannot read: `shared/hdf5_index.rs`), or the row
/// windows where this module cannot decode them; `Err` for an index no
/// reader can use or a chunk that cannot fit `max_memory`.
pub(super) fn index(
    dataset: &Dataset,
    shape: &[usize],
    chunk_shape: Vec<u64>,
    listed: impl FnOnce() -> Result<Vec<Listed>, String>,
    sample_size: usize,
    file_len: u64,
    max_memory: u64,
) -> Result<Indexed, String> {
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
            FILTER_FLETCHER32 => Filter::Fletcher32,
            FILTER_LZF => Filter::Lzf,
            _ => {
                return Ok(Indexed::Rows(format!(
                    "its chunks are filtered by {f}, which hdf5-pure decodes"
                )));
            }
        });
    }
    let listed = listed()?;
    let expected = shape
        .iter()
        .zip(&chunk)
        .try_fold(1usize, |a, (&n, &c)| a.checked_mul(n.div_ceil(c)))
        .unwrap_or(usize::MAX);
    // Deflate and LZF can grow incompressible data a little (a few bytes
    // per 16 KiB block; LZF at most 1 in 32, and h5py stores such a chunk
    // unfiltered); twice the chunk is far beyond either.
    let most = 2 * bytes as u64 + 4096;
    let mut index = HashMap::with_capacity(listed.len().min(expected));
    let mut largest = 0;
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
        let end = c.address.checked_add(c.size);
        if end.is_none_or(|e| e > file_len) || c.size == 0 {
            return Err(format!(
                "the chunk at offset {:?} is stored at byte {} ({} bytes), past the end of the {file_len}-byte file",
                c.offset, c.address, c.size
            ));
        }
        if c.size > most {
            return Err(format!(
                "the chunk at offset {:?} is stored in {} bytes, more than a chunk of {bytes} bytes can take",
                c.offset, c.size
            ));
        }
        largest = largest.max(c.size as usize);
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
                size: c.size,
                mask: c.mask,
            },
        );
        if old.is_some() {
            return Err(format!(
                "the chunk index lists the chunk at offset {:?} twice",
                c.offset
            ));
        }
    }
    // As `hdf5-pure`'s reads give it: the declared fill value in the
    // dataset's type, as an f64.
    let fill = dataset
        .fill_value::<f64>()
        .map_err(|e| format!("unreadable fill value: {e}"))?
        .unwrap_or(0.0);
    Ok(Indexed::Chunks(Box::new(Chunks {
        shape: chunk,
        bytes,
        largest,
        filters,
        index,
        expected,
        fill,
    })))
}

impl Chunks {
    /// What `volray info` says of the way a box is read.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "read box by box: the chunks of shape {:?} a box touches, from the chunk index",
            self.shape
        );
        if !self.filters.is_empty() {
            let names: Vec<&str> = self.filters.iter().map(|f| f.name()).collect();
            s += &format!(" ({} decoded here)", names.join(", "));
        }
        let missing = self.expected.saturating_sub(self.index.len());
        if missing > 0 {
            s += &format!(
                "; {missing} of its {} chunks are not written and read as the fill value {}",
                self.expected, self.fill
            );
        }
        s
    }

    /// The chunk at `at` on the chunk grid decoded from its `stored`
    /// bytes: exactly [`Chunks::bytes`] long. `dataset` names it in
    /// messages.
    pub fn decode(
        &self,
        path: &Path,
        dataset: &str,
        at: &[usize],
        chunk: &StoredChunk,
        stored: Vec<u8>,
    ) -> Result<Vec<u8>, IoError> {
        let offset: Vec<usize> = at.iter().zip(&self.shape).map(|(&i, &k)| i * k).collect();
        let fail = |reason: String| {
            IoError::invalid(
                path,
                format!("HDF5 dataset \"{dataset}\": the chunk at offset {offset:?} {reason}"),
            )
        };
        let applied = |i: usize| i >= 32 || chunk.mask & (1 << i) == 0;
        let mut data = stored;
        for (i, f) in self.filters.iter().enumerate().rev() {
            if !applied(i) {
                continue;
            }
            // What this filter was given on writing: the chunk, and the
            // checksums of the Fletcher-32 filters applied before it.
            let checksums = self.filters[..i]
                .iter()
                .enumerate()
                .filter(|&(j, g)| *g == Filter::Fletcher32 && applied(j))
                .count();
            let size = self.bytes + 4 * checksums;
            let what = |codec: &str| {
                format!("HDF5 dataset \"{dataset}\": {codec} chunk at offset {offset:?}")
            };
            data = match *f {
                Filter::Deflate => {
                    inflate_exact(path, &data, Compression::Zlib, size, &what("deflated"))?
                }
                Filter::Lzf => {
                    inflate_exact(path, &data, Compression::Lzf, size, &what("LZF-compressed"))?
                }
                Filter::Shuffle(n) => unshuffle(&data, n),
                Filter::Fletcher32 => {
                    let Some(split) = data.len().checked_sub(4) else {
                        return Err(fail(format!(
                            "holds {} bytes, too few for its Fletcher-32 checksum",
                            data.len()
                        )));
                    };
                    let (payload, tail) = data.split_at(split);
                    let stored = u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]);
                    let computed = fletcher32(payload);
                    if stored != computed && stored != swap_halves(computed) {
                        return Err(fail(format!(
                            "fails its Fletcher-32 checksum (stored {stored:#010x}, computed {computed:#010x}): the file is damaged"
                        )));
                    }
                    data.truncate(split);
                    data
                }
            };
        }
        if data.len() != self.bytes {
            return Err(fail(format!(
                "holds {} bytes, but a chunk of shape {:?} is {}",
                data.len(),
                self.shape,
                self.bytes
            )));
        }
        Ok(data)
    }
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

/// HDF5's Fletcher-32 checksum (`H5_checksum_fletcher32`, H5checksum.c):
/// the data as big-endian 16-bit words, summed into `sum1` and `sum1`'s
/// running total `sum2` in 32-bit arithmetic (wrapping, as C's unsigned
/// does), both folded toward 16 bits (`(s & 0xffff) + (s >> 16)`) after
/// every 360 words; an odd last byte added as the high byte of a word,
/// then folded; a last fold of both; `sum2 << 16 | sum1`.
fn fletcher32(data: &[u8]) -> u32 {
    let fold = |s: u32| (s & 0xffff) + (s >> 16);
    let (mut sum1, mut sum2) = (0u32, 0u32);
    let words = data.len() / 2;
    for block in data[..2 * words].chunks(2 * 360) {
        for w in block.chunks_exact(2) {
            sum1 = sum1.wrapping_add(u32::from(u16::from_be_bytes([w[0], w[1]])));
            sum2 = sum2.wrapping_add(sum1);
        }
        sum1 = fold(sum1);
        sum2 = fold(sum2);
    }
    if data.len() % 2 == 1 {
        sum1 = sum1.wrapping_add(u32::from(data[data.len() - 1]) << 8);
        sum2 = sum2.wrapping_add(sum1);
        sum1 = fold(sum1);
        sum2 = fold(sum2);
    }
    (fold(sum2) << 16) | fold(sum1)
}

/// The checksum as libhdf5 before 1.6.3 stored it on little-endian
/// machines, the bytes of each 16-bit half swapped; H5Zfletcher32.c
/// accepts either, and so does this reader.
fn swap_halves(c: u32) -> u32 {
    ((c & 0x00ff_00ff) << 8) | ((c >> 8) & 0x00ff_00ff)
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

    #[test]
    fn fletcher32_sums_big_endian_words_and_an_odd_last_byte() {
        // Words 0x0102, 0x0304 and a last byte 0x05 as 0x0500:
        // sum1 = 0x0102, 0x0406, 0x0906; sum2 = 0x0102, 0x0508, 0x0e0e.
        assert_eq!(fletcher32(&[1, 2, 3, 4, 5]), 0x0e0e_0906);
        assert_eq!(fletcher32(&[]), 0);
        // All ones: 1000 words of 0xffff. Each is 0 modulo 65535, which
        // the folds keep in the range 1..=0xffff where the sum is not 0.
        let c = fletcher32(&[0xff; 2000]);
        assert_eq!((c >> 16) % 0xffff, 0);
        assert_eq!((c & 0xffff) % 0xffff, 0);
        assert_eq!(swap_halves(0x1234_5678), 0x3412_7856);
    }
}
