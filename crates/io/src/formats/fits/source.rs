//! Where a FITS file's bytes come from: the file itself, or the stream a
//! gzip file (`.fits.gz`, or any file starting with the gzip magic)
//! inflates to. Both are read front to back: headers block by block, data
//! skipped or read in chunks. A plain file's lengths are checked against
//! the file before anything is read; a gzip stream is only trusted as far
//! as it goes, so a header that lies about its data runs into the end of
//! the stream (one line, naming what was being read) instead of making
//! volray allocate what it claims.

use std::fs::File;
use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use flate2::read::MultiGzDecoder;

use crate::error::IoError;
use crate::shared::input::{open_input, read_exact_at};

/// The bytes of a FITS file, plain or inflated, and how far they were read.
pub(super) struct Source {
    reader: Reader,
    /// Bytes of the (inflated) file consumed so far.
    pub pos: u64,
    /// The file's length on disk.
    pub file_len: u64,
}

enum Reader {
    Plain(BufReader<File>),
    Gzip(Box<MultiGzDecoder<BufReader<File>>>),
    /// An image decompressed from its tiles (`tiled.rs`).
    Memory(io::Cursor<Vec<u8>>),
}

impl Source {
    /// Opens `path`, telling gzip from plain data by the gzip magic.
    pub(super) fn open(path: &Path) -> Result<Source, IoError> {
        let (mut file, file_len) = open_input(path)?;
        let mut magic = [0u8; 2];
        let is_gzip = file_len >= 2 && {
            read_exact_at(path, &mut file, &mut magic, 0, file_len)?;
            file.seek(SeekFrom::Start(0))
                .map_err(|e| IoError::os(path, "seek in", e))?;
            magic == [0x1f, 0x8b]
        };
        let reader = BufReader::new(file);
        let reader = if is_gzip {
            Reader::Gzip(Box::new(MultiGzDecoder::new(reader)))
        } else {
            Reader::Plain(reader)
        };
        Ok(Source {
            reader,
            pos: 0,
            file_len,
        })
    }

    /// The bytes of an image decompressed from its tiles, read as its
    /// file would be.
    pub(super) fn from_bytes(bytes: Vec<u8>) -> Source {
        let file_len = bytes.len() as u64;
        Source {
            reader: Reader::Memory(io::Cursor::new(bytes)),
            pos: 0,
            file_len,
        }
    }

    pub(super) fn is_gzip(&self) -> bool {
        matches!(self.reader, Reader::Gzip(_))
    }

    /// Whether the bytes are in memory, not the file's.
    pub(super) fn is_memory(&self) -> bool {
        matches!(self.reader, Reader::Memory(_))
    }

    /// Fills as much of `buf` as the file still holds: the number of
    /// bytes read, less than `buf.len()` only at the end of the file.
    /// `what` names what is read, for messages.
    pub(super) fn fill_some(
        &mut self,
        path: &Path,
        buf: &mut [u8],
        what: &str,
    ) -> Result<usize, IoError> {
        let mut done = 0;
        while done < buf.len() {
            let got = match &mut self.reader {
                Reader::Plain(r) => r.read(&mut buf[done..]),
                Reader::Gzip(r) => r.read(&mut buf[done..]),
                Reader::Memory(r) => r.read(&mut buf[done..]),
            };
            match got {
                Ok(0) => break,
                Ok(n) => done += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if self.is_gzip() => {
                    return Err(IoError::invalid(
                        path,
                        format!(
                            "{what}: corrupt gzip stream after {} bytes: {e}",
                            self.pos + done as u64
                        ),
                    ));
                }
                Err(e) => return Err(IoError::os(path, "read", e)),
            }
        }
        self.pos += done as u64;
        Ok(done)
    }

    /// Fills `buf`; a file that ends first is refused, naming `what`.
    pub(super) fn fill(&mut self, path: &Path, buf: &mut [u8], what: &str) -> Result<(), IoError> {
        let start = self.pos;
        let got = self.fill_some(path, buf, what)?;
        if got < buf.len() {
            return Err(IoError::invalid(
                path,
                format!(
                    "{what}: the {} ends after {} bytes, {} bytes short of the {} declared",
                    if self.is_gzip() {
                        "gzip stream"
                    } else {
                        "file"
                    },
                    start + got as u64,
                    buf.len() - got,
                    start + buf.len() as u64
                ),
            ));
        }
        Ok(())
    }

    /// Moves `n` bytes forward (`what` names them, for messages). A plain
    /// file seeks (its caller checked the length); a gzip stream is read
    /// through.
    pub(super) fn skip(&mut self, path: &Path, n: u64, what: &str) -> Result<(), IoError> {
        if n == 0 {
            return Ok(());
        }
        if let Reader::Plain(r) = &mut self.reader {
            let to = self.pos.checked_add(n).filter(|&to| to <= self.file_len);
            let Some(to) = to else {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "{what}: {n} bytes from byte {} run past the end of the {}-byte file",
                        self.pos, self.file_len
                    ),
                ));
            };
            r.seek(SeekFrom::Start(to))
                .map_err(|e| IoError::os(path, "seek in", e))?;
            self.pos = to;
            return Ok(());
        }
        let mut scratch = vec![0u8; n.min(1 << 16) as usize];
        let mut left = n;
        while left > 0 {
            let k = left.min(scratch.len() as u64) as usize;
            self.fill(path, &mut scratch[..k], what)?;
            left -= k as u64;
        }
        Ok(())
    }
}
