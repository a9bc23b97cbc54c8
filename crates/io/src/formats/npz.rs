//! NumPy `.npz` archives: the zip files `numpy.savez` (members stored) and
//! `numpy.savez_compressed` (members deflated) write, one `.npy` member
//! per array (`arr_0.npy`, `arr_1.npy`, ... for positional arrays, or the
//! keyword's name).
//!
//! The archive is read with the `zip` crate (built with deflate only); each
//! member is streamed through the `.npy` reader (`npy/`), which checks its
//! header against the member's declared size and `--max-memory` before
//! allocating and reads `a[x, y, z]` as a `.npy` file is read. A deflated
//! member declaring more than 1032 times its compressed size is refused
//! before it is read, and a member that decompresses to other than its
//! declared size or fails its CRC is refused as corrupt.
//!
//! Arrays are named as `np.load` names them (the member less `.npy`):
//! `--array NAME` picks one, the first in the archive by default, with a
//! note listing them all. Spacing 1 and origin 0, as for `.npy`.

use std::io::{self, BufReader, Read};
use std::path::Path;

use zip::result::ZipError;
use zip::{CompressionMethod, ZipArchive};

use crate::error::{CorruptStream, IoError};
use crate::formats::npy;
use crate::shared::compress::MAX_DEFLATE_RATIO;
use crate::shared::input::open_input;
use crate::{Loaded, ReadOptions, VolumeFormat};

/// Reads the `.npz` archive at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (file, file_len) = open_input(path)?;
    let zip_error = |what: &str, e: ZipError| match e {
        ZipError::Io(e) if e.raw_os_error().is_some() => IoError::os(path, "read", e),
        e => IoError::invalid(path, format!("{what}: {e}")),
    };
    let mut archive = ZipArchive::new(BufReader::new(file))
        .map_err(|e| zip_error("not a readable .npz (zip) archive", e))?;

    // The arrays: every member named *.npy, in archive order.
    let mut arrays: Vec<(usize, String)> = Vec::new();
    for i in 0..archive.len() {
        if let Some(Ok(name)) = archive.name_for_index(i)
            && let Some(array) = name.strip_suffix(".npy")
        {
            arrays.push((i, array.to_string()));
        }
    }
    let names: Vec<String> = arrays.iter().map(|(_, n)| n.clone()).collect();
    let listed = || {
        names
            .iter()
            .map(|n| format!("\"{n}\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let chosen = match &opts.array {
        Some(want) => arrays.iter().find(|(_, n)| n == want).ok_or_else(|| {
            IoError::no_such_array(
                path,
                want,
                if names.is_empty() {
                    "the archive holds no .npy arrays".to_string()
                } else {
                    format!("the archive holds the arrays {}", listed())
                },
            )
        })?,
        None => arrays.first().ok_or_else(|| {
            IoError::invalid(
                path,
                format!(
                    "the zip archive holds no .npy arrays ({} members): not an .npz file as numpy.savez writes it",
                    archive.len()
                ),
            )
        })?,
    };
    let (index, name) = chosen.clone();

    let member = archive
        .by_index(index)
        .map_err(|e| zip_error(&format!("array \"{name}\""), e))?;
    let (size, packed) = (member.size(), member.compressed_size());
    let method = member.compression();
    match method {
        CompressionMethod::Stored if size != packed || size > file_len => {
            return Err(IoError::invalid(
                path,
                format!(
                    "array \"{name}\": a stored member of {packed} bytes declares {size} bytes"
                ),
            ));
        }
        CompressionMethod::Deflated if size > packed.saturating_mul(MAX_DEFLATE_RATIO) => {
            return Err(IoError::invalid(
                path,
                format!(
                    "array \"{name}\": the member declares {size} bytes, more than its {packed} deflated bytes can decode to"
                ),
            ));
        }
        CompressionMethod::Stored | CompressionMethod::Deflated => {}
        other => {
            return Err(IoError::invalid(
                path,
                format!(
                    "array \"{name}\" is compressed with {other}, which volray does not read (numpy.savez stores members, savez_compressed deflates them)"
                ),
            ));
        }
    }
    let mut reader = Member {
        inner: member,
        name: &name,
    };
    let (volume, mut info) = npy::read_stream(path, &mut reader, size, opts.max_memory)?;
    info.notes.insert(
        0,
        format!(
            "array \"{name}\" ({}) of the {} the archive holds: {}{}",
            if opts.array.is_some() {
                "the one asked for"
            } else {
                "the first"
            },
            names.len(),
            listed(),
            if names.len() > 1 {
                " (pick one with --array)"
            } else {
                ""
            }
        ),
    );
    info.header.insert(
        0,
        (
            "member".into(),
            format!(
                "{name}.npy, {} ({packed} bytes in the archive)",
                if method == CompressionMethod::Stored {
                    "stored"
                } else {
                    "deflated"
                }
            ),
        ),
    );
    info.arrays = names.clone();
    info.array = Some(name);
    Ok(Loaded {
        volume,
        format: VolumeFormat::Npz,
        info,
    })
}

/// A member's bytes, its decoder's complaints (a bad CRC, a stream that
/// ends early or runs long) made bad input rather than I/O failures.
struct Member<'n, R: Read> {
    inner: R,
    name: &'n str,
}

impl<R: Read> Read for Member<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.inner.read(buf).map_err(|e| {
            if e.raw_os_error().is_some() || e.kind() == io::ErrorKind::Interrupted {
                e
            } else {
                io::Error::new(
                    io::ErrorKind::InvalidData,
                    CorruptStream(format!("array \"{}\": corrupt member: {e}", self.name)),
                )
            }
        })
    }
}
