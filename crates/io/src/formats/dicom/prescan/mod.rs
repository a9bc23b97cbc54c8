//! Checks a DICOM file's element lengths against the bytes that hold them,
//! before `dicom-object` parses it.
//!
//! The DICOM parser allocates each element's declared length before
//! reading it, so a 1 KB file that declares a 4 GB element would make it
//! allocate (and zero) 4 GB. This walk reads only the element headers
//! (PS3.5 §7.1: tag, VR, length; §7.5: items and delimiters) and refuses
//! any length that runs past its container: the file, a sequence or an
//! item of defined length. Nesting is bounded, so a hostile file cannot
//! exhaust the stack either.

mod element;
#[cfg(test)]
mod tests;
mod walker;

use std::io::Read;

use flate2::read::DeflateDecoder;

use self::element::{EXPLICIT_LE, Encoding, Header, UNDEFINED, element_header, length_error};
pub(super) use self::walker::PixelData;
use self::walker::{Until, Walked, Walker};

/// The transfer syntaxes whose data set encoding differs from explicit VR
/// little endian (every compressed syntax encodes its data set that way).
const IMPLICIT_VR_LE: &str = "1.2.840.10008.1.2";
const EXPLICIT_VR_BE: &str = "1.2.840.10008.1.2.2";
const DEFLATED_EXPLICIT_VR_LE: &str = "1.2.840.10008.1.2.1.99";

/// A deflated data set may inflate to at most this many times its
/// compressed size (deflate's own ceiling is about 1032:1).
const MAX_INFLATION: usize = crate::shared::compress::MAX_DEFLATE_RATIO as usize;
/// What the walk learnt about a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Scan {
    /// The transfer syntax UID of the file meta group.
    pub transfer_syntax: String,
    /// The top-level pixel data element, if the walk reached it.
    pub pixel_data: Option<PixelData>,
    /// Where the walk stopped: the end of the bytes it checked, or the
    /// start of the pixel data header when asked to stop there.
    pub end: usize,
}
/// The outcome of walking a prefix of a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Prescan {
    /// Every element checked (up to the pixel data when asked to stop).
    Done(Scan),
    /// The bytes ended inside an element header or value before the pixel
    /// data: more of the file is needed (or, for the whole file, it is cut short).
    NeedMore,
}
/// Walks `bytes`, the start of a DICOM file (or all of it if `whole`),
/// and checks every element length. With `stop_at_pixel_data` the walk
/// ends at the first top-level element from (7FE0,0008) on, where the
/// header parse stops (the header reader wants only what comes before the
/// pixels).
pub(super) fn prescan(
    bytes: &[u8],
    whole: bool,
    stop_at_pixel_data: bool,
) -> Result<Prescan, String> {
    if bytes.len() < 132 {
        return if whole {
            Err(format!(
                "{} bytes is too short for a DICOM file",
                bytes.len()
            ))
        } else {
            Ok(Prescan::NeedMore)
        };
    }
    if &bytes[128..132] != b"DICM" {
        return Err("no DICM magic at byte 128 (not a DICOM Part 10 file)".into());
    }
    // File meta group: always explicit VR little endian (PS3.10 §7.1),
    // opened by its group length (0002,0000). The parser reads elements
    // until it has consumed that many bytes, whatever their group, so the
    // walk does the same and the data set starts where the parser's will.
    let meta_element = |pos: usize| -> Result<Option<(Header, usize)>, String> {
        let Some(header) = element_header(bytes, pos, EXPLICIT_LE) else {
            return if whole {
                Err("file ends inside the file meta group".into())
            } else {
                Ok(None)
            };
        };
        if header.length == UNDEFINED {
            return Err(format!(
                "file meta element ({:04X},{:04X}) has an undefined length",
                header.tag.0, header.tag.1
            ));
        }
        let end = pos + header.size + header.length as usize;
        if end > bytes.len() {
            return if whole {
                Err(length_error(header, pos, bytes.len()))
            } else {
                Ok(None)
            };
        }
        Ok(Some((header, end)))
    };
    let Some((first, mut pos)) = meta_element(132)? else {
        return Ok(Prescan::NeedMore);
    };
    if first.tag != (0x0002, 0x0000) || first.length != 4 {
        return Err(format!(
            "file meta group starts with ({:04X},{:04X}) of {} bytes, not its 4-byte group length (0002,0000)",
            first.tag.0, first.tag.1, first.length
        ));
    }
    let value = pos - 4;
    let group_length = u32::from_le_bytes([
        bytes[value],
        bytes[value + 1],
        bytes[value + 2],
        bytes[value + 3],
    ]) as usize;
    let meta_start = pos;
    let mut transfer_syntax = None;
    while pos - meta_start < group_length {
        let Some((header, end)) = meta_element(pos)? else {
            return Ok(Prescan::NeedMore);
        };
        if header.tag == (0x0002, 0x0010) {
            let uid = String::from_utf8_lossy(&bytes[pos + header.size..end]);
            transfer_syntax = Some(uid.trim_end_matches(['\0', ' ']).to_string());
        }
        pos = end;
    }
    let transfer_syntax =
        transfer_syntax.ok_or("file meta group has no TransferSyntaxUID (0002,0010)")?;
    let encoding = match transfer_syntax.as_str() {
        IMPLICIT_VR_LE => Encoding {
            big_endian: false,
            explicit_vr: false,
        },
        EXPLICIT_VR_BE => Encoding {
            big_endian: true,
            explicit_vr: true,
        },
        _ => EXPLICIT_LE,
    };

    let walk = |data: &[u8], start: usize, whole: bool| {
        let mut walker = Walker {
            bytes: data,
            whole,
            stop_at_pixel_data,
            pixel_data: None,
        };
        walker.elements(start, data.len(), encoding, 0, Until::End)
    };
    if transfer_syntax == DEFLATED_EXPLICIT_VR_LE {
        // The data set after the meta group is one raw deflate stream.
        if !whole {
            return Ok(Prescan::NeedMore);
        }
        let compressed = &bytes[pos..];
        let limit = compressed.len().saturating_mul(MAX_INFLATION).max(1 << 20);
        let mut inflated = Vec::new();
        DeflateDecoder::new(compressed)
            .take(limit as u64 + 1)
            .read_to_end(&mut inflated)
            .map_err(|e| format!("deflated data set is corrupt: {e}"))?;
        if inflated.len() > limit {
            return Err(format!(
                "deflated data set inflates past {limit} bytes ({MAX_INFLATION} times its size)"
            ));
        }
        return match walk(&inflated, 0, true)? {
            Walked::Done(_, pixel_data) => Ok(Prescan::Done(Scan {
                transfer_syntax,
                pixel_data,
                end: bytes.len(),
            })),
            Walked::NeedMore => Err("deflated data set ends inside an element".into()),
        };
    }
    match walk(bytes, pos, whole)? {
        Walked::Done(end, pixel_data) => Ok(Prescan::Done(Scan {
            transfer_syntax,
            pixel_data,
            end,
        })),
        Walked::NeedMore => Ok(Prescan::NeedMore),
    }
}
