//! Reading a legacy VTK file as VTK's own reader does: whitespace-separated
//! keywords and numbers, whole lines for the title and metadata, and runs
//! of raw bytes for BINARY data, all from one buffered stream that knows
//! its position and how many bytes the file has left.
//!
//! Tokens and lines have bounded lengths, so a file of garbage cannot make
//! the reader buffer more than [`MAX_TOKEN`] or [`MAX_LINE`] bytes.

use std::io::{self, BufRead, Seek};
use std::path::{Path, PathBuf};

use crate::error::IoError;

/// Longest keyword, name or number accepted (VTK itself reads 256).
pub(crate) const MAX_TOKEN: usize = 1024;

/// Longest title or metadata line accepted (VTK itself reads 256).
pub(crate) const MAX_LINE: usize = 1 << 16;

/// A legacy VTK file being read.
pub(crate) struct Lexer<R> {
    path: PathBuf,
    inner: R,
    /// Bytes consumed so far.
    pos: u64,
    /// The file's length.
    len: u64,
    /// A token read ahead by [`Lexer::peek_token`].
    pending: Option<String>,
}

impl<R: BufRead + Seek> Lexer<R> {
    pub(crate) fn new(path: &Path, inner: R, len: u64) -> Self {
        Lexer {
            path: path.to_path_buf(),
            inner,
            pos: 0,
            len,
            pending: None,
        }
    }

    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Bytes consumed so far (a peeked token counts as consumed).
    pub(crate) fn pos(&self) -> u64 {
        self.pos
    }

    /// Bytes left in the file after [`Lexer::pos`].
    pub(crate) fn remaining(&self) -> u64 {
        self.len.saturating_sub(self.pos)
    }

    fn io(&self, e: io::Error) -> IoError {
        IoError::os(&self.path, "read", e)
    }

    /// The next byte without consuming it, `None` at the end of the file.
    fn peek_byte(&mut self) -> Result<Option<u8>, IoError> {
        loop {
            match self.inner.fill_buf() {
                Ok(buf) => return Ok(buf.first().copied()),
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(self.io(e)),
            }
        }
    }

    fn consume(&mut self, n: usize) {
        self.inner.consume(n);
        self.pos += n as u64;
    }

    /// The next whitespace-separated token, `None` at the end of the file.
    pub(crate) fn next_token(&mut self) -> Result<Option<String>, IoError> {
        if let Some(t) = self.pending.take() {
            return Ok(Some(t));
        }
        while let Some(b) = self.peek_byte()? {
            if b.is_ascii_whitespace() {
                self.consume(1);
            } else {
                break;
            }
        }
        let start = self.pos;
        let mut token = Vec::new();
        while let Some(b) = self.peek_byte()? {
            if b.is_ascii_whitespace() {
                break;
            }
            if token.len() == MAX_TOKEN {
                return Err(IoError::invalid(
                    &self.path,
                    format!(
                        "text at byte {start} runs on for more than {MAX_TOKEN} bytes without a space: not a legacy VTK keyword or number"
                    ),
                ));
            }
            token.push(b);
            self.consume(1);
        }
        if token.is_empty() {
            return Ok(None);
        }
        Ok(Some(String::from_utf8_lossy(&token).into_owned()))
    }

    /// The next token without consuming it.
    pub(crate) fn peek_token(&mut self) -> Result<Option<&str>, IoError> {
        if self.pending.is_none() {
            self.pending = self.next_token()?;
        }
        Ok(self.pending.as_deref())
    }

    /// The next token; at the end of the file an error saying `what` was
    /// expected.
    pub(crate) fn expect(&mut self, what: &str) -> Result<String, IoError> {
        self.next_token()?.ok_or_else(|| {
            IoError::invalid(
                &self.path,
                format!("file ends where {what} should be (byte {})", self.pos),
            )
        })
    }

    /// The next token as a number of type `T`.
    pub(crate) fn number<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, IoError> {
        let t = self.expect(what)?;
        t.parse().map_err(|_| {
            IoError::invalid(
                &self.path,
                format!("{what} is \"{t}\": not a valid number here"),
            )
        })
    }

    /// The rest of the current line (without `\r\n`), and the line break.
    /// `None` at the end of the file.
    pub(crate) fn line(&mut self) -> Result<Option<String>, IoError> {
        debug_assert!(self.pending.is_none(), "line() after peek_token()");
        let mut bytes = Vec::new();
        let mut any = false;
        while let Some(b) = self.peek_byte()? {
            any = true;
            self.consume(1);
            if b == b'\n' {
                break;
            }
            if bytes.len() == MAX_LINE {
                return Err(IoError::invalid(
                    &self.path,
                    format!(
                        "line ending at byte {} is longer than {MAX_LINE} bytes",
                        self.pos
                    ),
                ));
            }
            bytes.push(b);
        }
        if !any {
            return Ok(None);
        }
        if bytes.last() == Some(&b'\r') {
            bytes.pop();
        }
        Ok(Some(String::from_utf8_lossy(&bytes).into_owned()))
    }

    /// Skips the rest of the current line, as VTK does between the words
    /// that announce BINARY data and the data itself.
    pub(crate) fn end_line(&mut self) -> Result<(), IoError> {
        debug_assert!(self.pending.is_none(), "end_line() after peek_token()");
        while let Some(b) = self.peek_byte()? {
            self.consume(1);
            if b == b'\n' {
                break;
            }
        }
        Ok(())
    }

    /// Fills `buf` with the next bytes; the caller has checked that the
    /// file has them, so a short read means the file changed.
    pub(crate) fn bytes(&mut self, buf: &mut [u8]) -> Result<(), IoError> {
        debug_assert!(self.pending.is_none(), "bytes() after peek_token()");
        let expected = self.pos + buf.len() as u64;
        let mut done = 0;
        while done < buf.len() {
            let avail = match self.inner.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(self.io(e)),
            };
            if avail.is_empty() {
                return Err(IoError::Truncated {
                    path: self.path.clone(),
                    read: self.pos,
                    expected,
                });
            }
            let n = avail.len().min(buf.len() - done);
            buf[done..done + n].copy_from_slice(&avail[..n]);
            self.consume(n);
            done += n;
        }
        Ok(())
    }

    /// Skips `n` bytes, which the caller has checked the file has.
    pub(crate) fn skip(&mut self, n: u64) -> Result<(), IoError> {
        debug_assert!(self.pending.is_none(), "skip() after peek_token()");
        let offset = i64::try_from(n)
            .map_err(|_| IoError::invalid(&self.path, format!("cannot skip {n} bytes")))?;
        self.inner.seek_relative(offset).map_err(|e| self.io(e))?;
        self.pos += n;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn lexer(text: &[u8]) -> Lexer<Cursor<Vec<u8>>> {
        Lexer::new(
            Path::new("t.vtk"),
            Cursor::new(text.to_vec()),
            text.len() as u64,
        )
    }

    #[test]
    fn tokens_lines_and_bytes() {
        let mut l = lexer(
            b"# vtk DataFile Version 3.0\r\ntitle  here \nBINARY\nSCALARS a float\n\x01\x02rest 7",
        );
        assert_eq!(
            l.line().unwrap().as_deref(),
            Some("# vtk DataFile Version 3.0")
        );
        assert_eq!(l.line().unwrap().as_deref(), Some("title  here "));
        assert_eq!(l.peek_token().unwrap(), Some("BINARY"));
        assert_eq!(l.next_token().unwrap().as_deref(), Some("BINARY"));
        assert_eq!(l.expect("keyword").unwrap(), "SCALARS");
        assert_eq!(l.expect("name").unwrap(), "a");
        assert_eq!(l.expect("type").unwrap(), "float");
        l.end_line().unwrap();
        let mut two = [0u8; 2];
        l.bytes(&mut two).unwrap();
        assert_eq!(two, [1, 2]);
        assert_eq!(l.remaining(), 6);
        l.skip(4).unwrap();
        assert_eq!(l.number::<u32>("count").unwrap(), 7);
        assert_eq!(l.next_token().unwrap(), None);
        let err = l.expect("DATASET").unwrap_err().to_string();
        assert!(err.contains("file ends where DATASET should be"), "{err}");
    }

    #[test]
    fn bad_numbers_and_runaway_tokens() {
        let mut l = lexer(b"DIMENSIONS x");
        l.next_token().unwrap();
        let err = l.number::<usize>("DIMENSIONS").unwrap_err().to_string();
        assert!(err.contains("DIMENSIONS is \"x\""), "{err}");
        let long = vec![b'a'; MAX_TOKEN + 1];
        let err = lexer(&long).next_token().unwrap_err().to_string();
        assert!(err.contains("more than 1024 bytes"), "{err}");
    }

    #[test]
    fn short_binary_data_is_truncation() {
        let mut l = lexer(b"ab");
        let mut buf = [0u8; 3];
        let err = l.bytes(&mut buf).unwrap_err();
        assert!(matches!(err, IoError::Truncated { .. }), "{err}");
    }
}
