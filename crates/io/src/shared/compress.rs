//! Inflating gzip and zlib payloads to exactly the size a header declares.
//!
//! A compressed stream is only trusted as far as its header: the output is
//! allocated for the declared size (which the caller has checked against
//! its limits), reading stops one byte past it, and a stream that inflates
//! to less or more is refused. A lying header can therefore neither make
//! volray allocate more than it declared nor hide extra data.

use std::io::Read;
use std::path::Path;

use flate2::read::{MultiGzDecoder, ZlibDecoder};

use crate::error::IoError;

/// The most bytes one byte of a deflate stream (zlib, gzip) can inflate
/// to: a 258-byte match costs at least two bits (RFC 1951), so about
/// 1032:1. A header that declares more than this many times its compressed
/// bytes is lying, and every reader refuses it before allocating.
pub const MAX_DEFLATE_RATIO: u64 = 1032;

/// The most bytes one byte of a bzip2 stream can decode to. A block holds
/// at most 900,000 bytes after the first run-length stage (libbzip2's
/// `nblockMAX` for `-9`), and that stage turns at most 5 bytes (4 equal
/// bytes and a count, which decoders take up to 255) into 259, so a block
/// decodes to at most 46,620,000 bytes; a block costs more than 21 bytes
/// (48-bit magic, 32-bit CRC, 1 + 24 bits, a symbol map of at least 32
/// bits, 18 bits of group and selector counts, a selector, two coding
/// tables of at least 8 bits, an end-of-block symbol: 173 bits). So no
/// stream decodes to more than 46,620,000 / 20 < 2,400,000 bytes per byte.
/// That bound refuses only absurd headers: bzip2 data is read
/// incrementally, the output growing only as data decodes and reading
/// stopped one byte past the declared size (payload/decode.rs).
pub const MAX_BZIP2_RATIO: u64 = 2_400_000;

/// The compressed encodings readers meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// gzip (RFC 1952), possibly several concatenated members (NRRD, `.nii.gz`).
    Gzip,
    /// zlib (RFC 1950): MetaImage `CompressedData`, VTK XML blocks.
    Zlib,
}

impl Compression {
    fn name(self) -> &'static str {
        match self {
            Compression::Gzip => "gzip",
            Compression::Zlib => "zlib",
        }
    }
}

/// Inflates `compressed` to exactly `expected` bytes. `what` names the
/// payload in messages ("data", "block 3").
pub fn inflate_exact(
    path: &Path,
    compressed: &[u8],
    kind: Compression,
    expected: usize,
    what: &str,
) -> Result<Vec<u8>, IoError> {
    let decoder: Box<dyn Read + '_> = match kind {
        Compression::Gzip => Box::new(MultiGzDecoder::new(compressed)),
        Compression::Zlib => Box::new(ZlibDecoder::new(compressed)),
    };
    if expected as u64 > (compressed.len() as u64).saturating_mul(MAX_DEFLATE_RATIO) {
        return Err(IoError::invalid(
            path,
            format!(
                "{what}: the header declares {expected} bytes, more than {} compressed bytes can inflate to",
                compressed.len()
            ),
        ));
    }
    let mut out = Vec::with_capacity(expected);
    let limit = expected as u64 + 1;
    decoder.take(limit).read_to_end(&mut out).map_err(|e| {
        IoError::invalid(path, format!("{what}: corrupt {} stream: {e}", kind.name()))
    })?;
    if out.len() < expected {
        return Err(IoError::invalid(
            path,
            format!(
                "{what}: {} stream inflates to {} bytes, but the header declares {expected}",
                kind.name(),
                out.len()
            ),
        ));
    }
    if out.len() > expected {
        return Err(IoError::invalid(
            path,
            format!(
                "{what}: {} stream inflates past the {expected} bytes the header declares",
                kind.name()
            ),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::write::{GzEncoder, ZlibEncoder};
    use std::io::Write;

    fn gz(bytes: &[u8]) -> Vec<u8> {
        let mut e = GzEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(bytes).unwrap();
        e.finish().unwrap()
    }

    #[test]
    fn exact_sizes_inflate_and_others_are_refused() {
        let data: Vec<u8> = (0..1000u32).map(|i| (i % 7) as u8).collect();
        let p = Path::new("v.nrrd");
        assert_eq!(
            inflate_exact(p, &gz(&data), Compression::Gzip, 1000, "data").unwrap(),
            data
        );
        let short = inflate_exact(p, &gz(&data), Compression::Gzip, 1001, "data").unwrap_err();
        assert!(
            short.to_string().contains("inflates to 1000 bytes"),
            "{short}"
        );
        let long = inflate_exact(p, &gz(&data), Compression::Gzip, 999, "data").unwrap_err();
        assert!(
            long.to_string().contains("inflates past the 999 bytes"),
            "{long}"
        );

        let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        z.write_all(&data).unwrap();
        let z = z.finish().unwrap();
        assert_eq!(
            inflate_exact(p, &z, Compression::Zlib, 1000, "block 0").unwrap(),
            data
        );
        let corrupt =
            inflate_exact(p, &z[..z.len() / 2], Compression::Zlib, 1000, "block 0").unwrap_err();
        assert!(!corrupt.is_io_failure());
        assert!(
            corrupt.to_string().starts_with("v.nrrd: block 0: "),
            "{corrupt}"
        );
    }

    #[test]
    fn concatenated_gzip_members_are_one_stream() {
        let mut two = gz(b"abc");
        two.extend(gz(b"def"));
        let out = inflate_exact(Path::new("f"), &two, Compression::Gzip, 6, "data").unwrap();
        assert_eq!(out, b"abcdef");
    }
}
