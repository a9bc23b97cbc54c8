//! One data element's header (PS3.5 §7.1: tag, VR, length; §7.5: items
//! and delimiters) in each of the data set encodings, and the VRs whose
//! lengths it checks.

use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
use dicom_dictionary_std::StandardDataDictionary;
use dicom_object::Tag;

/// An undefined length (PS3.5 §7.1.1).
pub(super) const UNDEFINED: u32 = 0xffff_ffff;

pub(super) const ITEM: (u16, u16) = (0xfffe, 0xe000);
pub(super) const ITEM_END: (u16, u16) = (0xfffe, 0xe00d);
pub(super) const SEQUENCE_END: (u16, u16) = (0xfffe, 0xe0dd);

/// Byte order and VR encoding of a data set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Encoding {
    pub(super) big_endian: bool,
    pub(super) explicit_vr: bool,
}

pub(super) const EXPLICIT_LE: Encoding = Encoding {
    big_endian: false,
    explicit_vr: true,
};

/// One element header.
#[derive(Debug, Clone, Copy)]
pub(super) struct Header {
    pub(super) tag: (u16, u16),
    /// Explicit VR, if the encoding has one and this is not an item or delimiter.
    pub(super) vr: Option<[u8; 2]>,
    pub(super) length: u32,
    /// Bytes of the header itself.
    pub(super) size: usize,
}

/// Reads the element header at `pos`, or `None` if the bytes end inside it.
pub(super) fn element_header(bytes: &[u8], pos: usize, enc: Encoding) -> Option<Header> {
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
pub(super) fn value_size(vr: [u8; 2]) -> Option<usize> {
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
pub(super) fn implicit_vr(tag: (u16, u16)) -> [u8; 2] {
    if tag == (0x7fe0, 0x0010) || (tag.0 >> 8 == 0x60 && tag.1 == 0x3000) {
        return *b"OW";
    }
    StandardDataDictionary
        .by_tag(Tag(tag.0, tag.1))
        .map_or(*b"UN", |entry| entry.vr().relaxed().to_bytes())
}

/// Whether `vr` is one of the VRs of PS3.5 §6.2 (the parser reads any
/// other as UN).
pub(super) fn known_vr(vr: [u8; 2]) -> bool {
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

pub(super) fn length_error(header: Header, pos: usize, end: usize) -> String {
    format!(
        "element ({:04X},{:04X}) at byte {pos} declares {} bytes, but only {} remain in its container",
        header.tag.0,
        header.tag.1,
        header.length,
        end.saturating_sub(pos + header.size)
    )
}
