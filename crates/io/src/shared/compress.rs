//! Decompressing gzip, zlib, LZ4-block, LZF and xz payloads to exactly the
//! size a header declares.
//!
//! A compressed stream is only trusted as far as its header: a declared
//! size beyond the codec's largest ratio is refused before decoding, the
//! output is allocated for the declared size (which the caller has checked
//! against its limits) or grows as data decodes, decoding stops one byte
//! past it, and a stream that decodes to less or more is refused. A lying
//! header can therefore neither make volray allocate more than it declared
//! nor hide extra data.
//!
//! LZ4 blocks (VTK's vtkLZ4DataCompressor: `LZ4_compress_fast`, the raw
//! block format without frame) are decoded by `lz4_flex`'s safe decoder
//! into a buffer of the declared size; LZF streams (HDF5's filter 32000,
//! h5py's `compression="lzf"`: liblzf's raw token stream, no header) by
//! `lzf-rust`'s decoder (pure Rust, `#![forbid(unsafe_code)]`; the crate
//! `lzf` is deprecated) likewise. xz streams (vtkLZMADataCompressor:
//! `lzma_easy_buffer_encode`, one stream per block) by `xz4rust`, a
//! pure-Rust port of xz-embedded built without `unsafe`: it decodes into
//! a small buffer the output grows from, checks the stream's CRC, and
//! allocates its dictionary once per [`Decompressor`] (reused across an
//! array's blocks) at the size the stream declares, refused past
//! [`MAX_XZ_DICT`]. lzma-rs was weighed and not taken: it keeps a whole
//! LZMA2 block's output in memory before passing any on, so a small
//! hostile block could grow without bound before the size check.

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

/// The most bytes one byte of an LZ4 block can decode to: a match costs a
/// token and a 2-byte offset and gives at most 19 bytes, each further
/// length byte adds at most 255 (LZ4 block format, "Sequence"); literals
/// are 1:1. So the output never exceeds 255 times the input.
pub const MAX_LZ4_RATIO: u64 = 255;

/// The most bytes one byte of an LZF stream can decode to: a literal run
/// decodes 1:1 (plus its control byte), a back-reference of 2 bytes gives
/// at most 8 bytes and one of 3 bytes (the extended length) at most
/// 7 + 255 + 2 = 264 (liblzf's `lzf_d.c` token format), so 88:1.
pub const MAX_LZF_RATIO: u64 = 88;

/// The largest xz dictionary volray allocates: xz's `-9` preset (64 MiB),
/// the largest that `lzma_easy_buffer_encode` (VTK's writer) uses. An xz
/// block header declaring more is refused before anything is allocated.
pub const MAX_XZ_DICT: usize = 64 << 20;

/// Output bytes decoded at a time from an xz stream.
const XZ_CHUNK: usize = 1 << 16;

/// The compressed encodings readers meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// gzip (RFC 1952), possibly several concatenated members (NRRD, `.nii.gz`).
    Gzip,
    /// zlib (RFC 1950): MetaImage `CompressedData`, VTK XML blocks.
    Zlib,
    /// LZ4 block format (no frame): VTK XML `vtkLZ4DataCompressor` blocks.
    Lz4Block,
    /// xz (.xz container, LZMA2): VTK XML `vtkLZMADataCompressor` blocks.
    Xz,
    /// LZF (liblzf's raw token stream): HDF5 chunks of h5py's filter 32000.
    Lzf,
}

impl Compression {
    /// The codec's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Compression::Gzip => "gzip",
            Compression::Zlib => "zlib",
            Compression::Lz4Block => "LZ4",
            Compression::Xz => "xz",
            Compression::Lzf => "LZF",
        }
    }

    /// The most bytes one compressed byte can decode to, where the format
    /// bounds it usefully; `None` for xz (LZMA's range coder spends far
    /// less than a bit on a repeated match), whose declared sizes are
    /// bounded by the caller's memory limit and whose output grows only as
    /// data decodes.
    pub fn max_ratio(self) -> Option<u64> {
        match self {
            Compression::Gzip | Compression::Zlib => Some(MAX_DEFLATE_RATIO),
            Compression::Lz4Block => Some(MAX_LZ4_RATIO),
            Compression::Lzf => Some(MAX_LZF_RATIO),
            Compression::Xz => None,
        }
    }
}

/// Decodes `compressed` to exactly `expected` bytes. `what` names the
/// payload in messages ("data", "block 3").
pub fn inflate_exact(
    path: &Path,
    compressed: &[u8],
    kind: Compression,
    expected: usize,
    what: &str,
) -> Result<Vec<u8>, IoError> {
    Decompressor::new(kind).decode_exact(path, compressed, expected, what)
}

/// Decodes payloads of one codec in turn (an array's blocks), keeping
/// what can be reused between them (the xz dictionary).
pub struct Decompressor {
    kind: Compression,
    xz: Option<Box<xz4rust::XzDecoder<'static>>>,
}

impl Decompressor {
    pub fn new(kind: Compression) -> Self {
        Decompressor { kind, xz: None }
    }

    /// Decodes `compressed` to exactly `expected` bytes, as [`inflate_exact`].
    pub fn decode_exact(
        &mut self,
        path: &Path,
        compressed: &[u8],
        expected: usize,
        what: &str,
    ) -> Result<Vec<u8>, IoError> {
        let kind = self.kind;
        if let Some(ratio) = kind.max_ratio()
            && expected as u64 > (compressed.len() as u64).saturating_mul(ratio)
        {
            return Err(IoError::invalid(
                path,
                format!(
                    "{what}: the header declares {expected} bytes, more than {} {} bytes can decode to",
                    compressed.len(),
                    kind.name()
                ),
            ));
        }
        match kind {
            Compression::Gzip => {
                read_exact(path, MultiGzDecoder::new(compressed), kind, expected, what)
            }
            Compression::Zlib => {
                read_exact(path, ZlibDecoder::new(compressed), kind, expected, what)
            }
            Compression::Lz4Block => lz4_exact(path, compressed, expected, what),
            Compression::Lzf => lzf_exact(path, compressed, expected, what),
            Compression::Xz => {
                let decoder = self.xz.get_or_insert_with(|| {
                    xz4rust::XzDecoder::in_heap_with_alloc_dict_size(4096, MAX_XZ_DICT)
                });
                decoder.reset();
                xz_exact(path, decoder, compressed, expected, what)
            }
        }
    }
}

/// An LZ4 block decoded into exactly `expected` bytes (bounded by
/// [`MAX_LZ4_RATIO`] before this allocates them).
fn lz4_exact(
    path: &Path,
    compressed: &[u8],
    expected: usize,
    what: &str,
) -> Result<Vec<u8>, IoError> {
    let mut out = vec![0u8; expected];
    match lz4_flex::block::decompress_into(compressed, &mut out) {
        Ok(n) if n == expected => Ok(out),
        Ok(n) => Err(IoError::invalid(
            path,
            format!("{what}: LZ4 block decodes to {n} bytes, but the header declares {expected}"),
        )),
        Err(lz4_flex::block::DecompressError::OutputTooSmall { .. }) => Err(IoError::invalid(
            path,
            format!("{what}: LZ4 block decodes past the {expected} bytes the header declares"),
        )),
        Err(e) => Err(IoError::invalid(
            path,
            format!("{what}: corrupt LZ4 block: {e}"),
        )),
    }
}

/// An LZF stream decoded into exactly `expected` bytes (bounded by
/// [`MAX_LZF_RATIO`] before this allocates them). `lzf-rust` stops at the
/// buffer's end: a stream that would write past it is refused, whichever
/// token it is in.
fn lzf_exact(
    path: &Path,
    compressed: &[u8],
    expected: usize,
    what: &str,
) -> Result<Vec<u8>, IoError> {
    let mut out = vec![0u8; expected];
    match lzf_rust::decompress(compressed, &mut out) {
        Ok(n) if n == expected => Ok(out),
        Ok(n) => Err(IoError::invalid(
            path,
            format!("{what}: LZF stream decodes to {n} bytes, but the header declares {expected}"),
        )),
        Err(lzf_rust::Error::OutputTooSmall) => Err(IoError::invalid(
            path,
            format!("{what}: LZF stream decodes past the {expected} bytes the header declares"),
        )),
        Err(e) => Err(IoError::invalid(
            path,
            format!(
                "{what}: corrupt LZF stream: {e} (or one decoding past the {expected} bytes the header declares)"
            ),
        )),
    }
}

/// An xz stream decoded to exactly `expected` bytes, the output growing
/// only as the stream yields data.
fn xz_exact(
    path: &Path,
    decoder: &mut xz4rust::XzDecoder<'static>,
    mut input: &[u8],
    expected: usize,
    what: &str,
) -> Result<Vec<u8>, IoError> {
    let mut out = Vec::with_capacity(expected.min(XZ_CHUNK));
    let mut chunk = vec![0u8; XZ_CHUNK];
    loop {
        let r = decoder.decode(input, &mut chunk).map_err(|e| {
            let why = match e {
                xz4rust::XzError::DictionaryTooLarge(n) => format!(
                    "its dictionary of {n} bytes is larger than volray allows ({MAX_XZ_DICT})"
                ),
                e => format!("{e}"),
            };
            IoError::invalid(path, format!("{what}: corrupt xz stream: {why}"))
        })?;
        input = &input[r.input_consumed()..];
        out.extend_from_slice(&chunk[..r.output_produced()]);
        if out.len() > expected {
            return Err(IoError::invalid(
                path,
                format!("{what}: xz stream decodes past the {expected} bytes the header declares"),
            ));
        }
        if r.is_end_of_stream() {
            break;
        }
        if !r.made_progress() {
            return Err(IoError::invalid(
                path,
                format!(
                    "{what}: corrupt xz stream: it ends after {} bytes, before its end marker",
                    out.len()
                ),
            ));
        }
    }
    if out.len() < expected {
        return Err(IoError::invalid(
            path,
            format!(
                "{what}: xz stream decodes to {} bytes, but the header declares {expected}",
                out.len()
            ),
        ));
    }
    Ok(out)
}

/// A deflate stream read to exactly `expected` bytes.
fn read_exact(
    path: &Path,
    decoder: impl Read,
    kind: Compression,
    expected: usize,
    what: &str,
) -> Result<Vec<u8>, IoError> {
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
    fn lzf_streams_decode_to_exactly_their_size_and_others_are_refused() {
        // A literal run of 3 ("abc": control 2), then a back-reference of
        // 4 + 2 = 6 bytes at distance 2 + 1 = 3 (control 4 << 5, offset 2).
        let stream = [2, b'a', b'b', b'c', 4 << 5, 2];
        let p = Path::new("v.h5");
        let lzf = |expected| inflate_exact(p, &stream, Compression::Lzf, expected, "chunk");
        assert_eq!(lzf(9).unwrap(), b"abcabcabc");
        let short = lzf(10).unwrap_err().to_string();
        assert!(short.contains("LZF stream decodes to 9 bytes"), "{short}");
        let long = lzf(8).unwrap_err().to_string();
        assert!(long.contains("decodes past the 8 bytes"), "{long}");
        // 6 bytes decode to at most 6 · 88 = 528.
        let lying = lzf(529).unwrap_err().to_string();
        assert!(
            lying.contains("more than 6 LZF bytes can decode to"),
            "{lying}"
        );
        // A reference to before the first byte.
        let err = inflate_exact(p, &[4 << 5, 2], Compression::Lzf, 6, "chunk").unwrap_err();
        assert!(
            err.to_string()
                .starts_with("v.h5: chunk: corrupt LZF stream"),
            "{err}"
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
