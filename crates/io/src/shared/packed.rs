//! Files behind gzip, bzip2 or xz (`.cube.gz`, `CHGCAR.bz2`, `grid.dx.xz`),
//! known by their first bytes, not their names, and read as the stream
//! they decompress to: the text formats (cube, CHGCAR, legacy VTK, OpenDX,
//! XSF), gOpenMol `.plt`, GIPL and MRtrix take their input through [`open_unpacked`],
//! which hands a plain file through unchanged.
//!
//! Nothing is decompressed whole: the readers stream numbers out of the
//! decompressed bytes as they come, so the memory a compressed file takes
//! is what its header declares, checked against `--max-memory` before
//! anything is allocated, as for a plain file. Where a reader bounds a
//! header's counts by the file's length, [`Opened::len`] is the most the
//! compressed stream can decode to: its length times the codec's largest
//! ratio (deflate 1032:1, bzip2 2,400,000:1, see `compress.rs`), and for
//! xz, which has no useful bound, [`XZ_TEXT_RATIO`] times, enforced: the
//! stream is refused as it passes that many bytes. A gzip bomb therefore
//! costs time in proportion to its decompressed size, never memory.
//!
//! Corrupt streams are bad input, not a failure of the system: the
//! decoders' errors come out as `CorruptStream` (error.rs), which
//! [`IoError::os`](crate::IoError) words as an invalid file.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Seek, SeekFrom};
use std::num::NonZeroUsize;
use std::path::Path;

use bzip2::read::MultiBzDecoder;
use flate2::read::MultiGzDecoder;

use crate::error::{CorruptStream, IoError};
use crate::shared::compress::{MAX_BZIP2_RATIO, MAX_DEFLATE_RATIO, MAX_XZ_DICT};
use crate::shared::input::open_input;

/// The most bytes one byte of an xz file may decompress to here. LZMA has
/// no useful bound (a repeated match costs far less than a bit), so this
/// is a limit, not a property of the codec: text of numbers compresses
/// about 5:1 to 20:1, a file of one repeated value a few thousand to one.
pub(crate) const XZ_TEXT_RATIO: u64 = 1 << 16;

/// The compressions a file may be wrapped in, by their magic numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Packing {
    /// gzip (RFC 1952): `1f 8b`.
    Gzip,
    /// bzip2: `BZh` and the block size digit.
    Bzip2,
    /// xz: `fd 37 7a 58 5a 00`.
    Xz,
}

impl Packing {
    /// The packing a file's first bytes show, if any.
    pub(crate) fn of(head: &[u8]) -> Option<Packing> {
        if head.starts_with(b"\x1f\x8b") {
            Some(Packing::Gzip)
        } else if head.len() >= 4 && head.starts_with(b"BZh") && (b'1'..=b'9').contains(&head[3]) {
            Some(Packing::Bzip2)
        } else if head.starts_with(b"\xfd7zXZ\0") {
            Some(Packing::Xz)
        } else {
            None
        }
    }

    /// The codec's name in messages.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Packing::Gzip => "gzip",
            Packing::Bzip2 => "bzip2",
            Packing::Xz => "xz",
        }
    }

    /// The command that decompresses such a file, for messages.
    pub(crate) fn tool(self) -> &'static str {
        match self {
            Packing::Gzip => "gunzip -k",
            Packing::Bzip2 => "bunzip2 -k",
            Packing::Xz => "unxz -k",
        }
    }

    /// The most bytes one compressed byte is taken to decode to.
    fn ratio(self) -> u64 {
        match self {
            Packing::Gzip => MAX_DEFLATE_RATIO,
            Packing::Bzip2 => MAX_BZIP2_RATIO,
            Packing::Xz => XZ_TEXT_RATIO,
        }
    }

    /// A decoder of this packing reading from `inner`.
    fn decoder<R: Read + Send + 'static>(self, inner: R) -> Box<dyn Read + Send> {
        match self {
            Packing::Gzip => Box::new(MultiGzDecoder::new(inner)),
            Packing::Bzip2 => Box::new(MultiBzDecoder::new(inner)),
            Packing::Xz => Box::new(xz4rust::XzReader::new_with_buffer_size_and_decoder(
                inner,
                NonZeroUsize::new(1 << 16).expect("non-zero"),
                xz4rust::XzDecoder::in_heap_with_alloc_dict_size(4096, MAX_XZ_DICT),
            )),
        }
    }
}

/// A file opened for streaming: its bytes, or the bytes it decompresses to.
pub(crate) struct Opened {
    pub reader: Unpacked,
    /// The file's length, or the most its compressed stream can decode to
    /// (see the module docs): what a header's counts are bounded by.
    pub len: u64,
    pub packing: Option<Packing>,
    /// The file's length on disk.
    pub file_len: u64,
}

impl Opened {
    /// The file's size as messages bounding a header's counts say it:
    /// `"2048-byte file"`, or for a compressed one `"512-byte gzip file
    /// (at most 528384 bytes decompressed)"`.
    pub(crate) fn size_phrase(&self) -> String {
        match self.packing {
            None => format!("{}-byte file", self.len),
            Some(p) => format!(
                "{}-byte {} file (at most {} bytes decompressed)",
                self.file_len,
                p.name(),
                self.len
            ),
        }
    }

    /// The note a reader adds to its `FileInfo` for a compressed file.
    pub(crate) fn note(&self) -> Option<String> {
        self.packing.map(|p| {
            format!(
                "read through {} decompression (the file is {}-compressed)",
                p.name(),
                p.name()
            )
        })
    }
}

/// Opens `path`, decompressing it as it is read if its first bytes show
/// gzip, bzip2 or xz.
pub(crate) fn open_unpacked(path: &Path) -> Result<Opened, IoError> {
    let (file, file_len) = open_input(path)?;
    let mut plain = BufReader::new(file);
    let head = plain.fill_buf().map_err(|e| IoError::os(path, "read", e))?;
    let Some(packing) = Packing::of(head) else {
        return Ok(Opened {
            reader: Unpacked {
                inner: Inner::Plain(plain),
                pos: 0,
                limit: u64::MAX,
                packing: None,
            },
            len: file_len,
            packing: None,
            file_len,
        });
    };
    let len = file_len.saturating_mul(packing.ratio());
    let decoded = BufReader::new(packing.decoder(plain));
    Ok(Opened {
        reader: Unpacked {
            inner: Inner::Decoded(decoded),
            pos: 0,
            limit: len,
            packing: Some(packing),
        },
        len,
        packing: Some(packing),
        file_len,
    })
}

/// The bytes a file's first bytes `head` decompress to (at most 1024), if
/// they open a gzip, bzip2 or xz stream: what the formats' sniffers look
/// at. A stream cut short by `head`'s end yields what it could.
pub(crate) fn unpack_head(head: &[u8]) -> Option<Vec<u8>> {
    let packing = Packing::of(head)?;
    let mut out = Vec::with_capacity(1024);
    let mut decoder = packing.decoder(io::Cursor::new(head.to_vec())).take(1024);
    let mut buf = [0u8; 256];
    while let Ok(n) = decoder.read(&mut buf) {
        if n == 0 {
            break;
        }
        out.extend_from_slice(&buf[..n]);
    }
    Some(out)
}

/// The first bytes (at most 1024) the file at `path` decompresses to, if
/// its first bytes `head` open a gzip, bzip2 or xz stream; read from the
/// file, not `head`, since a bzip2 stream yields nothing before its first
/// block (up to 900 kB) is whole. `None` for a plain file, or where the
/// file cannot be read (the reader then says why).
pub(crate) fn unpack_file_head(path: &Path, head: &[u8]) -> Option<Vec<u8>> {
    let packing = Packing::of(head)?;
    let (file, _) = open_input(path).ok()?;
    let mut decoder = packing.decoder(BufReader::new(file)).take(1024);
    let mut out = Vec::with_capacity(1024);
    let mut buf = [0u8; 256];
    while let Ok(n) = decoder.read(&mut buf) {
        if n == 0 {
            break;
        }
        out.extend_from_slice(&buf[..n]);
    }
    Some(out)
}

/// A file's bytes, plain or decompressed, read front to back: `BufRead`,
/// and `Seek` forward from where it is (`SeekFrom::Current` of zero or
/// more: a compressed stream skips by decoding), which is all the legacy
/// VTK reader's skips of unwanted arrays ask; a plain file seeks freely.
pub(crate) struct Unpacked {
    inner: Inner,
    /// Decompressed bytes consumed so far.
    pos: u64,
    /// The most decompressed bytes read before the stream is refused.
    limit: u64,
    packing: Option<Packing>,
}

enum Inner {
    Plain(BufReader<File>),
    Decoded(BufReader<Box<dyn Read + Send>>),
}

impl Unpacked {
    /// A decoder's error as bad input ([`CorruptStream`]); the system's
    /// own failures pass as they are.
    fn corrupt(&self, e: io::Error) -> io::Error {
        match self.packing {
            Some(p)
                if e.kind() != io::ErrorKind::Interrupted
                    && e.get_ref().is_none_or(|r| !r.is::<CorruptStream>()) =>
            {
                let os = e.raw_os_error().is_some();
                if os {
                    e
                } else {
                    io::Error::new(
                        io::ErrorKind::InvalidData,
                        CorruptStream(format!(
                            "corrupt {} stream after {} decompressed bytes: {e}",
                            p.name(),
                            self.pos
                        )),
                    )
                }
            }
            _ => e,
        }
    }

    fn over_limit(&self) -> io::Error {
        let p = self.packing.map_or("", Packing::name);
        io::Error::new(
            io::ErrorKind::InvalidData,
            CorruptStream(format!(
                "the {p} stream decompresses to more than {} bytes, more than its {} compressed bytes are taken to hold",
                self.limit,
                self.limit / self.packing.map_or(1, Packing::ratio)
            )),
        )
    }
}

impl Read for Unpacked {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = {
            let available = self.fill_buf()?;
            let n = available.len().min(buf.len());
            buf[..n].copy_from_slice(&available[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for Unpacked {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if self.pos > self.limit {
            return Err(self.over_limit());
        }
        if let Inner::Decoded(r) = &mut self.inner
            && let Err(e) = r.fill_buf()
        {
            return Err(self.corrupt(e));
        }
        // Filled above for a decoded stream (so this does not decode).
        match &mut self.inner {
            Inner::Plain(r) => r.fill_buf(),
            Inner::Decoded(r) => r.fill_buf(),
        }
    }

    fn consume(&mut self, amount: usize) {
        self.pos += amount as u64;
        match &mut self.inner {
            Inner::Plain(r) => r.consume(amount),
            Inner::Decoded(r) => r.consume(amount),
        }
    }
}

impl Seek for Unpacked {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        match (&mut self.inner, to) {
            (Inner::Plain(r), to) => {
                let at = r.seek(to)?;
                self.pos = at;
                Ok(at)
            }
            (Inner::Decoded(_), SeekFrom::Current(n)) if n >= 0 => {
                let mut left = n as u64;
                while left > 0 {
                    let available = self.fill_buf()?.len();
                    if available == 0 {
                        break;
                    }
                    let step = (available as u64).min(left) as usize;
                    self.consume(step);
                    left -= step as u64;
                }
                // Past the end, as a file's seek allows: later reads find
                // nothing there.
                self.pos += left;
                Ok(self.pos)
            }
            (Inner::Decoded(_), _) => Err(io::Error::new(
                io::ErrorKind::Unsupported,
                "a compressed stream is read front to back only",
            )),
        }
    }

    fn seek_relative(&mut self, offset: i64) -> io::Result<()> {
        match &mut self.inner {
            Inner::Plain(r) => {
                r.seek_relative(offset)?;
                self.pos = self.pos.wrapping_add_signed(offset);
                Ok(())
            }
            Inner::Decoded(_) => self.seek(SeekFrom::Current(offset)).map(|_| ()),
        }
    }

    fn stream_position(&mut self) -> io::Result<u64> {
        match &mut self.inner {
            Inner::Plain(r) => r.stream_position(),
            Inner::Decoded(_) => Ok(self.pos),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(bytes).unwrap();
        e.finish().unwrap()
    }

    fn bzip2(bytes: &[u8]) -> Vec<u8> {
        let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::default());
        e.write_all(bytes).unwrap();
        e.finish().unwrap()
    }

    fn read_all(path: &Path) -> Result<(Vec<u8>, Option<Packing>), IoError> {
        let mut o = open_unpacked(path)?;
        let mut out = Vec::new();
        o.reader
            .read_to_end(&mut out)
            .map_err(|e| IoError::os(path, "read", e))?;
        Ok((out, o.packing))
    }

    #[test]
    fn plain_gzip_and_bzip2_files_read_as_their_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let text: Vec<u8> = (0..5000)
            .flat_map(|i| format!("{i} ").into_bytes())
            .collect();
        for (name, bytes, packing) in [
            ("plain", text.clone(), None),
            ("gz", gzip(&text), Some(Packing::Gzip)),
            ("bz2", bzip2(&text), Some(Packing::Bzip2)),
        ] {
            let path = dir.path().join(name);
            std::fs::write(&path, &bytes).unwrap();
            assert_eq!(read_all(&path).unwrap(), (text.clone(), packing), "{name}");
            assert_eq!(unpack_head(&bytes).map(|h| h.len()), packing.map(|_| 1024));
        }
    }

    #[test]
    fn a_compressed_stream_seeks_forward_only() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.gz");
        let bytes: Vec<u8> = (0..100_000u32).map(|i| (i % 251) as u8).collect();
        std::fs::write(&path, gzip(&bytes)).unwrap();
        let mut o = open_unpacked(&path).unwrap();
        o.reader.seek_relative(70_000).unwrap();
        let mut b = [0u8; 3];
        o.reader.read_exact(&mut b).unwrap();
        assert_eq!(b, [bytes[70_000], bytes[70_001], bytes[70_002]]);
        assert_eq!(o.reader.stream_position().unwrap(), 70_003);
        assert!(o.reader.seek(SeekFrom::Start(0)).is_err());
    }

    #[test]
    fn a_corrupt_stream_is_bad_input_naming_the_codec() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.gz");
        let mut bytes = gzip(&vec![b'7'; 100_000]);
        let n = bytes.len();
        for b in &mut bytes[12..n - 8] {
            *b = 0xff;
        }
        std::fs::write(&path, &bytes).unwrap();
        let err = read_all(&path).unwrap_err();
        assert!(!err.is_io_failure(), "{err}");
        let msg = err.to_string();
        assert!(msg.contains("corrupt gzip stream"), "{msg}");
        assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    }
}
