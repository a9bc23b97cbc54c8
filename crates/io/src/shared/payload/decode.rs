//! Decoding a region's stream into samples: inflating gzip and zlib
//! data (no more and no less than declared), and reading decimal text and
//! hexadecimal byte pairs.

use std::io::{self, BufRead, Read};
use std::path::Path;

use super::layout::Layout;
use crate::dtype::Stored;
use crate::error::IoError;
use crate::shared::text_reader::TextReader;

/// Bytes decoded per chunk from compressed and text streams.
const CHUNK: usize = 1 << 16;

/// A decoder's error: a corrupt stream is bad input, anything else is the
/// operating system's.
fn stream_error(path: &Path, name: &str, e: io::Error) -> IoError {
    match e.kind() {
        io::ErrorKind::InvalidInput | io::ErrorKind::InvalidData | io::ErrorKind::UnexpectedEof => {
            IoError::invalid(path, format!("corrupt {name} data: {e}"))
        }
        _ => IoError::os(path, "read", e),
    }
}

/// Reads up to `buf.len()` bytes, fewer only at the end of the stream.
fn read_full(reader: &mut dyn Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut done = 0;
    while done < buf.len() {
        match reader.read(&mut buf[done..]) {
            Ok(0) => break,
            Ok(n) => done += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(done)
}

pub(super) fn read_inflated<T: Stored>(
    path: &Path,
    name: &str,
    decoder: &mut dyn Read,
    samples: usize,
    layout: &Layout,
    sink: &mut dyn FnMut(&[T]),
) -> Result<(), IoError> {
    let skip = layout.inflated_skip;
    if skip > 0 {
        let skipped = io::copy(&mut decoder.take(skip), &mut io::sink())
            .map_err(|e| stream_error(path, name, e))?;
        if skipped < skip {
            return Err(IoError::invalid(
                path,
                format!(
                    "{name} data inflates to {skipped} bytes, less than the byte skip of {skip}"
                ),
            ));
        }
    }
    let size = layout.dtype.size();
    let expected = samples as u64 * size as u64;
    let chunk_samples = (CHUNK / size).max(1);
    let mut bytes = vec![0u8; chunk_samples.min(samples.max(1)) * size];
    let mut values = Vec::with_capacity(chunk_samples);
    let mut done = 0usize;
    while done < samples {
        let n = chunk_samples.min(samples - done);
        let buf = &mut bytes[..n * size];
        let got = read_full(decoder, buf).map_err(|e| stream_error(path, name, e))?;
        if got < buf.len() {
            return Err(IoError::invalid(
                path,
                format!(
                    "{name} data inflates to {} bytes, but the header declares {expected}",
                    skip + (done * size + got) as u64
                ),
            ));
        }
        values.clear();
        T::extend(&mut values, buf, layout.dtype, layout.endian);
        sink(&values);
        done += n;
    }
    let mut extra = [0u8; 1];
    if read_full(decoder, &mut extra).map_err(|e| stream_error(path, name, e))? > 0 {
        return Err(IoError::invalid(
            path,
            format!(
                "{name} data inflates past the {} bytes the header declares",
                skip.saturating_add(expected)
            ),
        ));
    }
    Ok(())
}

/// Reads `samples` decimal numbers separated by whitespace or commas;
/// anything after them is ignored.
pub(super) fn read_text<T: Stored>(
    path: &Path,
    reader: impl BufRead,
    samples: usize,
    sink: &mut dyn FnMut(&[T]),
) -> Result<(), IoError> {
    let mut values = Vec::with_capacity(CHUNK.min(samples));
    TextReader::data_section(path, reader).tokens(samples, "the text data", |n, token| {
        let v: f64 = token
            .parse()
            .map_err(|_| format!("text value {} is \"{token}\", not a number", n + 1))?;
        values.push(T::from_f64(v));
        if values.len() == CHUNK {
            sink(&values);
            values.clear();
        }
        Ok(())
    })?;
    sink(&values);
    Ok(())
}

/// Reads `samples` samples written as hexadecimal byte pairs.
pub(super) fn read_hex<T: Stored>(
    path: &Path,
    reader: &mut impl BufRead,
    samples: usize,
    layout: &Layout,
    sink: &mut dyn FnMut(&[T]),
) -> Result<(), IoError> {
    let size = layout.dtype.size();
    let total = samples * size;
    let chunk = (CHUNK / size).max(1) * size;
    let mut bytes = Vec::with_capacity(chunk.min(total));
    let mut values = Vec::new();
    let mut high: Option<u8> = None;
    let mut done = 0usize;
    while done < total {
        let buf = reader
            .fill_buf()
            .map_err(|e| IoError::os(path, "read", e))?;
        if buf.is_empty() {
            return Err(IoError::invalid(
                path,
                format!("the hex data holds {done} bytes, but the header declares {total}"),
            ));
        }
        let mut used = 0;
        for &b in buf {
            if done == total {
                break;
            }
            used += 1;
            if b.is_ascii_whitespace() {
                continue;
            }
            let digit = (b as char).to_digit(16).ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!(
                        "hex data byte {} holds '{}', not a hex digit",
                        done + 1,
                        b.escape_ascii()
                    ),
                )
            })? as u8;
            match high.take() {
                None => high = Some(digit),
                Some(h) => {
                    bytes.push(h << 4 | digit);
                    done += 1;
                    if bytes.len() == chunk || done == total {
                        values.clear();
                        T::extend(&mut values, &bytes, layout.dtype, layout.endian);
                        sink(&values);
                        bytes.clear();
                    }
                }
            }
        }
        reader.consume(used);
    }
    Ok(())
}
