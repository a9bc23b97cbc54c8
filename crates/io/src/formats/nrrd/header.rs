//! The text of a NRRD header: the magic line, `field: value` lines,
//! `key:=value` pairs, comments, and the blank line that ends it (after
//! which attached data starts), as the NRRD format definition
//! (teem.sourceforge.net/nrrd/format.html) lays them out. This file only
//! splits the header into fields; `nrrd/mod.rs` interprets them.

use std::collections::HashMap;
use std::fs::File;
use std::path::Path;

use crate::error::IoError;
use crate::shared::text_header::{HeaderFormat, HeaderLines, MAX_HEADER};

/// Every field the format defines, by canonical name, with the other
/// spellings teem accepts.
const FIELDS: &[(&str, &[&str])] = &[
    ("content", &[]),
    ("number", &[]),
    ("type", &[]),
    ("block size", &["blocksize"]),
    ("dimension", &[]),
    ("space", &[]),
    ("space dimension", &[]),
    ("sizes", &[]),
    ("spacings", &[]),
    ("thicknesses", &[]),
    ("axis mins", &["axismins"]),
    ("axis maxs", &["axismaxs"]),
    ("space directions", &[]),
    ("centers", &["centerings"]),
    ("kinds", &[]),
    ("labels", &[]),
    ("units", &[]),
    ("min", &[]),
    ("max", &[]),
    ("old min", &["oldmin"]),
    ("old max", &["oldmax"]),
    ("endian", &[]),
    ("encoding", &[]),
    ("line skip", &["lineskip"]),
    ("byte skip", &["byteskip"]),
    ("sample units", &[]),
    ("space units", &[]),
    ("space origin", &[]),
    ("measurement frame", &[]),
    ("data file", &["datafile"]),
];

/// The canonical name of a field as written, if the format defines it
/// (field names are case-insensitive).
fn canonical(name: &str) -> Option<&'static str> {
    let lower = name.to_ascii_lowercase();
    FIELDS
        .iter()
        .find(|(c, others)| *c == lower || others.contains(&lower.as_str()))
        .map(|(c, _)| *c)
}

/// A NRRD header split into its parts.
#[derive(Debug, Default)]
pub(super) struct Header {
    /// The format version from the magic (`NRRD0004` is 4; `NRRD00.01` is 1).
    pub version: u32,
    /// Every field and key/value pair as written, in file order.
    pub written: Vec<(String, String)>,
    /// The defined fields by canonical name.
    fields: HashMap<&'static str, String>,
    /// Fields the format does not define, as written.
    pub unknown: Vec<String>,
    /// The file names after `data file: LIST`.
    pub list: Vec<String>,
    /// Where the data of an attached header starts: just past the blank
    /// line that ends the header; `None` if the header ran to the end of
    /// the file without one.
    pub data_offset: Option<u64>,
}

impl Header {
    /// The value of a defined field (by canonical name), if given.
    pub(super) fn get(&self, field: &str) -> Option<&str> {
        debug_assert!(canonical(field) == Some(field), "{field}");
        self.fields.get(field).map(String::as_str)
    }

    /// Reads the header at the start of `file` (its length `file_len`).
    pub(super) fn read(path: &Path, file: File, file_len: u64) -> Result<Header, IoError> {
        let mut lines = HeaderLines::new(file, file_len);
        let mut header = Header::default();
        let mut in_list = false;
        while let Some(line) = lines.next(path)? {
            if line.number == 1 {
                header.version = parse_magic(path, line.bytes)?;
                continue;
            }
            let line_no = line.number;
            let text = line.text(
                path,
                HeaderFormat::Nrrd,
                "is the blank line before the data missing?",
            )?;
            if in_list {
                if text.trim().is_empty() {
                    header.data_offset = Some(line.end);
                    return Ok(header);
                }
                header.list.push(text.trim().to_string());
                continue;
            }
            if text.is_empty() {
                header.data_offset = line.ended.then_some(line.end);
                return Ok(header);
            }
            if text.starts_with('#') {
                continue;
            }
            let Some(colon) = text.find(':') else {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "NRRD header line {line_no} (\"{}\") is neither \"field: value\" nor \"key:=value\"",
                        text.escape_debug()
                    ),
                ));
            };
            let (name, rest) = (&text[..colon], &text[colon + 1..]);
            if let Some(value) = rest.strip_prefix('=') {
                header.written.push((name.to_string(), value.to_string()));
                continue;
            }
            let (name, value) = (name.trim(), rest.trim());
            header.written.push((name.to_string(), value.to_string()));
            match canonical(name) {
                Some(field) => {
                    if header.fields.insert(field, value.to_string()).is_some() {
                        return Err(IoError::invalid(
                            path,
                            format!("NRRD field \"{field}\" is given twice (line {line_no})"),
                        ));
                    }
                    if field == "data file" && value.starts_with("LIST") {
                        in_list = true;
                    }
                }
                None => header.unknown.push(name.to_string()),
            }
        }
        // The file (or the bound) ends before a blank line: no attached data.
        if lines.hit_limit() {
            return Err(IoError::invalid(
                path,
                format!(
                    "the NRRD header has no end within its first {MAX_HEADER} bytes (no blank line)"
                ),
            ));
        }
        if lines.count() == 0 {
            return Err(IoError::invalid(path, "empty file: not a NRRD file"));
        }
        Ok(header)
    }
}

/// The version a magic line names: `NRRD0001` to `NRRD0005`, or the early
/// `NRRD00.01`.
fn parse_magic(path: &Path, line: &[u8]) -> Result<u32, IoError> {
    let version = match line {
        b"NRRD00.01" => Some(1),
        [b'N', b'R', b'R', b'D', b'0', b'0', b'0', d @ b'1'..=b'5'] => Some(u32::from(d - b'0')),
        _ => None,
    };
    version.ok_or_else(|| {
        let shown: String = line
            .iter()
            .take(16)
            .map(|b| b.escape_ascii().to_string())
            .collect();
        if line.starts_with(b"NRRD") {
            IoError::invalid(
                path,
                format!("NRRD magic \"{shown}\": this reader knows NRRD0001 to NRRD0005"),
            )
        } else {
            IoError::invalid(
                path,
                format!("not a NRRD file: it starts with \"{shown}\", not \"NRRD000\""),
            )
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &[u8]) -> Result<Header, IoError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.nrrd");
        std::fs::write(&path, text).unwrap();
        let file = File::open(&path).unwrap();
        Header::read(&path, file, text.len() as u64)
    }

    #[test]
    fn fields_pairs_comments_and_the_blank_line() {
        let text = b"NRRD0004\n# a comment\nType: float\r\ndimension:3\nsizes: 2 3 4\nlineskip: 2\nmy key:=a: b\nfoo: bar\n\nDATA";
        let h = parse(text).unwrap();
        assert_eq!(h.version, 4);
        assert_eq!(h.get("type"), Some("float"));
        assert_eq!(h.get("dimension"), Some("3"));
        assert_eq!(h.get("line skip"), Some("2"));
        assert_eq!(h.get("byte skip"), None);
        assert_eq!(h.unknown, ["foo"]);
        assert_eq!(h.written[0], ("Type".to_string(), "float".to_string()));
        assert_eq!(h.written[4], ("my key".to_string(), "a: b".to_string()));
        assert_eq!(h.data_offset, Some(text.len() as u64 - 4));
    }

    #[test]
    fn list_of_data_files() {
        let h = parse(b"NRRD0005\ndata file: LIST 2\na.raw\n b.raw \n\n").unwrap();
        assert_eq!(h.get("data file"), Some("LIST 2"));
        assert_eq!(h.list, ["a.raw", "b.raw"]);
        // The list may also run to the end of the file.
        let h = parse(b"NRRD0005\ndata file: LIST\na.raw").unwrap();
        assert_eq!(h.list, ["a.raw"]);
    }

    #[test]
    fn bad_headers() {
        let err = parse(b"P5\n3 3\n").unwrap_err().to_string();
        assert!(
            err.ends_with("not a NRRD file: it starts with \"P5\", not \"NRRD000\""),
            "{err}"
        );
        let err = parse(b"NRRD0009\n").unwrap_err().to_string();
        assert!(err.contains("knows NRRD0001 to NRRD0005"), "{err}");
        let err = parse(b"NRRD0004\ntype: float\ntype: double\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("\"type\" is given twice (line 3)"), "{err}");
        let err = parse(b"NRRD0004\njunk line\n").unwrap_err().to_string();
        assert!(err.contains("line 2 (\"junk line\") is neither"), "{err}");
        let err = parse(b"NRRD0004\ntype: float\n\xff\xfe\x00")
            .unwrap_err()
            .to_string();
        assert!(err.contains("line 3 is not text"), "{err}");
        assert_eq!(parse(b"NRRD00.01\n").unwrap().version, 1);
        assert!(parse(b"").is_err());
        // A header without its blank line has no attached data.
        assert_eq!(parse(b"NRRD0004\ntype: float").unwrap().data_offset, None);
    }
}
