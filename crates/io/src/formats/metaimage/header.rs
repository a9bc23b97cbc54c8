//! The text of a MetaImage header: `Key = Value` lines up to and including
//! `ElementDataFile`, which MetaIO requires to be the last field; after it
//! come the data (`LOCAL`) or, for `LIST`, the data file names. This file
//! only splits the header into fields; `metaimage/mod.rs` interprets them.

use std::collections::HashMap;
use std::fs::File;
use std::path::Path;

use crate::error::IoError;
use crate::shared::text_header::{HeaderFormat, HeaderLines, MAX_HEADER};

/// A MetaImage header split into its fields.
#[derive(Debug, Default)]
pub(super) struct Header {
    /// Every field as written (`Key`, `Value`), in file order.
    pub written: Vec<(String, String)>,
    /// Field values by key. Keys are case-sensitive, as in MetaIO.
    fields: HashMap<String, String>,
    /// The file names after `ElementDataFile = LIST`.
    pub list: Vec<String>,
    /// Where `LOCAL` data starts: just past the `ElementDataFile` line.
    pub data_offset: u64,
}

impl Header {
    /// The value of field `key`, if given.
    pub(super) fn get(&self, key: &str) -> Option<&str> {
        self.fields.get(key).map(String::as_str)
    }

    /// Reads the header at the start of `file` (its length `file_len`).
    pub(super) fn read(path: &Path, file: File, file_len: u64) -> Result<Header, IoError> {
        let mut lines = HeaderLines::new(file, file_len);
        let mut header = Header::default();
        let mut in_list = false;
        while let Some(line) = lines.next(path)? {
            let line_no = line.number;
            let text = line.text(
                path,
                HeaderFormat::MetaImage,
                "is the ElementDataFile field missing?",
            )?;
            if in_list {
                if !text.trim().is_empty() {
                    header.list.push(text.trim().to_string());
                }
                continue;
            }
            if text.trim().is_empty() {
                continue;
            }
            let Some((key, value)) = text.split_once('=') else {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "MetaImage header line {line_no} (\"{}\") is not \"Key = Value\"",
                        text.chars().take(60).collect::<String>().escape_debug()
                    ),
                ));
            };
            let (key, value) = (key.trim(), value.trim());
            header.written.push((key.to_string(), value.to_string()));
            if header
                .fields
                .insert(key.to_string(), value.to_string())
                .is_some()
            {
                return Err(IoError::invalid(
                    path,
                    format!("MetaImage field {key} is given twice (line {line_no})"),
                ));
            }
            if key == "ElementDataFile" {
                header.data_offset = line.end;
                if value.starts_with("LIST") {
                    in_list = true;
                } else {
                    return Ok(header);
                }
            }
        }
        if in_list {
            return Ok(header);
        }
        let why = if lines.hit_limit() {
            format!("no ElementDataFile field in the first {MAX_HEADER} bytes")
        } else if header.written.is_empty() {
            "not a MetaImage header: no \"Key = Value\" lines".to_string()
        } else {
            "MetaImage header has no ElementDataFile field (it is required, as the last field)"
                .to_string()
        };
        Err(IoError::invalid(path, why))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &[u8]) -> Result<Header, IoError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.mha");
        std::fs::write(&path, text).unwrap();
        let file = File::open(&path).unwrap();
        Header::read(&path, file, text.len() as u64)
    }

    #[test]
    fn fields_up_to_the_data_file() {
        let text = b"ObjectType = Image\r\nNDims=3\n\nElementSpacing = 1 2 3\nElementDataFile = LOCAL\n\x00\x01=\n";
        let h = parse(text).unwrap();
        assert_eq!(h.get("NDims"), Some("3"));
        assert_eq!(h.get("ElementSpacing"), Some("1 2 3"));
        assert_eq!(h.get("ndims"), None);
        assert_eq!(h.get("ElementDataFile"), Some("LOCAL"));
        assert_eq!(h.data_offset, text.len() as u64 - 4);
        assert_eq!(h.written.len(), 4);
    }

    #[test]
    fn list_names_follow() {
        let h = parse(b"NDims = 3\nElementDataFile = LIST 2\na.raw\n\n b.raw\n").unwrap();
        assert_eq!(h.list, ["a.raw", "b.raw"]);
    }

    #[test]
    fn bad_headers() {
        let err = parse(b"NDims = 3\nDimSize = 2 2 2\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("has no ElementDataFile"), "{err}");
        let err = parse(b"NDims = 3\nNDims = 4\n").unwrap_err().to_string();
        assert!(err.contains("NDims is given twice (line 2)"), "{err}");
        let err = parse(b"NDims 3\n").unwrap_err().to_string();
        assert!(
            err.contains("line 1 (\"NDims 3\") is not \"Key = Value\""),
            "{err}"
        );
        let err = parse(b"NDims = 3\n\xff\xfe\n").unwrap_err().to_string();
        assert!(err.contains("line 2 is not text"), "{err}");
        let err = parse(b"").unwrap_err().to_string();
        assert!(err.contains("not a MetaImage header"), "{err}");
    }
}
