//! The walk over a data set's elements, into sequences and items, that
//! refuses any length running past its container and finds the top-level
//! pixel data.

use super::element::{
    Encoding, ITEM, ITEM_END, SEQUENCE_END, UNDEFINED, element_header, implicit_vr, known_vr,
    length_error, value_size,
};

/// Sequences nest at most this deep (real files rarely pass 5).
const MAX_DEPTH: usize = 32;

/// The top-level pixel data element (7FE0,0010 or float 0008/0009).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in super::super) struct PixelData {
    /// Element number in group 7FE0: 0x0010 (integer), 0x0008 (float),
    /// 0x0009 (double).
    pub element: u16,
    /// Declared length in bytes; `None` when encapsulated (undefined length).
    pub length: Option<u32>,
}

/// Where a run of elements ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Until {
    /// At the end of the container.
    End,
    /// At an item delimitation item (an item of undefined length).
    ItemEnd,
}

pub(super) enum Walked {
    /// Checked up to this position; the pixel data element, if met.
    Done(usize, Option<PixelData>),
    NeedMore,
}

pub(super) struct Walker<'a> {
    pub(super) bytes: &'a [u8],
    /// `bytes` is the whole file: running out of bytes is an error.
    pub(super) whole: bool,
    pub(super) stop_at_pixel_data: bool,
    pub(super) pixel_data: Option<PixelData>,
}

/// Early exits of the walk: an error or "the prefix ended".
enum Stop {
    Error(String),
    NeedMore,
    /// Reached the top-level pixel data with `stop_at_pixel_data`.
    PixelData(usize),
}

impl Walker<'_> {
    pub(super) fn elements(
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
