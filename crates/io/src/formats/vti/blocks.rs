//! The block-header framing of VTK XML binary data (vtkXMLWriter): a byte
//! count, or for compressed data (zlib, LZ4 or LZMA, vtkXMLWriter's
//! `WriteCompressionHeader`) the block count, block size, last block size
//! and compressed block sizes, in `header_type` words of the file's byte
//! order; raw (appended) or base64 (inline or appended), with the header
//! and data base64-encoded separately or as one stream. Each block is one
//! zlib stream, raw LZ4 block or xz stream (`shared/compress.rs`).
//!
//! Every declared size is checked against the bytes that hold it, and each
//! compressed block against its codec's largest ratio (zlib, LZ4), before
//! allocating; xz blocks grow only as they decode.

use std::path::Path;

use base64::Engine;
use base64::engine::DecodePaddingMode;
use base64::engine::general_purpose::{GeneralPurpose, GeneralPurposeConfig};

use crate::dtype::Endian;
use crate::error::IoError;
use crate::shared::compress::{Compression, Decompressor};

/// How a file frames its binary data (`VTKFile` attributes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct BlockFormat {
    /// Byte order of header words and samples (`byte_order`).
    pub endian: Endian,
    /// Bytes per header word (`header_type` UInt32 or UInt64).
    pub word: usize,
    /// `compressor="vtkZLibDataCompressor"`, `"vtkLZ4DataCompressor"` or
    /// `"vtkLZMADataCompressor"`; `None` when uncompressed.
    pub compressed: Option<Compression>,
}

/// Base64 as VTK writes it, read leniently about padding and trailing bits.
const BASE64: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new()
        .with_decode_allow_trailing_bits(true)
        .with_decode_padding_mode(DecodePaddingMode::Indifferent),
);

/// Reads header word `i` of `header`.
fn word(header: &[u8], s: &BlockFormat, i: usize) -> u64 {
    let w = &header[i * s.word..(i + 1) * s.word];
    match (s.word, s.endian) {
        (4, Endian::Little) => u64::from(u32::from_le_bytes([w[0], w[1], w[2], w[3]])),
        (4, Endian::Big) => u64::from(u32::from_be_bytes([w[0], w[1], w[2], w[3]])),
        (_, Endian::Little) => u64::from_le_bytes(w.try_into().unwrap_or([0; 8])),
        (_, Endian::Big) => u64::from_be_bytes(w.try_into().unwrap_or([0; 8])),
    }
}

/// A compressed array's block layout, read from its header.
struct Blocks {
    /// Uncompressed size of each block.
    sizes: Vec<usize>,
    /// Compressed size of each block.
    compressed: Vec<usize>,
}

/// The block layout in `header` (3 + n words), checked against the
/// expected size and against the codec's ratio.
fn blocks(
    path: &Path,
    header: &[u8],
    s: &BlockFormat,
    expected: usize,
    name: &str,
) -> Result<Blocks, IoError> {
    let n = word(header, s, 0) as usize;
    let block = word(header, s, 1);
    let last = word(header, s, 2);
    let total = if n == 0 {
        0
    } else {
        let last = if last == 0 { block } else { last };
        (n as u64 - 1).saturating_mul(block).saturating_add(last)
    };
    if total != expected as u64 || (n > 1 && last > block) {
        return Err(IoError::invalid(
            path,
            format!(
                "DataArray \"{name}\": compression header declares {n} blocks of {block} bytes (last {last}), not the {expected} bytes its extent and type need"
            ),
        ));
    }
    let compressed: Vec<usize> = (0..n).map(|i| word(header, s, 3 + i) as usize).collect();
    let sum = compressed
        .iter()
        .fold(0u64, |a, &c| a.saturating_add(c as u64));
    let ratio = s.compressed.and_then(Compression::max_ratio);
    if ratio.is_some_and(|r| (expected as u64) > sum.saturating_mul(r)) {
        return Err(IoError::invalid(
            path,
            format!(
                "DataArray \"{name}\": {sum} compressed bytes cannot inflate to the {expected} its header declares"
            ),
        ));
    }
    let mut sizes = vec![block as usize; n];
    if let Some(l) = sizes.last_mut()
        && last != 0
    {
        *l = last as usize;
    }
    Ok(Blocks { sizes, compressed })
}

/// Decodes the blocks laid out in `b` from `data` with `kind`.
fn inflate_blocks(
    path: &Path,
    data: &[u8],
    b: &Blocks,
    kind: Compression,
    expected: usize,
    name: &str,
) -> Result<Vec<u8>, IoError> {
    // The output grows as blocks decode; each block's declared size is
    // bounded by the codec's ratio before it is allocated (an xz block's
    // output grows as it decodes).
    let mut out = Vec::with_capacity(expected.min(1 << 20));
    let mut decompressor = Decompressor::new(kind);
    let mut at = 0usize;
    for (i, (&size, &c)) in b.sizes.iter().zip(&b.compressed).enumerate() {
        if kind
            .max_ratio()
            .is_some_and(|r| size as u64 > (c as u64).saturating_mul(r).saturating_add(64))
        {
            return Err(IoError::invalid(
                path,
                format!(
                    "DataArray \"{name}\": compressed block {i} of {c} bytes cannot inflate to the {size} bytes its header declares"
                ),
            ));
        }
        let chunk = data.get(at..at.saturating_add(c)).ok_or_else(|| {
            IoError::invalid(path, format!("DataArray \"{name}\": compressed block {i} ({c} bytes) runs past the end of the data"))
        })?;
        out.extend(decompressor.decode_exact(
            path,
            chunk,
            size,
            &format!("DataArray \"{name}\" block {i}"),
        )?);
        at += c;
    }
    Ok(out)
}

/// Raw appended data at `region` (which runs to the end of the file).
pub(super) fn raw_block(
    path: &Path,
    region: &[u8],
    s: &BlockFormat,
    expected: usize,
    name: &str,
) -> Result<Vec<u8>, IoError> {
    let short = |what: &str| {
        IoError::invalid(
            path,
            format!("appended DataArray \"{name}\": the file ends inside its {what}"),
        )
    };
    let w = s.word;
    let Some(kind) = s.compressed else {
        let header = region.get(..w).ok_or_else(|| short("header"))?;
        let n = word(header, s, 0);
        if n != expected as u64 {
            return Err(size_mismatch(path, name, n, expected));
        }
        return region
            .get(w..w + expected)
            .map(<[u8]>::to_vec)
            .ok_or_else(|| short("data"));
    };
    let head = region
        .get(..3 * w)
        .ok_or_else(|| short("compression header"))?;
    let n = word(head, s, 0);
    if n > ((region.len() - 3 * w) / w) as u64 {
        return Err(short("compression header"));
    }
    let hlen = (3 + n as usize) * w;
    let b = blocks(path, &region[..hlen], s, expected, name)?;
    inflate_blocks(path, &region[hlen..], &b, kind, expected, name)
}

fn size_mismatch(path: &Path, name: &str, declared: u64, expected: usize) -> IoError {
    IoError::invalid(
        path,
        format!(
            "DataArray \"{name}\": header declares {declared} bytes, but its extent and type need {expected}"
        ),
    )
}

/// Decodes base64 `text` in chunks of 4 characters.
fn b64(path: &Path, text: &[u8], name: &str) -> Result<Vec<u8>, IoError> {
    BASE64
        .decode(text)
        .map_err(|e| IoError::invalid(path, format!("DataArray \"{name}\": bad base64 data: {e}")))
}

/// Base64 characters that encode `n` bytes.
fn b64_len(n: usize) -> usize {
    n.div_ceil(3).saturating_mul(4)
}

/// Base64 binary data: inline (`text` is the element's text, without
/// whitespace) or appended (`text` runs from the array's offset to the end
/// of the file). The header and the data are either separately encoded
/// (each padded, as VTK writes compressed arrays) or one stream (as VTK
/// writes uncompressed ones); a padded header segment tells them apart.
pub(super) fn base64_block(
    path: &Path,
    text: &[u8],
    s: &BlockFormat,
    expected: usize,
    name: &str,
    inline: bool,
) -> Result<Vec<u8>, IoError> {
    let short = || {
        IoError::invalid(
            path,
            format!(
                "DataArray \"{name}\": base64 data ends before the {expected} bytes it should hold"
            ),
        )
    };
    let w = s.word;
    // The header's length: one word, or 3 + n words when compressed (the
    // first 3 words are 4·w characters in either encoding).
    let header_len = if s.compressed.is_some() {
        let first = b64(path, text.get(..4 * w).ok_or_else(short)?, name)?;
        let n = word(&first, s, 0);
        if n > (text.len() / w) as u64 {
            return Err(short());
        }
        (3 + n as usize) * w
    } else {
        w
    };
    let seg = b64_len(header_len);
    let separate = text.len() >= seg && (header_len % 3 == 0 || text[seg - 1] == b'=');
    if separate {
        let header = b64(path, &text[..seg], name)?;
        if header.len() < header_len {
            return Err(short());
        }
        let rest = &text[seg..];
        let Some(kind) = s.compressed else {
            let n = word(&header, s, 0);
            if n != expected as u64 {
                return Err(size_mismatch(path, name, n, expected));
            }
            let chars = if inline {
                rest.len()
            } else {
                b64_len(expected)
            };
            let data = b64(path, rest.get(..chars).ok_or_else(short)?, name)?;
            return data.get(..expected).map(<[u8]>::to_vec).ok_or_else(short);
        };
        let b = blocks(path, &header, s, expected, name)?;
        let sum: usize = b.compressed.iter().sum();
        let chars = if inline { rest.len() } else { b64_len(sum) };
        let data = b64(path, rest.get(..chars).ok_or_else(short)?, name)?;
        return inflate_blocks(path, &data, &b, kind, expected, name);
    }
    // One stream: decode the header first, then as much as it declares.
    let header = b64(
        path,
        text.get(..b64_len(header_len)).ok_or_else(short)?,
        name,
    )?;
    let header = header.get(..header_len).ok_or_else(short)?;
    let payload = if s.compressed.is_some() {
        blocks(path, header, s, expected, name)?
            .compressed
            .iter()
            .sum()
    } else {
        let n = word(header, s, 0);
        if n != expected as u64 {
            return Err(size_mismatch(path, name, n, expected));
        }
        expected
    };
    let chars = b64_len(header_len.saturating_add(payload));
    let all = b64(path, text.get(..chars).ok_or_else(short)?, name)?;
    let data = all
        .get(header_len..header_len + payload)
        .ok_or_else(short)?;
    match s.compressed {
        Some(kind) => {
            let b = blocks(path, header, s, expected, name)?;
            inflate_blocks(path, data, &b, kind, expected, name)
        }
        None => Ok(data.to_vec()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format(word: usize, compressed: Option<Compression>) -> BlockFormat {
        BlockFormat {
            endian: Endian::Little,
            word,
            compressed,
        }
    }

    #[test]
    fn base64_header_and_data_in_one_or_two_streams() {
        let data: Vec<u8> = (0..10).collect();
        let p = Path::new("f.vti");
        for word in [4usize, 8] {
            let s = format(word, None);
            let mut header = 10u64.to_le_bytes()[..word].to_vec();
            // Separately encoded.
            let text = [BASE64.encode(&header), BASE64.encode(&data)].concat();
            assert_eq!(
                base64_block(p, text.as_bytes(), &s, 10, "a", true).unwrap(),
                data
            );
            // One stream.
            header.extend(&data);
            let text = BASE64.encode(&header);
            assert_eq!(
                base64_block(p, text.as_bytes(), &s, 10, "a", true).unwrap(),
                data
            );
            // A header that disagrees with the extent.
            let err = base64_block(p, text.as_bytes(), &s, 12, "a", true).unwrap_err();
            assert!(
                err.to_string()
                    .contains("declares 10 bytes, but its extent and type need 12"),
                "{err}"
            );
        }
    }

    #[test]
    fn compressed_blocks_round_trip() {
        use flate2::write::ZlibEncoder;
        use std::io::Write;
        let data: Vec<u8> = (0..700u32).map(|i| (i * 7 % 251) as u8).collect();
        let p = Path::new("f.vti");
        // Blocks of 256, 256 and 188 bytes, as vtkXMLWriter lays them out.
        let chunks: Vec<Vec<u8>> = data
            .chunks(256)
            .map(|c| {
                let mut e = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
                e.write_all(c).unwrap();
                e.finish().unwrap()
            })
            .collect();
        let mut header: Vec<u8> = Vec::new();
        for w in [3u32, 256, 188] {
            header.extend(w.to_le_bytes());
        }
        for c in &chunks {
            header.extend((c.len() as u32).to_le_bytes());
        }
        let s = format(4, Some(Compression::Zlib));
        let mut raw = header.clone();
        raw.extend(chunks.concat());
        assert_eq!(raw_block(p, &raw, &s, 700, "a").unwrap(), data);
        let text = [BASE64.encode(&header), BASE64.encode(chunks.concat())].concat();
        assert_eq!(
            base64_block(p, text.as_bytes(), &s, 700, "a", false).unwrap(),
            data
        );
        // A lying block size.
        let err = raw_block(p, &raw, &s, 800, "a").unwrap_err();
        assert!(
            err.to_string()
                .contains("declares 3 blocks of 256 bytes (last 188)"),
            "{err}"
        );
        // Cut short.
        let err = raw_block(p, &raw[..raw.len() - 5], &s, 700, "a").unwrap_err();
        assert!(err.to_string().contains("block 2"), "{err}");
    }
}
