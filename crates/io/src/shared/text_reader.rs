//! Streaming reader for the text volume formats (Gaussian cube, VASP
//! CHGCAR/CHG) and for the decimal text samples behind a NRRD or
//! MetaImage header: header lines one at a time, then long runs of
//! whitespace-separated numbers read token by token, so a file of
//! hundreds of megabytes is never held in memory as text.
//!
//! Every message names the line it is about (1-based; for data that starts
//! partway into a file, counted from the data's start and said so). Lines
//! and tokens have bounded lengths, so a file without line breaks cannot
//! make the reader allocate more than [`MAX_LINE`] bytes of text.

use std::io::{BufRead, ErrorKind, Read};
use std::path::{Path, PathBuf};

use crate::error::IoError;

/// Longest header line accepted: real headers are under 200 characters.
pub(crate) const MAX_LINE: usize = 1 << 16;

/// Longest number token accepted: `-1.23456789012345678E-123` is 25.
const MAX_TOKEN: usize = 64;

/// A text file read line by line and token by token.
pub(crate) struct TextReader<R> {
    path: PathBuf,
    inner: R,
    /// Complete lines consumed so far; the current line is `lines + 1`.
    lines: usize,
    /// False after a token run that stopped inside a line.
    at_line_start: bool,
    /// Whether commas separate tokens as white space does.
    commas: bool,
    /// What line numbers count from, after "line N" in messages: empty for
    /// a whole file.
    lines_of: &'static str,
}

impl<R: BufRead> TextReader<R> {
    pub(crate) fn new(path: &Path, inner: R) -> Self {
        TextReader {
            path: path.to_path_buf(),
            inner,
            lines: 0,
            at_line_start: true,
            commas: false,
            lines_of: "",
        }
    }

    /// A reader of the text samples that follow a header in `path`
    /// (`inner` starts at the data): commas separate numbers too, and
    /// messages count lines from the start of the data.
    pub(crate) fn data_section(path: &Path, inner: R) -> Self {
        TextReader {
            commas: true,
            lines_of: " of the data",
            ..TextReader::new(path, inner)
        }
    }

    /// The number of the line the reader is in (or about to read).
    pub(crate) fn line_number(&self) -> usize {
        self.lines + 1
    }

    /// A bad-input error about the line [`TextReader::line`] returned last.
    pub(crate) fn error(&self, reason: impl std::fmt::Display) -> IoError {
        self.error_at(self.lines.max(1), reason)
    }

    /// A bad-input error about line `line`.
    fn error_at(&self, line: usize, reason: impl std::fmt::Display) -> IoError {
        IoError::invalid(
            &self.path,
            format!("line {line}{}: {reason}", self.lines_of),
        )
    }

    /// The next line without its line break, or `None` at the end of the
    /// file. Refuses lines longer than [`MAX_LINE`] and bytes that are not
    /// UTF-8.
    pub(crate) fn try_line(&mut self) -> Result<Option<String>, IoError> {
        let mut bytes = Vec::new();
        let n = (&mut self.inner)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', &mut bytes)
            .map_err(|e| IoError::os(&self.path, "read", e))?;
        if n == 0 {
            return Ok(None);
        }
        let complete = bytes.last() == Some(&b'\n');
        if !complete && n > MAX_LINE {
            return Err(self.error(format!("longer than {MAX_LINE} characters")));
        }
        while matches!(bytes.last(), Some(b'\n' | b'\r')) {
            bytes.pop();
        }
        let text = String::from_utf8(bytes).map_err(|_| self.error("not UTF-8 text"))?;
        self.lines += 1;
        self.at_line_start = true;
        Ok(Some(text))
    }

    /// The next line; the end of the file is an error saying that `what`
    /// was expected there.
    pub(crate) fn line(&mut self, what: &str) -> Result<String, IoError> {
        match self.try_line()? {
            Some(line) => Ok(line),
            None => Err(IoError::invalid(
                &self.path,
                format!(
                    "file ends at line {}{} where {what} should be",
                    self.line_number(),
                    self.lines_of
                ),
            )),
        }
    }

    /// Reads exactly `count` whitespace-separated tokens, handing each with
    /// its index to `f`, which may refuse it with a reason. Tokens may
    /// span any number of lines; the reader stops right after the last
    /// one, possibly inside a line (see [`TextReader::finish_line`]).
    /// `what` names the values for the message when the file ends early.
    pub(crate) fn tokens(
        &mut self,
        count: usize,
        what: &str,
        mut f: impl FnMut(usize, &str) -> Result<(), String>,
    ) -> Result<(), IoError> {
        let mut token = [0u8; MAX_TOKEN];
        let mut len = 0;
        let mut done = 0;
        let (commas, lines_of) = (self.commas, self.lines_of);
        let error_at = |line: usize, reason: &dyn std::fmt::Display| {
            IoError::invalid(&self.path, format!("line {line}{lines_of}: {reason}"))
        };
        let mut emit = |token: &[u8], done: &mut usize, lines: usize| -> Result<(), IoError> {
            let text =
                std::str::from_utf8(token).map_err(|_| error_at(lines + 1, &"not UTF-8 text"))?;
            f(*done, text).map_err(|reason| error_at(lines + 1, &reason))?;
            *done += 1;
            Ok(())
        };
        while done < count {
            let buf = match self.inner.fill_buf() {
                Ok(buf) => buf,
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) => return Err(IoError::os(&self.path, "read", e)),
            };
            if buf.is_empty() {
                if len > 0 {
                    emit(&token[..len], &mut done, self.lines)?;
                    self.at_line_start = false;
                }
                if done < count {
                    return Err(IoError::invalid(
                        &self.path,
                        format!(
                            "file ends at line {}{lines_of} after {done} of the {count} values of {what}",
                            self.lines + 1
                        ),
                    ));
                }
                break;
            }
            let mut used = 0;
            for &b in buf {
                used += 1;
                if b.is_ascii_whitespace() || (commas && b == b',') {
                    if len > 0 {
                        emit(&token[..len], &mut done, self.lines)?;
                        len = 0;
                    }
                    if b == b'\n' {
                        self.lines += 1;
                        self.at_line_start = true;
                    } else {
                        self.at_line_start = false;
                    }
                    if done == count {
                        break;
                    }
                } else {
                    if len == MAX_TOKEN {
                        return Err(error_at(
                            self.lines + 1,
                            &format!("a value longer than {MAX_TOKEN} characters"),
                        ));
                    }
                    token[len] = b;
                    len += 1;
                    self.at_line_start = false;
                }
            }
            self.inner.consume(used);
        }
        Ok(())
    }

    /// Consumes the rest of the current line after a token run; refuses
    /// anything but white space there (more values than declared).
    pub(crate) fn finish_line(&mut self, what: &str) -> Result<(), IoError> {
        if self.at_line_start {
            return Ok(());
        }
        let line_number = self.line_number();
        if let Some(rest) = self.try_line()?
            && let Some(extra) = rest.split_whitespace().next()
        {
            return Err(self.error_at(
                line_number,
                format!("\"{extra}\" follows the last of {what}"),
            ));
        }
        Ok(())
    }

    /// Refuses anything but blank lines from here to the end of the file.
    pub(crate) fn expect_end(&mut self, what: &str) -> Result<(), IoError> {
        self.finish_line(what)?;
        while let Some(line) = self.try_line()? {
            if let Some(extra) = line.split_whitespace().next() {
                return Err(self.error_at(
                    self.lines,
                    format!("\"{extra}\" follows the last of {what}"),
                ));
            }
        }
        Ok(())
    }
}

/// Parses a number as Fortran programs write them: Rust's syntax, plus a
/// `D` exponent (`1.0D-05`) and the exponent without its letter that
/// Fortran's `E` edit descriptor writes when it has three digits
/// (`0.12345-100` for 0.12345E-100).
pub(crate) fn parse_number(token: &str) -> Option<f64> {
    if let Ok(v) = token.parse::<f64>() {
        return Some(v);
    }
    if token.contains(['D', 'd']) {
        return token.replace(['D', 'd'], "E").parse().ok();
    }
    let bytes = token.as_bytes();
    let at = (1..bytes.len()).rev().find(|&i| {
        matches!(bytes[i], b'+' | b'-') && (bytes[i - 1].is_ascii_digit() || bytes[i - 1] == b'.')
    })?;
    format!("{}E{}", &token[..at], &token[at..]).parse().ok()
}

/// Parses a number token from a file for the value called `what`.
pub(crate) fn number(token: &str, what: &str) -> Result<f64, String> {
    parse_number(token).ok_or_else(|| format!("{what}: \"{token}\" is not a number"))
}

/// Parses an integer token for the field called `what`.
/// The whole lines of a file's first bytes, as the format sniffers get
/// them: a last line without its newline may have been cut by the window
/// and is left out.
pub(crate) fn whole_lines(text: &str) -> impl Iterator<Item = &str> {
    let whole = text.rfind('\n').map_or("", |end| &text[..end]);
    whole.lines()
}

/// The finite numbers of `line`, if every whitespace-separated token is one.
pub(crate) fn all_numbers(line: &str) -> Option<Vec<f64>> {
    line.split_whitespace()
        .map(|t| parse_number(t).filter(|v| v.is_finite()))
        .collect()
}

pub(crate) fn integer(token: &str, what: &str) -> Result<i64, String> {
    token
        .parse::<i64>()
        .map_err(|_| format!("{what}: \"{token}\" is not an integer"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn reader(text: &str) -> TextReader<Cursor<Vec<u8>>> {
        TextReader::new(Path::new("t.txt"), Cursor::new(text.as_bytes().to_vec()))
    }

    #[test]
    fn fortran_numbers() {
        assert_eq!(parse_number("1.5"), Some(1.5));
        assert_eq!(parse_number("-2.5E+02"), Some(-250.0));
        assert_eq!(parse_number("1.0D-02"), Some(0.01));
        assert_eq!(parse_number("0.25d1"), Some(2.5));
        assert_eq!(parse_number("0.12345-100"), Some(0.12345e-100));
        assert_eq!(parse_number("-0.5+101"), Some(-0.5e101));
        assert_eq!(parse_number("1.-5"), Some(1e-5));
        for bad in ["", "-", "abc", "1.2.3", "**********", "1e", "+-1"] {
            assert_eq!(parse_number(bad), None, "{bad}");
        }
    }

    #[test]
    fn lines_and_tokens_interleave() {
        let mut r = reader("head one\r\n  1 2 3\n4\n\n 5 6 7\ntail\n");
        assert_eq!(r.line("head").unwrap(), "head one");
        let mut got = Vec::new();
        r.tokens(5, "values", |i, t| {
            got.push((i, number(t, "v")?));
            Ok(())
        })
        .unwrap();
        assert_eq!(
            got,
            [(0, 1.0), (1, 2.0), (2, 3.0), (3, 4.0), (4, 5.0)],
            "tokens cross line breaks and blank lines"
        );
        assert_eq!(r.line_number(), 5);
        let err = r.finish_line("the block").unwrap_err().to_string();
        assert_eq!(err, "t.txt: line 5: \"6\" follows the last of the block");
        assert_eq!(r.line("tail").unwrap(), "tail");
        assert!(r.try_line().unwrap().is_none());
        let err = r.line("the grid").unwrap_err().to_string();
        assert_eq!(err, "t.txt: file ends at line 7 where the grid should be");
    }

    #[test]
    fn token_run_ending_at_a_line_break_finishes_cleanly() {
        let mut r = reader("1 2\n3 4\nnext\n");
        r.tokens(2, "values", |_, _| Ok(())).unwrap();
        r.finish_line("values").unwrap();
        assert_eq!(r.line("next").unwrap(), "3 4");
        // Without a final line break the last token still counts.
        let mut r = reader("1 2\n3");
        let mut n = 0;
        r.tokens(3, "values", |_, _| {
            n += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(n, 3);
        r.expect_end("values").unwrap();
    }

    #[test]
    fn short_data_bad_tokens_and_trailing_values_are_refused() {
        let mut r = reader("1 2\n3\n");
        let err = r.tokens(5, "the grid", |_, _| Ok(())).unwrap_err();
        assert_eq!(
            err.to_string(),
            "t.txt: file ends at line 3 after 3 of the 5 values of the grid"
        );
        let mut r = reader("1 2\n3 x 5\n");
        let err = r
            .tokens(5, "the grid", |_, t| number(t, "value").map(|_| ()))
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "t.txt: line 2: value: \"x\" is not a number"
        );
        let mut r = reader("1 2\n\n 9\n");
        r.tokens(2, "data", |_, _| Ok(())).unwrap();
        let err = r.expect_end("data").unwrap_err().to_string();
        assert_eq!(err, "t.txt: line 3: \"9\" follows the last of data");
        let long = "7".repeat(MAX_TOKEN + 1);
        let mut r = reader(&long);
        let err = r.tokens(1, "data", |_, _| Ok(())).unwrap_err().to_string();
        assert!(err.contains("longer than 64 characters"), "{err}");
    }

    #[test]
    fn data_sections_split_at_commas_and_count_their_own_lines() {
        let data = |text: &str| {
            TextReader::data_section(Path::new("d.nrrd"), Cursor::new(text.as_bytes().to_vec()))
        };
        let mut got = Vec::new();
        data("1,2 ,3\n,4")
            .tokens(4, "the data", |_, t| {
                got.push(number(t, "v")?);
                Ok(())
            })
            .unwrap();
        assert_eq!(got, [1.0, 2.0, 3.0, 4.0]);
        let err = data("1\n2,x")
            .tokens(3, "the data", |_, t| number(t, "value").map(|_| ()))
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "d.nrrd: line 2 of the data: value: \"x\" is not a number"
        );
        let err = data("1\n")
            .tokens(2, "the data", |_, _| Ok(()))
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "d.nrrd: file ends at line 2 of the data after 1 of the 2 values of the data"
        );
        // Whole files keep commas inside tokens.
        let err = reader("1,2")
            .tokens(1, "values", |_, t| number(t, "value").map(|_| ()))
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "t.txt: line 1: value: \"1,2\" is not a number"
        );
    }

    #[test]
    fn overlong_and_binary_lines_are_refused() {
        let mut r = reader(&"x".repeat(MAX_LINE + 10));
        let err = r.line("a comment").unwrap_err().to_string();
        assert!(err.contains("line 1: longer than 65536"), "{err}");
        let mut r = TextReader::new(Path::new("b"), Cursor::new(vec![b'a', 0xff, b'\n']));
        let err = r.line("a comment").unwrap_err().to_string();
        assert_eq!(err, "b: line 1: not UTF-8 text");
    }

    #[test]
    fn integers() {
        assert_eq!(integer("-12", "n"), Ok(-12));
        assert_eq!(
            integer("1.5", "NGX"),
            Err("NGX: \"1.5\" is not an integer".into())
        );
    }
}
