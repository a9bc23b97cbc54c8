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

use std::io::Read;

use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
use dicom_dictionary_std::StandardDataDictionary;
use dicom_object::Tag;
use flate2::read::DeflateDecoder;

/// The transfer syntaxes whose data set encoding differs from explicit VR
/// little endian (every compressed syntax encodes its data set that way).
const IMPLICIT_VR_LE: &str = "1.2.840.10008.1.2";
const EXPLICIT_VR_BE: &str = "1.2.840.10008.1.2.2";
const DEFLATED_EXPLICIT_VR_LE: &str = "1.2.840.10008.1.2.1.99";

/// A deflated data set may inflate to at most this many times its
/// compressed size (deflate's own ceiling is about 1032:1).
const MAX_INFLATION: usize = crate::shared::compress::MAX_DEFLATE_RATIO as usize;

/// Sequences nest at most this deep (real files rarely pass 5).
const MAX_DEPTH: usize = 32;

/// An undefined length (PS3.5 §7.1.1).
const UNDEFINED: u32 = 0xffff_ffff;

const ITEM: (u16, u16) = (0xfffe, 0xe000);
const ITEM_END: (u16, u16) = (0xfffe, 0xe00d);
const SEQUENCE_END: (u16, u16) = (0xfffe, 0xe0dd);

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

/// The top-level pixel data element (7FE0,0010 or float 0008/0009).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PixelData {
    /// Element number in group 7FE0: 0x0010 (integer), 0x0008 (float),
    /// 0x0009 (double).
    pub element: u16,
    /// Declared length in bytes; `None` when encapsulated (undefined length).
    pub length: Option<u32>,
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

/// Byte order and VR encoding of a data set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Encoding {
    big_endian: bool,
    explicit_vr: bool,
}

const EXPLICIT_LE: Encoding = Encoding {
    big_endian: false,
    explicit_vr: true,
};

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

/// One element header.
#[derive(Debug, Clone, Copy)]
struct Header {
    tag: (u16, u16),
    /// Explicit VR, if the encoding has one and this is not an item or delimiter.
    vr: Option<[u8; 2]>,
    length: u32,
    /// Bytes of the header itself.
    size: usize,
}

/// Reads the element header at `pos`, or `None` if the bytes end inside it.
fn element_header(bytes: &[u8], pos: usize, enc: Encoding) -> Option<Header> {
    let u16_at = |i: usize| -> Option<u16> {
        let b = bytes.get(i..i + 2)?;
        Some(if enc.big_endian {
            u16::from_be_bytes([b[0], b[1]])
        } else {
            u16::from_le_bytes([b[0], b[1]])
        })
    };
    let u32_at = |i: usize| -> Option<u32> {
        let b = bytes.get(i..i + 4)?;
        let a = [b[0], b[1], b[2], b[3]];
        Some(if enc.big_endian {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        })
    };
    let tag = (u16_at(pos)?, u16_at(pos + 2)?);
    if tag.0 == 0xfffe || !enc.explicit_vr {
        return Some(Header {
            tag,
            vr: None,
            length: u32_at(pos + 4)?,
            size: 8,
        });
    }
    let vr = bytes.get(pos + 4..pos + 6)?;
    let vr = [vr[0], vr[1]];
    // PS3.5 Table 7.1-2: these VRs have a 16-bit length; all others (and,
    // as the parser reads them, unknown VRs) have 2 reserved bytes and a
    // 32-bit length (Table 7.1-1).
    let short = matches!(
        &vr,
        b"AE"
            | b"AS"
            | b"AT"
            | b"CS"
            | b"DA"
            | b"DS"
            | b"DT"
            | b"FL"
            | b"FD"
            | b"IS"
            | b"LO"
            | b"LT"
            | b"PN"
            | b"SH"
            | b"SL"
            | b"SS"
            | b"ST"
            | b"TM"
            | b"UI"
            | b"UL"
            | b"US"
    );
    if !short {
        Some(Header {
            tag,
            vr: Some(vr),
            length: u32_at(pos + 8)?,
            size: 12,
        })
    } else {
        Some(Header {
            tag,
            vr: Some(vr),
            length: u32::from(u16_at(pos + 6)?),
            size: 8,
        })
    }
}

/// The size of one value of a binary VR (PS3.5 Table 6.2-1), whose
/// values' length must be a multiple of it. The parser reads
/// `length / size` values of such an element but moves on by `length`,
/// so a length that is not a multiple leaves it reading the next element
/// header from the wrong place: at a "length" made of other bytes, which
/// it allocates before reading (found by fuzzing, docs/robustness.md).
fn value_size(vr: [u8; 2]) -> Option<usize> {
    match &vr {
        b"US" | b"SS" | b"OW" => Some(2),
        b"AT" | b"FL" | b"OF" | b"SL" | b"UL" | b"OL" => Some(4),
        b"FD" | b"OD" | b"SV" | b"UV" | b"OV" => Some(8),
        _ => None,
    }
}

/// The VR the parser gives an element in implicit VR: OW for pixel and
/// overlay data, else the dictionary's (the first of its choices), else
/// UN (as `dicom-encoding`'s implicit VR decoder does).
fn implicit_vr(tag: (u16, u16)) -> [u8; 2] {
    if tag == (0x7fe0, 0x0010) || (tag.0 >> 8 == 0x60 && tag.1 == 0x3000) {
        return *b"OW";
    }
    StandardDataDictionary
        .by_tag(Tag(tag.0, tag.1))
        .map_or(*b"UN", |entry| entry.vr().relaxed().to_bytes())
}

/// Whether `vr` is one of the VRs of PS3.5 §6.2 (the parser reads any
/// other as UN).
fn known_vr(vr: [u8; 2]) -> bool {
    matches!(
        &vr,
        b"AE"
            | b"AS"
            | b"AT"
            | b"CS"
            | b"DA"
            | b"DS"
            | b"DT"
            | b"FL"
            | b"FD"
            | b"IS"
            | b"LO"
            | b"LT"
            | b"OB"
            | b"OD"
            | b"OF"
            | b"OL"
            | b"OV"
            | b"OW"
            | b"PN"
            | b"SH"
            | b"SL"
            | b"SQ"
            | b"SS"
            | b"ST"
            | b"SV"
            | b"TM"
            | b"UC"
            | b"UI"
            | b"UL"
            | b"UN"
            | b"UR"
            | b"US"
            | b"UT"
            | b"UV"
    )
}

fn length_error(header: Header, pos: usize, end: usize) -> String {
    format!(
        "element ({:04X},{:04X}) at byte {pos} declares {} bytes, but only {} remain in its container",
        header.tag.0,
        header.tag.1,
        header.length,
        end.saturating_sub(pos + header.size)
    )
}

/// Where a run of elements ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Until {
    /// At the end of the container.
    End,
    /// At an item delimitation item (an item of undefined length).
    ItemEnd,
}

enum Walked {
    /// Checked up to this position; the pixel data element, if met.
    Done(usize, Option<PixelData>),
    NeedMore,
}

struct Walker<'a> {
    bytes: &'a [u8],
    /// `bytes` is the whole file: running out of bytes is an error.
    whole: bool,
    stop_at_pixel_data: bool,
    pixel_data: Option<PixelData>,
}

/// Early exits of the walk: an error or "the prefix ended".
enum Stop {
    Error(String),
    NeedMore,
    /// Reached the top-level pixel data with `stop_at_pixel_data`.
    PixelData(usize),
}

impl Walker<'_> {
    fn elements(
        &mut self,
        start: usize,
        end: usize,
        enc: Encoding,
        depth: usize,
        until: Until,
    ) -> Result<Walked, String> {
        match self.run(start, end, enc, depth, until) {
            Ok(pos) => Ok(Walked::Done(pos, self.pixel_data)),
            Err(Stop::PixelData(pos)) => Ok(Walked::Done(pos, self.pixel_data)),
            Err(Stop::NeedMore) => Ok(Walked::NeedMore),
            Err(Stop::Error(e)) => Err(e),
        }
    }

    /// Bytes ran out at `pos` before `end` was reached.
    fn short(&self, what: &str, pos: usize) -> Stop {
        if self.whole {
            Stop::Error(format!("file ends inside {what} at byte {pos}"))
        } else {
            Stop::NeedMore
        }
    }

    /// Checks elements from `pos` to `end` (or to an item delimiter) and
    /// returns the position after them.
    fn run(
        &mut self,
        mut pos: usize,
        end: usize,
        enc: Encoding,
        depth: usize,
        until: Until,
    ) -> Result<usize, Stop> {
        if depth > MAX_DEPTH {
            return Err(Stop::Error(format!(
                "sequences nest deeper than {MAX_DEPTH} levels at byte {pos}"
            )));
        }
        loop {
            if pos >= end {
                if until == Until::ItemEnd {
                    return Err(self.short("an item of undefined length", pos));
                }
                return Ok(pos);
            }
            // Fewer than 8 bytes left at the very end of the file: trailing
            // padding, which parsers ignore.
            if depth == 0 && until == Until::End && self.whole && end - pos < 8 {
                return Ok(end);
            }
            let header = element_header(&self.bytes[..end], pos, enc)
                .ok_or_else(|| self.short("an element header", pos))?;
            let value = pos + header.size;
            match header.tag {
                ITEM_END => {
                    if until == Until::ItemEnd {
                        return Ok(value);
                    }
                    return Err(Stop::Error(format!(
                        "item delimiter at byte {pos} outside an item of undefined length"
                    )));
                }
                SEQUENCE_END | ITEM => {
                    return Err(Stop::Error(format!(
                        "({:04X},{:04X}) at byte {pos} outside a sequence",
                        header.tag.0, header.tag.1
                    )));
                }
                _ => {}
            }
            if depth == 0 && matches!(header.tag, (0x7fe0, 0x0008 | 0x0009 | 0x0010)) {
                self.pixel_data = Some(PixelData {
                    element: header.tag.1,
                    length: (header.length != UNDEFINED).then_some(header.length),
                });
            }
            // The header parse (`read_until(FloatPixelData)`) stops at the
            // first top-level tag from (7FE0,0008) on, and reads every one
            // before it, (7FE0,0001) and (7FE0,0002) included: the walk
            // must check those too, since a deflated data set is parsed
            // whole (found by fuzzing, docs/robustness.md).
            if self.stop_at_pixel_data && depth == 0 && header.tag >= (0x7fe0, 0x0008) {
                return Err(Stop::PixelData(pos));
            }
            if header.length == UNDEFINED {
                // A sequence (SQ, or any implicit VR / UN element of undefined
                // length: PS3.5 §6.2.2), or encapsulated pixel data.
                let encapsulated = header.tag == (0x7fe0, 0x0010) && header.vr != Some(*b"SQ");
                let item_enc = if header.vr.is_some_and(|vr| vr == *b"UN" || !known_vr(vr)) {
                    // PS3.5 §6.2.2 note 4: UN of undefined length holds implicit VR LE.
                    Encoding {
                        big_endian: false,
                        explicit_vr: false,
                    }
                } else {
                    enc
                };
                let kind = if encapsulated {
                    Items::Fragments
                } else {
                    Items::Undefined
                };
                pos = self.items(value, end, item_enc, depth, kind)?;
            } else {
                let len = header.length as usize;
                if len > end - value.min(end) {
                    if !self.whole && end == self.bytes.len() {
                        return Err(Stop::NeedMore);
                    }
                    return Err(Stop::Error(length_error(header, pos, end)));
                }
                let vr = header.vr.unwrap_or_else(|| implicit_vr(header.tag));
                if let Some(size) = value_size(vr)
                    && !len.is_multiple_of(size)
                {
                    return Err(Stop::Error(format!(
                        "element ({:04X},{:04X}) at byte {pos} is {} ({size}-byte values) but declares {len} bytes, not a multiple of {size}",
                        header.tag.0,
                        header.tag.1,
                        String::from_utf8_lossy(&vr)
                    )));
                }
                if header.vr == Some(*b"SQ")
                    || (header.vr.is_none() && self.defined_sequence(value, len, enc))
                {
                    self.items(value, value + len, enc, depth, Items::Defined)?;
                }
                pos = value + len;
            }
        }
    }

    /// In implicit VR a defined-length value is a sequence if it parses as
    /// items; such sequences are checked too. Other values are opaque.
    fn defined_sequence(&self, value: usize, len: usize, enc: Encoding) -> bool {
        len >= 8
            && element_header(&self.bytes[..value + len], value, enc).is_some_and(|h| h.tag == ITEM)
    }

    /// Checks the items of a sequence (or the fragments of encapsulated
    /// pixel data) from `pos`: up to `end` for a sequence of defined
    /// length, else up to the sequence delimiter. Returns the position
    /// after the sequence.
    fn items(
        &mut self,
        mut pos: usize,
        end: usize,
        enc: Encoding,
        depth: usize,
        kind: Items,
    ) -> Result<usize, Stop> {
        loop {
            if kind == Items::Defined && pos >= end {
                return Ok(pos);
            }
            let header = element_header(&self.bytes[..end], pos, enc)
                .ok_or_else(|| self.short("a sequence", pos))?;
            let value = pos + header.size;
            match header.tag {
                SEQUENCE_END if kind != Items::Defined => return Ok(value),
                ITEM if header.length == UNDEFINED && kind != Items::Fragments => {
                    pos = self.run(value, end, enc, depth + 1, Until::ItemEnd)?;
                }
                ITEM if header.length != UNDEFINED => {
                    let len = header.length as usize;
                    if len > end - value.min(end) {
                        if !self.whole && end == self.bytes.len() {
                            return Err(Stop::NeedMore);
                        }
                        return Err(Stop::Error(length_error(header, pos, end)));
                    }
                    if kind != Items::Fragments {
                        self.run(value, value + len, enc, depth + 1, Until::End)?;
                    }
                    pos = value + len;
                }
                tag => {
                    return Err(Stop::Error(format!(
                        "({:04X},{:04X}) at byte {pos} where a sequence item was expected",
                        tag.0, tag.1
                    )));
                }
            }
        }
    }
}

/// What a sequence holds and how it ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Items {
    /// Items, up to the sequence's defined length.
    Defined,
    /// Items, up to a sequence delimiter.
    Undefined,
    /// Pixel data fragments (opaque items), up to a sequence delimiter.
    Fragments,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal file: preamble, magic, meta group with a transfer syntax,
    /// then `dataset`.
    fn file(ts: &str, dataset: &[u8]) -> Vec<u8> {
        let mut b = vec![0u8; 128];
        b.extend_from_slice(b"DICM");
        let mut uid = ts.as_bytes().to_vec();
        if uid.len() % 2 == 1 {
            uid.push(0);
        }
        let mut meta = vec![0x02, 0x00, 0x10, 0x00, b'U', b'I'];
        meta.extend_from_slice(&(uid.len() as u16).to_le_bytes());
        meta.extend_from_slice(&uid);
        b.extend_from_slice(&[0x02, 0x00, 0x00, 0x00, b'U', b'L', 4, 0]);
        b.extend_from_slice(&(meta.len() as u32).to_le_bytes());
        b.extend_from_slice(&meta);
        b.extend_from_slice(dataset);
        b
    }

    fn explicit(group: u16, element: u16, vr: &[u8; 2], value: &[u8]) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(&group.to_le_bytes());
        b.extend_from_slice(&element.to_le_bytes());
        b.extend_from_slice(vr);
        b.extend_from_slice(&(value.len() as u16).to_le_bytes());
        b.extend_from_slice(value);
        b
    }

    fn long(group: u16, element: u16, vr: &[u8; 2], length: u32) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(&group.to_le_bytes());
        b.extend_from_slice(&element.to_le_bytes());
        b.extend_from_slice(vr);
        b.extend_from_slice(&[0, 0]);
        b.extend_from_slice(&length.to_le_bytes());
        b
    }

    fn item_header(tag: (u16, u16), length: u32) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(&tag.0.to_le_bytes());
        b.extend_from_slice(&tag.1.to_le_bytes());
        b.extend_from_slice(&length.to_le_bytes());
        b
    }

    const EXPLICIT: &str = "1.2.840.10008.1.2.1";

    #[test]
    fn good_file_with_sequences_and_pixel_data() {
        let mut ds = explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes());
        // A sequence of undefined length holding one item of undefined
        // length and one of defined length.
        ds.extend(long(0x5200, 0x9229, b"SQ", UNDEFINED));
        ds.extend(item_header(ITEM, UNDEFINED));
        ds.extend(explicit(0x0028, 0x0030, b"DS", b"1\\1 "));
        ds.extend(item_header(ITEM_END, 0));
        let inner = explicit(0x0020, 0x0032, b"DS", b"0\\0\\0 ");
        ds.extend(item_header(ITEM, inner.len() as u32));
        ds.extend(inner);
        ds.extend(item_header(SEQUENCE_END, 0));
        ds.extend(long(0x7fe0, 0x0010, b"OW", 4));
        ds.extend([1, 0, 2, 0]);
        let f = file(EXPLICIT, &ds);
        let Prescan::Done(scan) = prescan(&f, true, false).unwrap() else {
            panic!("whole file needs no more")
        };
        assert_eq!(scan.transfer_syntax, EXPLICIT);
        assert_eq!(
            scan.pixel_data,
            Some(PixelData {
                element: 0x0010,
                length: Some(4)
            })
        );
        // Stopping at the pixel data reports where its header starts.
        let Prescan::Done(head) = prescan(&f, true, true).unwrap() else {
            panic!()
        };
        assert_eq!(head.end, f.len() - 16);
        // Any prefix that ends before the pixel data needs more bytes.
        for cut in [100, 140, 160, f.len() - 20] {
            assert_eq!(
                prescan(&f[..cut], false, true).unwrap(),
                Prescan::NeedMore,
                "{cut}"
            );
        }
    }

    #[test]
    fn binary_values_must_fill_whole_values() {
        // Explicit VR: FD holds 8-byte values, so 2 bytes (the fuzz
        // finding, tests/fuzz_regressions.rs) or 12 are refused, 16 not.
        for (len, ok) in [(2usize, false), (12, false), (16, true), (0, true)] {
            let mut ds = explicit(0x0008, 0x0060, b"FD", &vec![0; len]);
            ds.extend(explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes()));
            let result = prescan(&file(EXPLICIT, &ds), true, false);
            match result {
                Ok(_) => assert!(ok, "{len}"),
                Err(err) => {
                    assert!(!ok, "{len}: {err}");
                    assert!(
                        err.contains("(0008,0060)")
                            && err.contains(&format!("declares {len} bytes, not a multiple of 8")),
                        "{err}"
                    );
                }
            }
        }
        // Implicit VR: the VR is the dictionary's, Rows (0028,0010) is US.
        let mut ds = item_header((0x0028, 0x0010), 3);
        ds.extend([3, 0, 0]);
        let err = prescan(&file(IMPLICIT_VR_LE, &ds), true, false).unwrap_err();
        assert!(err.contains("is US (2-byte values)"), "{err}");
        let mut ds = item_header((0x0028, 0x0010), 2);
        ds.extend([3, 0]);
        assert!(prescan(&file(IMPLICIT_VR_LE, &ds), true, false).is_ok());
        // A tag the dictionary does not know is UN: any length.
        let mut ds = item_header((0x0009, 0x1001), 3);
        ds.extend([3, 0, 0]);
        assert!(prescan(&file(IMPLICIT_VR_LE, &ds), true, false).is_ok());
    }

    #[test]
    fn header_walk_stops_where_the_header_parse_does() {
        // An extended offset table (7FE0,0001) before the pixel data is
        // read by the header parse, so it is checked, not taken for the
        // pixel data.
        let mut ds = explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes());
        ds.extend(long(0x7fe0, 0x0001, b"OV", 8));
        ds.extend([0; 8]);
        let pixels_at = file(EXPLICIT, &ds).len();
        ds.extend(long(0x7fe0, 0x0010, b"OW", 4));
        ds.extend([1, 0, 2, 0]);
        let f = file(EXPLICIT, &ds);
        let Prescan::Done(head) = prescan(&f, true, true).unwrap() else {
            panic!("whole file needs no more")
        };
        assert_eq!(head.end, pixels_at);
        assert_eq!(
            head.pixel_data,
            Some(PixelData {
                element: 0x0010,
                length: Some(4)
            })
        );
        // The same table declaring more bytes than the file holds.
        let mut ds = long(0x7fe0, 0x0001, b"OV", 0x4000_0000);
        ds.extend([0; 16]);
        let err = prescan(&file(EXPLICIT, &ds), true, true).unwrap_err();
        assert!(err.contains("(7FE0,0001)"), "{err}");
    }

    #[test]
    fn lying_lengths_are_refused() {
        let mut ds = explicit(0x0028, 0x0010, b"US", &3u16.to_le_bytes());
        ds.extend(long(0x7fe0, 0x0010, b"OW", 0xfff0_0000));
        ds.extend([0; 16]);
        let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
        assert!(
            err.contains("(7FE0,0010)") && err.contains("declares 4293918720 bytes"),
            "{err}"
        );

        // An item longer than its defined-length sequence.
        let mut ds = long(0x5200, 0x9229, b"SQ", 8);
        ds.extend(item_header(ITEM, 100));
        ds.extend([0; 100]);
        let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
        assert!(err.contains("(FFFE,E000)"), "{err}");

        // A sequence that never ends.
        let mut ds = long(0x5200, 0x9229, b"SQ", UNDEFINED);
        ds.extend(item_header(ITEM, 0));
        let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
        assert!(err.contains("file ends inside"), "{err}");

        // Nesting deeper than the limit.
        let mut ds = Vec::new();
        for _ in 0..40 {
            ds.extend(long(0x5200, 0x9229, b"SQ", UNDEFINED));
            ds.extend(item_header(ITEM, UNDEFINED));
        }
        let err = prescan(&file(EXPLICIT, &ds), true, false).unwrap_err();
        assert!(err.contains("nest deeper"), "{err}");

        let mut f = file(EXPLICIT, &[]);
        f[130] = b'X';
        assert!(prescan(&f, true, false).unwrap_err().contains("DICM"));

        // A group length that runs into the data set makes the parser read
        // data set elements as meta elements: the walk follows it there.
        let mut ds = item_header((0x0008, 0x0005), 0xffff_0000);
        ds.extend([16, 0, 0, 0]);
        let mut f = file(IMPLICIT_VR_LE, &ds);
        let err = prescan(&f, true, false).unwrap_err();
        assert!(err.contains("declares 4294901760 bytes"), "{err}");
        let len = u32::from_le_bytes([f[140], f[141], f[142], f[143]]);
        f[140..144].copy_from_slice(&(len + 8).to_le_bytes());
        let err = prescan(&f, true, false).unwrap_err();
        assert!(err.contains("(0008,0005) at byte"), "{err}");
        let mut f = file(EXPLICIT, &[]);
        f[132] = 0x08;
        let err = prescan(&f, true, false).unwrap_err();
        assert!(err.contains("not its 4-byte group length"), "{err}");
    }

    #[test]
    fn implicit_and_big_endian_encodings() {
        // Implicit VR LE: tag, 32-bit length, value.
        let mut ds = Vec::new();
        ds.extend(item_header((0x0028, 0x0010), 2));
        ds.extend(3u16.to_le_bytes());
        ds.extend(item_header((0x7fe0, 0x0010), 6));
        ds.extend([0; 4]);
        let err = prescan(&file(IMPLICIT_VR_LE, &ds), true, false).unwrap_err();
        assert!(err.contains("declares 6 bytes, but only 4 remain"), "{err}");

        // Explicit VR big endian: the US length is big-endian too.
        let mut ds = vec![0x00, 0x28, 0x00, 0x10, b'U', b'S', 0x00, 0x02, 0x00, 0x03];
        ds.extend([0x7f, 0xe0, 0x00, 0x10, b'O', b'W', 0, 0, 0, 0, 0, 2, 0, 1]);
        let Prescan::Done(scan) = prescan(&file(EXPLICIT_VR_BE, &ds), true, false).unwrap() else {
            panic!()
        };
        assert_eq!(scan.pixel_data.unwrap().length, Some(2));
    }
}
