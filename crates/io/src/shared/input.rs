//! Opening input files and streaming their samples in bounded chunks.

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

use crate::error::IoError;

/// Samples decoded per chunk: bounds the scratch memory beside the output.
const CHUNK_SAMPLES: usize = 1 << 16;

/// Opens `path` for reading and returns it with its length in bytes; a
/// path that is not a regular file (a directory, a FIFO, a device) is
/// refused without being opened.
pub(crate) fn open_input(path: &Path) -> Result<(File, u64), IoError> {
    // Checked before opening too: opening a FIFO for reading blocks until
    // a writer comes, so a header naming one as its data file would hang.
    let meta = std::fs::metadata(path).map_err(|e| IoError::os(path, "open", e))?;
    if !meta.is_file() {
        return Err(IoError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    let file = File::open(path).map_err(|e| IoError::os(path, "open", e))?;
    let meta = file
        .metadata()
        .map_err(|e| IoError::os(path, "read metadata of", e))?;
    if !meta.is_file() {
        return Err(IoError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    Ok((file, meta.len()))
}

/// Reads exactly `buf.len()` bytes; a short file is [`IoError::Truncated`].
/// `offset` is how many bytes of the expected total were read before, for
/// the message.
pub(crate) fn read_exact_at(
    path: &Path,
    reader: &mut impl Read,
    buf: &mut [u8],
    offset: u64,
    expected: u64,
) -> Result<(), IoError> {
    let mut done = 0;
    while done < buf.len() {
        match reader.read(&mut buf[done..]) {
            Ok(0) => {
                return Err(IoError::Truncated {
                    path: path.to_path_buf(),
                    read: offset + done as u64,
                    expected,
                });
            }
            Ok(n) => done += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(IoError::os(path, "read", e)),
        }
    }
    Ok(())
}

/// Reads `count` samples of `item_size` bytes each from `reader`, never
/// more, in chunks: `decode` turns each chunk (a whole number of samples)
/// into values (`f32`, or the type a volume keeps) appended to its scratch
/// vector, and `sink` receives them. `offset` is the position of the first
/// sample in the file (for messages).
pub(crate) fn read_samples<T>(
    path: &Path,
    reader: &mut impl Read,
    count: usize,
    item_size: usize,
    offset: u64,
    mut decode: impl FnMut(&[u8], &mut Vec<T>),
    mut sink: impl FnMut(&[T]),
) -> Result<(), IoError> {
    let expected = offset + (count as u64) * (item_size as u64);
    let chunk = CHUNK_SAMPLES.min(count);
    let mut bytes = vec![0u8; chunk * item_size];
    let mut values = Vec::with_capacity(chunk);
    let mut done = 0usize;
    while done < count {
        let n = chunk.min(count - done);
        let buf = &mut bytes[..n * item_size];
        let at = offset + (done as u64) * (item_size as u64);
        read_exact_at(path, reader, buf, at, expected)?;
        values.clear();
        decode(buf, &mut values);
        debug_assert_eq!(values.len(), n);
        sink(&values);
        done += n;
    }
    Ok(())
}
