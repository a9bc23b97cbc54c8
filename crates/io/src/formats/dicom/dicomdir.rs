//! The DICOMDIR of a DICOM file-set (a CD, DVD or archive folder): its
//! directory records walked to the series and their files.
//!
//! PS3.10 §8 and PS3.3 F.3: the DICOMDIR is a Part 10 file in explicit VR
//! little endian whose Directory Record Sequence (0004,1220) holds one
//! item per record. Records form a tree by byte offsets from the first
//! byte of the file (preamble included): the root's first record is at
//! OffsetOfTheFirstDirectoryRecordOfTheRootDirectoryEntity (0004,1200),
//! each record names its next sibling (OffsetOfTheNextDirectoryRecord,
//! (0004,1400)) and its first child
//! (OffsetOfReferencedLowerLevelDirectoryEntity, (0004,1420)); 0 ends a
//! chain. The levels are PATIENT → STUDY → SERIES → IMAGE (or RT DOSE,
//! PRESENTATION, ...; F.5), and a record below a SERIES that has a
//! ReferencedFileID (0004,1500) names one file of that series by its path
//! components relative to the DICOMDIR's folder (upper case, at most 8
//! characters, no extension, as ISO 9660 discs write them).
//!
//! This walker reads the bytes itself rather than through the DICOM
//! parser, because it needs each item's offset. Every length is checked
//! against its container, nesting is bounded, an offset that does not
//! point at a record and a chain that loops are refused, so a hostile
//! DICOMDIR cannot make it read out of bounds, recurse deeply or hang.

use std::collections::{BTreeMap, HashSet};

/// The transfer syntax a DICOMDIR must use (PS3.10 §8.6): explicit VR
/// little endian.
const EXPLICIT_VR_LE: &str = "1.2.840.10008.1.2.1";

/// Nesting of sequences within a record, at most (real records have none
/// or one level).
const MAX_DEPTH: usize = 16;

/// Directory records, at most: a DVD of CT studies has some 10⁵.
pub(super) const MAX_RECORDS: usize = 2_000_000;

/// One series of the file-set as its SERIES record and the records below
/// it describe it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct DirSeries {
    pub uid: String,
    pub number: Option<i64>,
    pub modality: String,
    pub description: String,
    /// The files' ReferencedFileID components, in record order.
    pub files: Vec<Vec<String>>,
    /// The byte offset of the SERIES record, for messages.
    pub offset: u32,
}

/// One directory record as the walk needs it.
#[derive(Debug, Clone, Default)]
struct Record {
    next: u32,
    lower: u32,
    kind: String,
    in_use: bool,
    file_id: Option<Vec<String>>,
    series_uid: String,
    series_number: Option<i64>,
    modality: String,
    description: String,
}

/// An element header: tag, VR (empty for items and delimiters), the
/// value's length (`None`: undefined) and where the value starts.
struct Element {
    group: u16,
    element: u16,
    vr: [u8; 2],
    length: Option<u32>,
    value: usize,
}

const UNDEFINED: u32 = 0xFFFF_FFFF;

/// Reads the element header at `pos` (explicit VR little endian).
fn element_at(bytes: &[u8], pos: usize) -> Result<Element, String> {
    let take = |at: usize, n: usize| {
        at.checked_add(n)
            .and_then(|end| bytes.get(at..end))
            .ok_or_else(|| format!("file ends inside the element header at byte {pos}"))
    };
    let head = take(pos, 4)?;
    let group = u16::from_le_bytes([head[0], head[1]]);
    let element = u16::from_le_bytes([head[2], head[3]]);
    if group == 0xFFFE {
        let l = take(pos + 4, 4)?;
        let length = u32::from_le_bytes([l[0], l[1], l[2], l[3]]);
        return Ok(Element {
            group,
            element,
            vr: [0, 0],
            length: (length != UNDEFINED).then_some(length),
            value: pos + 8,
        });
    }
    let vr = take(pos + 4, 2)?;
    let vr = [vr[0], vr[1]];
    let long = matches!(
        &vr,
        b"OB"
            | b"OD"
            | b"OF"
            | b"OL"
            | b"OV"
            | b"OW"
            | b"SQ"
            | b"SV"
            | b"UC"
            | b"UN"
            | b"UR"
            | b"UT"
            | b"UV"
    );
    let (length, value) = if long {
        let l = take(pos + 8, 4)?;
        (u32::from_le_bytes([l[0], l[1], l[2], l[3]]), pos + 12)
    } else {
        let l = take(pos + 6, 2)?;
        (u32::from(u16::from_le_bytes([l[0], l[1]])), pos + 8)
    };
    if !vr.iter().all(u8::is_ascii_uppercase) {
        return Err(format!(
            "element ({group:04X},{element:04X}) at byte {pos} has no valid VR: not explicit VR little endian"
        ));
    }
    Ok(Element {
        group,
        element,
        vr,
        length: (length != UNDEFINED).then_some(length),
        value,
    })
}

/// The end of the value of `e`, checked to lie within `end`.
fn value_end(e: &Element, end: usize, pos: usize) -> Result<usize, String> {
    let length = e.length.expect("defined");
    e.value
        .checked_add(length as usize)
        .filter(|&v| v <= end)
        .ok_or_else(|| {
            format!(
                "element ({:04X},{:04X}) at byte {pos} declares {length} bytes, past the end of its container at byte {end}",
                e.group, e.element
            )
        })
}

/// Skips an undefined-length sequence (or UN) value starting at `pos`:
/// its items to the sequence delimiter. Returns the position after it.
fn skip_sequence(bytes: &[u8], mut pos: usize, end: usize, depth: usize) -> Result<usize, String> {
    if depth > MAX_DEPTH {
        return Err(format!("sequences nested deeper than {MAX_DEPTH} levels"));
    }
    loop {
        let e = element_at(bytes, pos)?;
        match (e.group, e.element) {
            (0xFFFE, 0xE0DD) => return Ok(e.value),
            (0xFFFE, 0xE000) => {
                pos = match e.length {
                    Some(_) => value_end(&e, end, pos)?,
                    None => skip_item(bytes, e.value, end, depth + 1)?,
                };
            }
            _ => {
                return Err(format!(
                    "({:04X},{:04X}) at byte {pos} inside a sequence, where an item belongs",
                    e.group, e.element
                ));
            }
        }
        if pos > end {
            return Err(format!("sequence runs past byte {end}"));
        }
    }
}

/// Skips the elements of an undefined-length item from `pos` to its
/// delimiter. Returns the position after the delimiter.
fn skip_item(bytes: &[u8], mut pos: usize, end: usize, depth: usize) -> Result<usize, String> {
    loop {
        let e = element_at(bytes, pos)?;
        if (e.group, e.element) == (0xFFFE, 0xE00D) {
            return Ok(e.value);
        }
        pos = skip_value(bytes, &e, pos, end, depth)?;
    }
}

/// The position after the value of element `e` (at `pos`).
fn skip_value(
    bytes: &[u8],
    e: &Element,
    pos: usize,
    end: usize,
    depth: usize,
) -> Result<usize, String> {
    match e.length {
        Some(_) => value_end(e, end, pos),
        None if &e.vr == b"SQ" || &e.vr == b"UN" => skip_sequence(bytes, e.value, end, depth + 1),
        None => Err(format!(
            "element ({:04X},{:04X}) at byte {pos} has an undefined length",
            e.group, e.element
        )),
    }
}

/// The text of a value, trailing padding (spaces, NULs) removed.
fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes)
        .trim_end_matches([' ', '\0'])
        .trim_start()
        .to_string()
}

fn u32_le(bytes: &[u8]) -> Option<u32> {
    Some(u32::from_le_bytes(bytes.try_into().ok()?))
}

/// Parses the record (an item of (0004,1220)) whose value runs from `pos`
/// to `end` (or to its delimiter when `end` is `None`, within `limit`).
/// Returns the record and the position after it.
fn record(
    bytes: &[u8],
    mut pos: usize,
    end: Option<usize>,
    limit: usize,
) -> Result<(Record, usize), String> {
    let mut r = Record {
        in_use: true,
        ..Record::default()
    };
    let stop = end.unwrap_or(limit);
    loop {
        if end == Some(pos) {
            return Ok((r, pos));
        }
        let e = element_at(bytes, pos)?;
        if (e.group, e.element) == (0xFFFE, 0xE00D) {
            if end.is_some() {
                return Err(format!(
                    "item delimiter at byte {pos} in an item of defined length"
                ));
            }
            return Ok((r, e.value));
        }
        let next = skip_value(bytes, &e, pos, stop, 0)?;
        let value = || &bytes[e.value..next];
        match (e.group, e.element) {
            (0x0004, 0x1400) => r.next = u32_le(value()).unwrap_or(0),
            (0x0004, 0x1420) => r.lower = u32_le(value()).unwrap_or(0),
            (0x0004, 0x1410) => r.in_use = value() != [0, 0],
            (0x0004, 0x1430) => r.kind = text(value()),
            (0x0004, 0x1500) => {
                r.file_id = Some(
                    text(value())
                        .split('\\')
                        .map(|c| c.trim().to_string())
                        .collect(),
                )
            }
            (0x0020, 0x000E) => r.series_uid = text(value()),
            (0x0020, 0x0011) => r.series_number = text(value()).parse().ok(),
            (0x0008, 0x0060) => r.modality = text(value()),
            (0x0008, 0x103E) => r.description = text(value()),
            _ => {}
        }
        pos = next;
    }
}

/// The records of the DICOMDIR `bytes` by offset, and the root's first
/// record's offset.
fn records(bytes: &[u8]) -> Result<(BTreeMap<u32, Record>, u32), String> {
    if bytes.len() < 132 || &bytes[128..132] != b"DICM" {
        return Err("no DICM magic at byte 128: not a DICOM Part 10 file".into());
    }
    // The file meta group (0002,xxxx), explicit VR little endian.
    let mut pos = 132;
    let mut syntax = String::new();
    loop {
        if pos + 2 > bytes.len() || bytes[pos..pos + 2] != [0x02, 0x00] {
            break;
        }
        let e = element_at(bytes, pos)?;
        let next = skip_value(bytes, &e, pos, bytes.len(), 0)?;
        if e.element == 0x0010 {
            syntax = text(&bytes[e.value..next]);
        }
        pos = next;
    }
    if syntax != EXPLICIT_VR_LE {
        return Err(format!(
            "transfer syntax {syntax:?}: a DICOMDIR is written in explicit VR little endian ({EXPLICIT_VR_LE})"
        ));
    }
    let mut root = None;
    let mut found = BTreeMap::new();
    let mut saw_sequence = false;
    while pos < bytes.len() {
        let e = element_at(bytes, pos)?;
        if (e.group, e.element) == (0x0004, 0x1200) {
            let next = skip_value(bytes, &e, pos, bytes.len(), 0)?;
            root = u32_le(&bytes[e.value..next]);
            pos = next;
            continue;
        }
        if (e.group, e.element) != (0x0004, 0x1220) {
            pos = skip_value(bytes, &e, pos, bytes.len(), 0)?;
            continue;
        }
        saw_sequence = true;
        let end = match e.length {
            Some(_) => Some(value_end(&e, bytes.len(), pos)?),
            None => None,
        };
        let mut at = e.value;
        loop {
            if end == Some(at) {
                break;
            }
            let item = element_at(bytes, at)?;
            match (item.group, item.element) {
                (0xFFFE, 0xE0DD) if end.is_none() => {
                    at = item.value;
                    break;
                }
                (0xFFFE, 0xE000) => {}
                (g, el) => {
                    return Err(format!(
                        "({g:04X},{el:04X}) at byte {at} in the Directory Record Sequence (0004,1220), where a record item belongs"
                    ));
                }
            }
            let item_end = match item.length {
                Some(_) => Some(value_end(&item, end.unwrap_or(bytes.len()), at)?),
                None => None,
            };
            let (r, after) = record(bytes, item.value, item_end, end.unwrap_or(bytes.len()))?;
            if found.len() >= MAX_RECORDS {
                return Err(format!("more than {MAX_RECORDS} directory records"));
            }
            let offset = u32::try_from(at).map_err(|_| "DICOMDIR larger than 4 GB".to_string())?;
            found.insert(offset, r);
            at = after;
        }
        pos = at;
    }
    if !saw_sequence {
        return Err("no Directory Record Sequence (0004,1220): not a DICOMDIR".into());
    }
    let root = root.ok_or(
        "no OffsetOfTheFirstDirectoryRecordOfTheRootDirectoryEntity (0004,1200)".to_string(),
    )?;
    Ok((found, root))
}

/// The series the DICOMDIR `bytes` lists, in the order its records give
/// them, each with its files; series without files are left out. Errors
/// are reasons, for the caller to prefix with the file.
pub(crate) fn series(bytes: &[u8]) -> Result<Vec<DirSeries>, String> {
    let (records, root) = records(bytes)?;
    let mut out: Vec<DirSeries> = Vec::new();
    let mut seen = HashSet::new();
    // (offset of the first record of a chain, index into `out` of the
    // series it lies under, if any).
    let mut chains: Vec<(u32, Option<usize>)> = vec![(root, None)];
    while let Some((first, series)) = chains.pop() {
        let mut at = first;
        while at != 0 {
            if !seen.insert(at) {
                return Err(format!(
                    "the directory records loop: the record at byte {at} is reached twice"
                ));
            }
            let r = records.get(&at).ok_or_else(|| {
                format!("a record offset points to byte {at}, where no directory record starts")
            })?;
            let mut below = series;
            if r.in_use {
                if r.kind == "SERIES" {
                    out.push(DirSeries {
                        uid: r.series_uid.clone(),
                        number: r.series_number,
                        modality: r.modality.clone(),
                        description: r.description.clone(),
                        files: Vec::new(),
                        offset: at,
                    });
                    below = Some(out.len() - 1);
                } else if let (Some(s), Some(id)) = (series, &r.file_id) {
                    out[s].files.push(id.clone());
                }
                if r.lower != 0 {
                    chains.push((r.lower, below));
                }
            }
            at = r.next;
        }
    }
    out.retain(|s| !s.files.is_empty());
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An explicit VR LE element with a short length.
    fn short(group: u16, element: u16, vr: &[u8; 2], value: &[u8]) -> Vec<u8> {
        let mut v = Vec::new();
        v.extend(group.to_le_bytes());
        v.extend(element.to_le_bytes());
        v.extend(vr);
        v.extend((value.len() as u16).to_le_bytes());
        v.extend(value);
        v
    }

    /// A DICOMDIR of the records `make(offsets)` builds, where `offsets`
    /// are where the records will start (computed by building twice).
    fn dicomdir(records: &dyn Fn(&[u32]) -> Vec<Vec<u8>>, root: &dyn Fn(&[u32]) -> u32) -> Vec<u8> {
        let build = |offsets: &[u32]| {
            let mut meta = short(0x0002, 0x0010, b"UI", b"1.2.840.10008.1.2.1\0");
            let mut file = vec![0u8; 128];
            file.extend(b"DICM");
            let mut group = short(0x0002, 0x0000, b"UL", &(meta.len() as u32).to_le_bytes());
            group.append(&mut meta);
            file.extend(group);
            file.extend(short(0x0004, 0x1200, b"UL", &root(offsets).to_le_bytes()));
            file.extend([0x04, 0x00, 0x20, 0x12]);
            file.extend(b"SQ\0\0");
            file.extend(UNDEFINED.to_le_bytes());
            let mut starts = Vec::new();
            for r in records(offsets) {
                starts.push(file.len() as u32);
                file.extend([0xFE, 0xFF, 0x00, 0xE0]);
                file.extend((r.len() as u32).to_le_bytes());
                file.extend(r);
            }
            file.extend([0xFE, 0xFF, 0xDD, 0xE0, 0, 0, 0, 0]);
            (file, starts)
        };
        let (_, starts) = build(&[0; 16]);
        build(&starts).0
    }

    fn rec(kind: &str, next: u32, lower: u32, extra: &[Vec<u8>]) -> Vec<u8> {
        let mut r = short(0x0004, 0x1400, b"UL", &next.to_le_bytes());
        r.extend(short(0x0004, 0x1420, b"UL", &lower.to_le_bytes()));
        let mut k = kind.as_bytes().to_vec();
        if k.len() % 2 == 1 {
            k.push(b' ');
        }
        r.extend(short(0x0004, 0x1430, b"CS", &k));
        for e in extra {
            r.extend(e);
        }
        r
    }

    fn file_id(id: &str) -> Vec<u8> {
        let mut v = id.as_bytes().to_vec();
        if v.len() % 2 == 1 {
            v.push(b' ');
        }
        short(0x0004, 0x1500, b"CS", &v)
    }

    fn tree(o: &[u32]) -> Vec<Vec<u8>> {
        let uid = short(0x0020, 0x000E, b"UI", b"1.2.3\0");
        vec![
            rec("PATIENT", 0, o[1], &[]),
            rec("STUDY", 0, o[2], &[]),
            rec("SERIES", 0, o[3], &[uid]),
            rec("IMAGE", o[4], 0, &[file_id("DIR\\IM1")]),
            rec("IMAGE", 0, 0, &[file_id("DIR\\IM2")]),
        ]
    }

    #[test]
    fn records_are_followed_by_their_offsets_to_the_files() {
        let bytes = dicomdir(&tree, &|o| o[0]);
        let s = series(&bytes).unwrap();
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].uid, "1.2.3");
        assert_eq!(s[0].files, vec![vec!["DIR", "IM1"], vec!["DIR", "IM2"]]);
    }

    #[test]
    fn a_loop_and_an_offset_to_nowhere_are_refused() {
        let looped = |o: &[u32]| {
            let mut t = tree(o);
            t[4] = rec("IMAGE", o[3], 0, &[file_id("DIR\\IM2")]);
            t
        };
        let err = series(&dicomdir(&looped, &|o| o[0])).unwrap_err();
        assert!(err.contains("the directory records loop"), "{err}");
        let err = series(&dicomdir(&tree, &|o| o[0] + 2)).unwrap_err();
        assert!(err.contains("where no directory record starts"), "{err}");
    }

    #[test]
    fn every_truncation_is_refused_or_read_without_panic() {
        let bytes = dicomdir(&tree, &|o| o[0]);
        for n in 0..bytes.len() {
            let _ = series(&bytes[..n]);
        }
    }
}
