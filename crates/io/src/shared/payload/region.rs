//! Where each region's data lies ([`Region::locate`], after any skipped
//! lines and bytes), and whether it can hold what the header declares
//! ([`check_region`]) before anything is allocated.

use std::fs::File;
use std::io::{BufRead, BufReader, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use super::layout::{Encoding, Layout};
use crate::error::IoError;
use crate::shared::input::open_input;

/// Deflate's largest compression ratio (RFC 1951: a 258-byte match costs
/// at least two bits, so 1032 output bytes per input byte at most).
use crate::shared::compress::{MAX_BZIP2_RATIO, MAX_DEFLATE_RATIO};

/// How far into a file the data starts, after the base position and any
/// skipped lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Skip {
    /// This many bytes further on.
    Forward(u64),
    /// The data (`data_len` bytes) ends this many bytes before the end of
    /// the file (NRRD `byte skip: -1` is 0, MetaImage `HeaderSize = -1`).
    BeforeEnd(u64),
}

/// Where one region's data lies: `len` bytes from `start` in `path`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Region {
    pub path: PathBuf,
    pub start: u64,
    pub len: u64,
}

impl Region {
    /// Finds the data in `path`: from `base`, skip `line_skip` lines, then
    /// apply `skip`. `data_len` is what the data needs on disk, used for
    /// [`Skip::BeforeEnd`]; otherwise the region runs to the end of the
    /// file. `what` names the skip fields for messages.
    pub(crate) fn locate(
        path: &Path,
        base: u64,
        line_skip: u64,
        skip: Skip,
        data_len: u64,
        what: &str,
    ) -> Result<Region, IoError> {
        let (file, file_len) = open_input(path)?;
        if base > file_len {
            return Err(IoError::invalid(
                path,
                format!("the data should start at byte {base} but the file has {file_len} bytes"),
            ));
        }
        let mut pos = base;
        if line_skip > 0 {
            pos = skip_lines(path, file, base, line_skip, file_len, what)?;
        }
        match skip {
            Skip::Forward(n) => {
                let start = pos.checked_add(n).filter(|&s| s <= file_len).ok_or_else(|| {
                    IoError::invalid(
                        path,
                        format!(
                            "{what}: skipping {n} bytes from byte {pos} passes the end of the file ({file_len} bytes)"
                        ),
                    )
                })?;
                Ok(Region {
                    path: path.to_path_buf(),
                    start,
                    len: file_len - start,
                })
            }
            Skip::BeforeEnd(trailing) => {
                let start = file_len
                    .checked_sub(trailing)
                    .and_then(|end| end.checked_sub(data_len))
                    .filter(|&s| s >= pos)
                    .ok_or_else(|| {
                        IoError::invalid(
                            path,
                            format!(
                                "{what}: the data ({data_len} bytes) should end {trailing} bytes before the end of the file, but only {} bytes follow the header",
                                file_len - pos
                            ),
                        )
                    })?;
                Ok(Region {
                    path: path.to_path_buf(),
                    start,
                    len: data_len,
                })
            }
        }
    }

    /// The same region cut to its first `len` bytes (a declared compressed
    /// size); more than the region holds is an error naming `what`.
    pub(crate) fn limit(mut self, len: u64, what: &str) -> Result<Region, IoError> {
        if len > self.len {
            return Err(IoError::invalid(
                &self.path,
                format!(
                    "{what} = {len} but only {} bytes follow byte {}",
                    self.len, self.start
                ),
            ));
        }
        self.len = len;
        Ok(self)
    }
}

/// Skips `lines` newline-terminated lines from `base`; returns the
/// position after them.
fn skip_lines(
    path: &Path,
    mut file: File,
    base: u64,
    lines: u64,
    file_len: u64,
    what: &str,
) -> Result<u64, IoError> {
    file.seek(SeekFrom::Start(base))
        .map_err(|e| IoError::os(path, "seek in", e))?;
    let mut reader = BufReader::new(file);
    let mut pos = base;
    for done in 0..lines {
        // Read through the next newline, never past the end of the file.
        loop {
            let buf = reader
                .fill_buf()
                .map_err(|e| IoError::os(path, "read", e))?;
            if buf.is_empty() {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "{what}: {lines} lines to skip but the file ends after {done} (at byte {file_len})"
                    ),
                ));
            }
            match buf.iter().position(|&b| b == b'\n') {
                Some(i) => {
                    reader.consume(i + 1);
                    pos += i as u64 + 1;
                    break;
                }
                None => {
                    let n = buf.len();
                    reader.consume(n);
                    pos += n as u64;
                }
            }
        }
    }
    Ok(pos)
}

/// Checks that `region` can hold `samples` samples of `layout` before any
/// of them is allocated. Raw data may be followed by more bytes than it
/// needs: that is noted in `notes`, not refused.
pub(crate) fn check_region(
    region: &Region,
    samples: usize,
    layout: &Layout,
    notes: &mut Vec<String>,
) -> Result<(), IoError> {
    let path = &region.path;
    let bytes = (samples as u64)
        .checked_mul(layout.dtype.size() as u64)
        .ok_or_else(|| {
            IoError::invalid(
                path,
                "the header describes more data than this machine can address",
            )
        })?;
    match layout.encoding {
        Encoding::Raw => {
            if region.len < bytes {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "the header declares {samples} samples of {} ({bytes} bytes) from byte {}, but the file has only {} bytes there",
                        layout.dtype, region.start, region.len
                    ),
                ));
            }
            if region.len > bytes {
                notes.push(format!(
                    "{}: {} bytes after the data ignored",
                    path.display(),
                    region.len - bytes
                ));
            }
        }
        Encoding::Hex => {
            if region.len / 2 < bytes {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "the header declares {bytes} bytes of hex data (two digits each) from byte {}, but the file has only {} bytes there",
                        region.start, region.len
                    ),
                ));
            }
        }
        Encoding::Text => {
            // Every number takes a digit and, but for the last, a separator.
            if samples > 0 && region.len < (samples as u64).saturating_mul(2) - 1 {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "the header declares {samples} text values, but the {} bytes from byte {} cannot hold that many numbers",
                        region.len, region.start
                    ),
                ));
            }
        }
        Encoding::Gzip | Encoding::Zlib => {
            let needed = bytes.saturating_add(layout.inflated_skip);
            if needed > region.len.saturating_mul(MAX_DEFLATE_RATIO) {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "the header declares {needed} bytes of data, but {} compressed bytes cannot inflate to more than {} (deflate's limit is {MAX_DEFLATE_RATIO}:1)",
                        region.len,
                        region.len.saturating_mul(MAX_DEFLATE_RATIO)
                    ),
                ));
            }
        }
        Encoding::Bzip2 => {
            let needed = bytes.saturating_add(layout.inflated_skip);
            if needed > region.len.saturating_mul(MAX_BZIP2_RATIO) {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "the header declares {needed} bytes of data, but {} bzip2-compressed bytes cannot decode to more than {}",
                        region.len,
                        region.len.saturating_mul(MAX_BZIP2_RATIO)
                    ),
                ));
            }
        }
    }
    Ok(())
}
