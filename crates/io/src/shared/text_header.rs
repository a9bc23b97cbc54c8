//! What the NRRD and MetaImage readers share about their text headers:
//! reading the header's lines at the start of a file within a bound
//! ([`HeaderLines`]), and the values of its fields, integers and per-axis
//! lists, each refusal naming the field the way the format's messages do
//! ([`Field`]). Which fields exist and what they mean is each format's own
//! business (`nrrd/`, `metaimage/`).

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Take};
use std::path::Path;

use crate::error::IoError;

/// Largest header read, in bytes. Real headers are a few kilobytes; a
/// `LIST` of ten thousand data file names is a few hundred.
pub(crate) const MAX_HEADER: u64 = 16 << 20;

/// A header format, for the wording of messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum HeaderFormat {
    Nrrd,
    MetaImage,
}

impl HeaderFormat {
    fn name(self) -> &'static str {
        match self {
            HeaderFormat::Nrrd => "NRRD",
            HeaderFormat::MetaImage => "MetaImage",
        }
    }
}

/// The lines of a text header at the start of a file, read no further than
/// [`MAX_HEADER`] bytes.
pub(crate) struct HeaderLines {
    reader: BufReader<Take<File>>,
    buf: Vec<u8>,
    /// Bytes consumed: where the next line starts.
    pos: u64,
    /// Lines returned so far.
    count: usize,
}

/// One line of a header.
pub(crate) struct Line<'a> {
    /// The line without its `\n` or `\r\n`.
    pub bytes: &'a [u8],
    /// 1-based.
    pub number: usize,
    /// Where the next line starts (just past this one's line break).
    pub end: u64,
    /// Whether the line ended with a line break (not with the file).
    pub ended: bool,
}

impl HeaderLines {
    /// The lines of `file`, which is `file_len` bytes long.
    pub(crate) fn new(file: File, file_len: u64) -> Self {
        HeaderLines {
            reader: BufReader::new(file.take(MAX_HEADER.min(file_len))),
            buf: Vec::new(),
            pos: 0,
            count: 0,
        }
    }

    /// The next line, or `None` at the end of the file or of [`MAX_HEADER`].
    pub(crate) fn next(&mut self, path: &Path) -> Result<Option<Line<'_>>, IoError> {
        self.buf.clear();
        let n = self
            .reader
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| IoError::os(path, "read", e))?;
        if n == 0 {
            return Ok(None);
        }
        self.pos += n as u64;
        self.count += 1;
        let ended = self.buf.last() == Some(&b'\n');
        while matches!(self.buf.last(), Some(b'\n' | b'\r')) {
            self.buf.pop();
        }
        Ok(Some(Line {
            bytes: &self.buf,
            number: self.count,
            end: self.pos,
            ended,
        }))
    }

    /// Lines returned so far.
    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// Whether the lines stopped at [`MAX_HEADER`] rather than at the end
    /// of the file.
    pub(crate) fn hit_limit(&self) -> bool {
        self.pos >= MAX_HEADER
    }
}

impl<'a> Line<'a> {
    /// The line as text; a line that is not UTF-8 is refused with `hint`,
    /// which says what that suggests in `format` (binary data read as header).
    pub(crate) fn text(
        &self,
        path: &Path,
        format: HeaderFormat,
        hint: &str,
    ) -> Result<&'a str, IoError> {
        std::str::from_utf8(self.bytes).map_err(|_| {
            IoError::invalid(
                path,
                format!(
                    "{} header line {} is not text: {hint}",
                    format.name(),
                    self.number
                ),
            )
        })
    }
}

/// A field of a header in `path`, for parsing its value: messages say
/// `NRRD field "sizes": ...` (NRRD field names hold spaces, so they are
/// quoted) or `MetaImage field DimSize: ...`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Field<'a> {
    pub format: HeaderFormat,
    pub path: &'a Path,
    pub name: &'a str,
}

impl<'a> Field<'a> {
    pub(crate) fn nrrd(path: &'a Path, name: &'a str) -> Self {
        Field {
            format: HeaderFormat::Nrrd,
            path,
            name,
        }
    }

    pub(crate) fn metaimage(path: &'a Path, name: &'a str) -> Self {
        Field {
            format: HeaderFormat::MetaImage,
            path,
            name,
        }
    }

    /// The field's name as messages write it.
    fn shown(&self) -> String {
        match self.format {
            HeaderFormat::Nrrd => format!("\"{}\"", self.name),
            HeaderFormat::MetaImage => self.name.to_string(),
        }
    }

    /// A bad-input error about the field's value: `why` says what is wrong.
    pub(crate) fn error(&self, why: impl std::fmt::Display) -> IoError {
        IoError::invalid(
            self.path,
            format!("{} field {}: {why}", self.format.name(), self.shown()),
        )
    }

    /// The value of a field the format requires, `value` if given.
    pub(crate) fn required<'v>(&self, value: Option<&'v str>) -> Result<&'v str, IoError> {
        value.ok_or_else(|| {
            IoError::invalid(
                self.path,
                format!(
                    "{} header has no {} field (it is required)",
                    self.format.name(),
                    self.shown()
                ),
            )
        })
    }

    pub(crate) fn uint(&self, value: &str) -> Result<usize, IoError> {
        value
            .trim()
            .parse()
            .map_err(|_| self.error(format!("\"{value}\" is not a non-negative integer")))
    }

    /// The whitespace-separated words of `value`, which must number `n`
    /// (in NRRD always the dimension).
    pub(crate) fn words<'v>(&self, value: &'v str, n: usize) -> Result<Vec<&'v str>, IoError> {
        let w: Vec<&str> = value.split_whitespace().collect();
        if w.len() != n {
            let k = w.len();
            return Err(self.error(match self.format {
                HeaderFormat::Nrrd => format!("{k} values but dimension is {n}"),
                HeaderFormat::MetaImage => format!("{k} values but {n} are needed"),
            }));
        }
        Ok(w)
    }

    /// `n` numbers (`nan` and `inf` included: what they mean, if anything,
    /// is up to the format).
    pub(crate) fn numbers(&self, value: &str, n: usize) -> Result<Vec<f64>, IoError> {
        self.words(value, n)?
            .iter()
            .map(|w| {
                w.parse::<f64>()
                    .map_err(|_| self.error(format!("\"{w}\" is not a number")))
            })
            .collect()
    }

    /// `n` axis sizes, none of them 0.
    pub(crate) fn sizes(&self, value: &str, n: usize) -> Result<Vec<usize>, IoError> {
        let sizes = self
            .words(value, n)?
            .iter()
            .map(|w| self.uint(w))
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(a) = sizes.iter().position(|&s| s == 0) {
            return Err(self.error(format!("axis {a} has size 0")));
        }
        Ok(sizes)
    }

    /// The number of samples an array of `sizes` holds, refused unless
    /// that many samples of `sample_size` bytes can be addressed (every
    /// product of some of the sizes then fits too).
    pub(crate) fn sample_count(
        &self,
        sizes: &[usize],
        sample_size: usize,
    ) -> Result<usize, IoError> {
        sizes
            .iter()
            .try_fold(1usize, |acc, &s| acc.checked_mul(s))
            .filter(|n| n.checked_mul(sample_size).is_some())
            .ok_or_else(|| {
                self.error(format!(
                    "{sizes:?} describe more data than this machine can address"
                ))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines_of(text: &[u8]) -> Vec<(Vec<u8>, usize, u64, bool)> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h");
        std::fs::write(&path, text).unwrap();
        let mut lines = HeaderLines::new(File::open(&path).unwrap(), text.len() as u64);
        let mut out = Vec::new();
        while let Some(l) = lines.next(&path).unwrap() {
            out.push((l.bytes.to_vec(), l.number, l.end, l.ended));
        }
        assert_eq!(lines.count(), out.len());
        assert!(!lines.hit_limit());
        out
    }

    #[test]
    fn lines_lose_their_breaks_and_know_where_they_end() {
        assert_eq!(
            lines_of(b"a: 1\r\n\nb"),
            [
                (b"a: 1".to_vec(), 1, 6, true),
                (b"".to_vec(), 2, 7, true),
                (b"b".to_vec(), 3, 8, false),
            ]
        );
        assert!(lines_of(b"").is_empty());
        let line = Line {
            bytes: b"\xff\xfe",
            number: 4,
            end: 0,
            ended: true,
        };
        let err = line
            .text(Path::new("f.mha"), HeaderFormat::MetaImage, "binary?")
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "f.mha: MetaImage header line 4 is not text: binary?"
        );
    }

    #[test]
    fn values_and_messages_in_each_format() {
        let p = Path::new("f");
        let nrrd = Field::nrrd(p, "sizes");
        let meta = Field::metaimage(p, "DimSize");
        assert_eq!(nrrd.sizes(" 4 3\t5 ", 3).unwrap(), [4, 3, 5]);
        assert_eq!(
            nrrd.sizes("4 3", 3).unwrap_err().to_string(),
            "f: NRRD field \"sizes\": 2 values but dimension is 3"
        );
        assert_eq!(
            meta.sizes("4 3", 3).unwrap_err().to_string(),
            "f: MetaImage field DimSize: 2 values but 3 are needed"
        );
        assert_eq!(
            meta.sizes("4 0 5", 3).unwrap_err().to_string(),
            "f: MetaImage field DimSize: axis 1 has size 0"
        );
        assert_eq!(
            nrrd.uint("-2").unwrap_err().to_string(),
            "f: NRRD field \"sizes\": \"-2\" is not a non-negative integer"
        );
        assert_eq!(
            meta.required(None).unwrap_err().to_string(),
            "f: MetaImage header has no DimSize field (it is required)"
        );
        assert_eq!(nrrd.required(Some("x")).unwrap(), "x");
        let n = nrrd.numbers("1.5 nan -inf", 3).unwrap();
        assert_eq!((n[0], n[2]), (1.5, f64::NEG_INFINITY));
        assert!(n[1].is_nan());
        assert_eq!(
            meta.numbers("1 x", 2).unwrap_err().to_string(),
            "f: MetaImage field DimSize: \"x\" is not a number"
        );
        assert_eq!(nrrd.sample_count(&[4, 3, 5], 8).unwrap(), 60);
        let huge = [usize::MAX / 2, 3];
        assert!(
            nrrd.sample_count(&huge, 1)
                .unwrap_err()
                .to_string()
                .contains("describe more data than this machine can address")
        );
        assert!(nrrd.sample_count(&[usize::MAX / 4, 1], 8).is_err());
    }
}
