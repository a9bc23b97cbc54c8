//! FreeSurfer MGH volumes (`.mgh`) and their gzip-compressed form (`.mgz`).
//!
//! An MGH file is a 284-byte big-endian header (`header.rs`: dimensions,
//! type, voxel sizes, direction cosines and centre), then the samples,
//! big-endian, x fastest, one volume (frame) after another, then an
//! optional footer (TR, flip angle, TE, TI, FoV and tags) that volray does
//! not need. The reference is nibabel's `mghformat.py`; a small own parser
//! was written because no maintained crate reads MGH, and it is 90 bytes
//! of fixed fields.
//!
//! - world coordinates (RAS+, mm) come from nibabel's `get_affine`
//!   (`header.rs`) and go through [`grid_to_volume`];
//! - `dims[3]` frames: `--frame` picks one (each a contiguous block);
//! - an `.mgz` (any file starting with the gzip magic) is inflated as a
//!   stream: what the header implies must fit the deflate ratio of the
//!   compressed file before anything is allocated, and the output grows
//!   as data arrives, so a lying header meets the end of the stream.

mod header;

pub(crate) use self::header::sniff;

use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use flate2::read::MultiGzDecoder;

use self::header::{HEADER_LEN, parse, sample_type};
use crate::dtype::{Endian, Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::compress::MAX_DEFLATE_RATIO;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::{open_input, read_exact_at};
use crate::shared::limits::check_frame_dims;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Samples decoded per read: bounds the scratch buffer beside the output.
const CHUNK_SAMPLES: usize = 1 << 16;

/// Reads the MGH or MGZ file at `path` (see the module documentation).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (mut file, file_len) = open_input(path)?;
    let mut magic = [0u8; 2];
    let gzip = file_len >= 2 && {
        read_exact_at(path, &mut file, &mut magic, 0, file_len)?;
        file.seek(SeekFrom::Start(0))
            .map_err(|e| IoError::os(path, "seek in", e))?;
        magic == [0x1f, 0x8b]
    };
    let mut source: Box<dyn Read> = if gzip {
        Box::new(MultiGzDecoder::new(BufReader::new(file)))
    } else {
        Box::new(BufReader::new(file))
    };
    let mut stream = Stream {
        path,
        reader: &mut source,
        at: 0,
        gzip,
    };

    let mut bytes = [0u8; HEADER_LEN];
    stream
        .fill(&mut bytes, HEADER_LEN as u64)
        .map_err(|e| match e {
            IoError::Truncated { read, .. } => IoError::invalid(
                path,
                format!("file ends after {read} bytes, inside the {HEADER_LEN}-byte MGH header"),
            ),
            other => other,
        })?;
    let h = parse(&bytes);
    if h.version != 1 {
        return Err(IoError::invalid(
            path,
            format!(
                "MGH field \"version\" is {}: expected 1 (big-endian)",
                h.version
            ),
        ));
    }
    let (dtype, type_name) =
        sample_type(h.type_code).map_err(|reason| IoError::invalid(path, reason))?;
    if let Some(d) = h.dims.iter().find(|&&d| d < 1) {
        return Err(IoError::invalid(
            path,
            format!(
                "MGH field \"dims\" is {} {} {} {}: every dimension must be at least 1, not {d}",
                h.dims[0], h.dims[1], h.dims[2], h.dims[3]
            ),
        ));
    }
    let [w, ht, d, nframes] = h.dims.map(|x| x as usize);
    let frame = opts.frame.unwrap_or(0);
    if frame >= nframes {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the file holds {nframes} frame{} (dims[3]), numbered from 0",
                if nframes == 1 { "" } else { "s" }
            ),
        ));
    }
    // Sizes in u128: four i32 dimensions times 4 bytes cannot overflow it.
    let size = dtype.size();
    let frame_bytes = (w as u128) * (ht as u128) * (d as u128) * size as u128;
    let start = HEADER_LEN as u128;
    let needed_all = start + frame_bytes * nframes as u128;
    let needed = start + frame_bytes * (frame as u128 + 1);
    let dims_text = format!("{w} {ht} {d} {nframes}");
    if gzip {
        if needed > u128::from(file_len) * u128::from(MAX_DEFLATE_RATIO) {
            return Err(IoError::invalid(
                path,
                format!(
                    "the MGH header (dims {dims_text}, {type_name}) implies {needed} bytes, more than a {file_len}-byte gzip file can hold"
                ),
            ));
        }
    } else if u128::from(file_len) < needed_all {
        return Err(IoError::invalid(
            path,
            format!(
                "file is {file_len} bytes, but the MGH header (dims {dims_text}, {type_name}) implies {needed_all}"
            ),
        ));
    }
    let dims = [w, ht, d];
    let mut all_dims = dims.to_vec();
    all_dims.push(nframes);
    let stored = dtype.stored();
    check_frame_dims(
        path,
        "MGH field \"dims\"",
        &all_dims,
        nframes,
        stored.bytes() as u64,
        opts.max_memory,
    )?;

    let mut info = FileInfo::new(format!("{type_name} (big-endian)"));
    info.header = h.fields();
    info.frames = nframes;
    info.frame = frame;
    info.length_unit = Some("mm".to_string());
    info.notes.push(if gzip {
        "FreeSurfer MGZ: an MGH file compressed with gzip".to_string()
    } else {
        "FreeSurfer MGH".to_string()
    });
    if nframes > 1 && opts.frame.is_none() {
        info.notes.push(format!(
            "the file holds {nframes} frames (dims[3]); frame 0 was read"
        ));
    }

    // The wanted frame: skip the ones before it, then read it in chunks.
    let frame_start = (start + frame_bytes * frame as u128) as u64;
    stream.skip_to(frame_start, needed as u64)?;
    let count = w * ht * d;
    let data = read_as_stored!(stored, |T| {
        let mut data: Vec<T> = Vec::with_capacity(if gzip {
            count.min(CHUNK_SAMPLES)
        } else {
            count
        });
        let mut chunk = vec![0u8; count.min(CHUNK_SAMPLES) * size];
        let mut done = 0;
        let mut result = Ok(());
        while done < count && result.is_ok() {
            let n = (count - done).min(CHUNK_SAMPLES);
            result = stream.fill(&mut chunk[..n * size], needed as u64);
            T::extend(&mut data, &chunk[..n * size], dtype, Endian::Big);
            done += n;
        }
        result.map(|()| data)
    })?;

    let (steps, origin, note) = h.affine(path)?;
    info.notes.extend(note);
    info.notes.push(format!(
        "world coordinates (RAS+, mm) as nibabel's get_affine: Mdc.T * delta, centre Pxyz_c ({}, {}, {}) at voxel dims/2",
        h.pxyz_c[0], h.pxyz_c[1], h.pxyz_c[2]
    ));
    let volume = grid_to_volume(path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Mgh,
        info,
    })
}

/// The file's bytes after the magic check, plain or inflated, with the
/// position read so far for messages.
struct Stream<'a> {
    path: &'a Path,
    reader: &'a mut Box<dyn Read>,
    at: u64,
    gzip: bool,
}

impl Stream<'_> {
    /// Fills `buf`; `expected` is what the header implies in all, for
    /// messages.
    fn fill(&mut self, buf: &mut [u8], expected: u64) -> Result<(), IoError> {
        if !self.gzip {
            read_exact_at(self.path, self.reader, buf, self.at, expected)?;
            self.at += buf.len() as u64;
            return Ok(());
        }
        let mut done = 0;
        while done < buf.len() {
            match self.reader.read(&mut buf[done..]) {
                Ok(0) => {
                    return Err(IoError::invalid(
                        self.path,
                        format!(
                            "gzip data ends after {} bytes, but the MGH header implies at least {expected}",
                            self.at + done as u64
                        ),
                    ));
                }
                Ok(n) => done += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(IoError::invalid(
                        self.path,
                        format!(
                            "corrupt gzip stream after {} bytes: {e}",
                            self.at + done as u64
                        ),
                    ));
                }
            }
        }
        self.at += buf.len() as u64;
        Ok(())
    }

    /// Reads and drops bytes up to position `to`.
    fn skip_to(&mut self, to: u64, expected: u64) -> Result<(), IoError> {
        let mut scratch = vec![0u8; ((to - self.at) as usize).min(1 << 16)];
        while self.at < to {
            let k = ((to - self.at) as usize).min(scratch.len());
            self.fill(&mut scratch[..k], expected)?;
        }
        Ok(())
    }
}
