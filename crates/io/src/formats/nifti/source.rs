//! Where a NIfTI file's bytes come from: the `.nii` itself or the `.img`
//! beside a `.hdr`, plain or gzip-compressed. A gzip file (`.nii.gz`, or
//! any file starting with the gzip magic) is inflated as a stream, so a
//! header that lies about the data size runs into the end of the stream
//! instead of making volray allocate what it claims.

use std::fs::File;
use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use flate2::read::MultiGzDecoder;

use crate::error::IoError;
use crate::shared::input::{open_input, read_exact_at};

/// Where the samples come from: the `.nii` itself, or the `.img` of a pair,
/// plain or gzip-compressed.
pub(super) enum Source {
    Plain(BufReader<File>),
    Gzip(Box<MultiGzDecoder<BufReader<File>>>),
}

impl Source {
    /// Opens `path`, telling gzip from plain data by the gzip magic.
    /// Returns the source and the file's length in bytes.
    pub(super) fn open(path: &Path) -> Result<(Source, u64), IoError> {
        let (mut file, len) = open_input(path)?;
        let mut magic = [0u8; 2];
        let is_gzip = len >= 2 && {
            read_exact_at(path, &mut file, &mut magic, 0, len)?;
            file.seek(SeekFrom::Start(0))
                .map_err(|e| IoError::os(path, "seek in", e))?;
            magic == [0x1f, 0x8b]
        };
        let reader = BufReader::new(file);
        let source = if is_gzip {
            Source::Gzip(Box::new(MultiGzDecoder::new(reader)))
        } else {
            Source::Plain(reader)
        };
        Ok((source, len))
    }

    pub(super) fn is_gzip(&self) -> bool {
        matches!(self, Source::Gzip(_))
    }

    /// Fills `buf` from the current position. `at` is that position in the
    /// (uncompressed) data and `expected` the total the header implies,
    /// both for messages.
    pub(super) fn fill(
        &mut self,
        path: &Path,
        buf: &mut [u8],
        at: u64,
        expected: u64,
    ) -> Result<(), IoError> {
        match self {
            Source::Plain(r) => read_exact_at(path, r, buf, at, expected),
            Source::Gzip(r) => {
                let mut done = 0;
                while done < buf.len() {
                    match r.read(&mut buf[done..]) {
                        Ok(0) => {
                            return Err(IoError::invalid(
                                path,
                                format!(
                                    "gzip data ends after {} bytes, but the NIfTI header implies at least {expected}",
                                    at + done as u64
                                ),
                            ));
                        }
                        Ok(n) => done += n,
                        Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                        Err(e) => {
                            return Err(IoError::invalid(
                                path,
                                format!(
                                    "corrupt gzip stream after {} bytes: {e}",
                                    at + done as u64
                                ),
                            ));
                        }
                    }
                }
                Ok(())
            }
        }
    }

    /// Moves `n` bytes forward from position `at`.
    pub(super) fn skip(
        &mut self,
        path: &Path,
        n: u64,
        at: u64,
        expected: u64,
    ) -> Result<(), IoError> {
        match self {
            Source::Plain(r) => r
                .seek_relative(i64::try_from(n).unwrap_or(i64::MAX))
                .map_err(|e| IoError::os(path, "seek in", e)),
            Source::Gzip(_) => {
                let mut scratch = vec![0u8; (n as usize).min(1 << 16)];
                let mut left = n;
                while left > 0 {
                    let k = (left as usize).min(scratch.len());
                    self.fill(path, &mut scratch[..k], at + (n - left), expected)?;
                    left -= k as u64;
                }
                Ok(())
            }
        }
    }
}

/// The `.img` (or `.img.gz`) beside a `.hdr` (or `.hdr.gz`), keeping the
/// extension's case.
pub(super) fn image_path(path: &Path) -> Result<PathBuf, IoError> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let lower = name.to_ascii_lowercase();
    let stem_len = if lower.ends_with(".hdr.gz") {
        name.len() - 7
    } else if lower.ends_with(".hdr") {
        name.len() - 4
    } else {
        return Err(IoError::invalid(
            path,
            "NIfTI magic says the data is in a separate .img file, but this header's name does not end in .hdr",
        ));
    };
    // ".hdr" -> ".img" letter by letter, so ".HDR" gives ".IMG".
    let ext = &name[stem_len..];
    let img_ext: String = ext
        .chars()
        .enumerate()
        .map(|(i, c)| match i {
            1..=3 => {
                let r = char::from(b"img"[i - 1]);
                if c.is_ascii_uppercase() {
                    r.to_ascii_uppercase()
                } else {
                    r
                }
            }
            _ => c,
        })
        .collect();
    Ok(path.with_file_name(format!("{}{}", &name[..stem_len], img_ext)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_paths_keep_case() {
        let img = |p: &str| image_path(Path::new(p)).unwrap();
        assert_eq!(img("d/brain.hdr"), PathBuf::from("d/brain.img"));
        assert_eq!(img("BRAIN.HDR"), PathBuf::from("BRAIN.IMG"));
        assert_eq!(img("b.hdr.gz"), PathBuf::from("b.img.gz"));
        assert!(image_path(Path::new("b.nii")).is_err());
    }
}
