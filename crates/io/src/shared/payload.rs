//! The samples behind a text header (NRRD, MetaImage): one or more data
//! regions (the rest of the header's own file, or separate data files),
//! each raw, gzip- or zlib-compressed, decimal text or hexadecimal, turned
//! into `f32` with one frame of a multi-volume file kept.
//!
//! A header is trusted only as far as the files bear it out:
//! [`Region::locate`] finds where each region's data starts and how many
//! bytes follow, [`check_region`] compares that with what the header
//! declares before anything is allocated, and [`read_regions`] reads no
//! byte past a region. Compressed streams cannot be sized from the file,
//! so their declared size is bounded by deflate's largest ratio and the
//! output grows only as data actually inflates; a stream that inflates to
//! less or more than declared is refused.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use flate2::read::{MultiGzDecoder, ZlibDecoder};

use crate::dtype::{DType, Endian, Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::input::{open_input, read_samples};
use crate::shared::mapped;
use crate::shared::text_reader::TextReader;
use volray_core::{SampleType, Samples};

/// Deflate's largest compression ratio (RFC 1951: a 258-byte match costs
/// at least two bits, so 1032 output bytes per input byte at most).
use crate::shared::compress::MAX_DEFLATE_RATIO;

/// Output samples allocated up front for a compressed stream; beyond this
/// the output grows with the data actually inflated.
const COMPRESSED_PREALLOC: usize = 1 << 20;

/// Bytes decoded per chunk from compressed and text streams.
const CHUNK: usize = 1 << 16;

/// How a region's bytes encode the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// The samples' bytes as they are.
    Raw,
    /// gzip (RFC 1952), possibly several concatenated members.
    Gzip,
    /// zlib (RFC 1950), or gzip where the stream starts with gzip's magic
    /// (MetaIO inflates with `inflateInit2(.., 47)`, which accepts both).
    Zlib,
    /// Decimal numbers separated by whitespace or commas.
    Text,
    /// Two hexadecimal digits per byte, whitespace between them ignored.
    Hex,
}

impl Encoding {
    fn is_compressed(self) -> bool {
        matches!(self, Encoding::Gzip | Encoding::Zlib)
    }
}

/// The sample type and encoding shared by all regions of a file.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    pub dtype: DType,
    pub endian: Endian,
    pub encoding: Encoding,
    /// Bytes of the inflated stream to skip before the samples (NRRD
    /// `byte skip` with a compressed encoding).
    pub inflated_skip: u64,
}

impl Layout {
    /// The type the volume keeps: the file's own ([`DType::stored`]), or
    /// `f32` for numbers written as text.
    pub(crate) fn stored(&self) -> SampleType {
        match self.encoding {
            Encoding::Text => SampleType::F32,
            _ => self.dtype.stored(),
        }
    }
}

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
    }
    Ok(())
}

/// Which samples of a multi-volume file to keep: sample `n` (counted
/// across all regions, file order) belongs to frame
/// `(n / stride) % count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct FrameSelect {
    pub stride: usize,
    pub count: usize,
    pub index: usize,
}

impl FrameSelect {
    /// Every sample (a file holding one volume).
    pub(crate) const ALL: FrameSelect = FrameSelect {
        stride: 1,
        count: 1,
        index: 0,
    };

    fn keep_into<T: Copy>(&self, first: usize, values: &[T], out: &mut Vec<T>) {
        if self.count == 1 {
            out.extend_from_slice(values);
        } else {
            out.extend(
                values
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| ((first + i) / self.stride) % self.count == self.index)
                    .map(|(_, &v)| v),
            );
        }
    }
}

/// The volume [`ReadOptions::frame`](crate::ReadOptions::frame) asks for
/// (`requested`, default 0) of a file that holds `frames`; refused if there
/// is no such volume.
pub(crate) fn chosen_frame(
    path: &Path,
    requested: Option<usize>,
    frames: usize,
) -> Result<usize, IoError> {
    let frame = requested.unwrap_or(0);
    if frame >= frames {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the file holds {frames} volume{} (frames 0 to {})",
                if frames == 1 { "" } else { "s" },
                frames.saturating_sub(1)
            ),
        ));
    }
    Ok(frame)
}

/// Reads `per_region` samples from each region in turn (all checked with
/// [`check_region`] first), keeping those `frame` selects, in the type
/// [`Layout::stored`] names.
pub(crate) fn read_regions(
    regions: &[Region],
    per_region: usize,
    layout: &Layout,
    frame: FrameSelect,
) -> Result<Samples, IoError> {
    read_as_stored!(layout.stored(), |T| read_regions_as::<T>(
        regions, per_region, layout, frame
    ))
}

/// Where the samples `frame` selects lie in the one file they can be
/// mapped from: a single region, raw encoding, the kept volume contiguous
/// (the frame axis of a 4-D file is its slowest), the samples stored as a
/// volume keeps them ([`mapped::mappable`]); otherwise why not.
pub(crate) fn mappable(
    regions: &[Region],
    per_region: usize,
    layout: &Layout,
    frame: FrameSelect,
) -> Result<(PathBuf, u64), String> {
    let [region] = regions else {
        return Err(format!(
            "the data is split over {} files: store it in one",
            regions.len()
        ));
    };
    let encoding = match layout.encoding {
        Encoding::Raw => None,
        Encoding::Gzip => Some("gzip-compressed"),
        Encoding::Zlib => Some("zlib-compressed"),
        Encoding::Text => Some("text"),
        Encoding::Hex => Some("hex"),
    };
    if let Some(e) = encoding {
        return Err(format!("{e} data: store it uncompressed (raw encoding)"));
    }
    let size = layout.dtype.size() as u64;
    let offset = if frame.count <= 1 {
        region.start
    } else if frame.stride.checked_mul(frame.count) == Some(per_region) {
        region.start + (frame.index * frame.stride) as u64 * size
    } else {
        return Err(
            "the volumes of the 4-D file are interleaved (its frame axis is not the slowest)"
                .into(),
        );
    };
    mapped::mappable(layout.dtype, layout.endian, offset)?;
    Ok((region.path.clone(), offset))
}

/// [`read_regions`] as `T`.
fn read_regions_as<T: Stored>(
    regions: &[Region],
    per_region: usize,
    layout: &Layout,
    frame: FrameSelect,
) -> Result<Vec<T>, IoError> {
    let total = per_region.checked_mul(regions.len()).ok_or_else(|| {
        IoError::invalid(
            regions.first().map_or(Path::new(""), |r| r.path.as_path()),
            "the header describes more samples than this machine can address",
        )
    })?;
    let kept = total / frame.count.max(1);
    let capacity = if layout.encoding.is_compressed() {
        kept.min(COMPRESSED_PREALLOC)
    } else {
        kept
    };
    let mut out = Vec::with_capacity(capacity);
    let mut seen = 0usize;
    for region in regions {
        let mut sink = |values: &[T]| {
            frame.keep_into(seen, values, &mut out);
            seen += values.len();
        };
        read_region(region, per_region, layout, &mut sink)?;
    }
    Ok(out)
}

/// Decodes the `samples` samples of one region, passing them to `sink` in
/// chunks.
fn read_region<T: Stored>(
    region: &Region,
    samples: usize,
    layout: &Layout,
    sink: &mut dyn FnMut(&[T]),
) -> Result<(), IoError> {
    let path = region.path.as_path();
    let (mut file, _) = open_input(path)?;
    file.seek(SeekFrom::Start(region.start))
        .map_err(|e| IoError::os(path, "seek in", e))?;
    let bounded = file.take(region.len);
    let (dtype, endian) = (layout.dtype, layout.endian);
    match layout.encoding {
        Encoding::Raw => read_samples(
            path,
            &mut BufReader::new(bounded),
            samples,
            dtype.size(),
            region.start,
            |bytes, out| T::extend(out, bytes, dtype, endian),
            |values| sink(values),
        ),
        Encoding::Gzip | Encoding::Zlib => {
            let mut buffered = BufReader::new(bounded);
            let head = buffered
                .fill_buf()
                .map_err(|e| IoError::os(path, "read", e))?;
            let gzip = layout.encoding == Encoding::Gzip || head.starts_with(&[0x1f, 0x8b]);
            let (name, mut decoder): (&str, Box<dyn Read>) = if gzip {
                ("gzip", Box::new(MultiGzDecoder::new(buffered)))
            } else {
                ("zlib", Box::new(ZlibDecoder::new(buffered)))
            };
            read_inflated(path, name, &mut decoder, samples, layout, sink)
        }
        Encoding::Text => read_text(path, BufReader::new(bounded), samples, sink),
        Encoding::Hex => read_hex(path, &mut BufReader::new(bounded), samples, layout, sink),
    }
}

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

fn read_inflated<T: Stored>(
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
fn read_text<T: Stored>(
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
fn read_hex<T: Stored>(
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

/// Expands a printf-style data file name template with one integer
/// conversion (`%d` or `%i`, with flags `-+ 0` and a width; `%%` is a
/// literal `%`), as NRRD's and MetaImage's numbered data files use.
pub(crate) fn format_number(template: &str, value: i64) -> Result<String, String> {
    let mut out = String::new();
    let mut chars = template.chars().peekable();
    let mut converted = false;
    while let Some(c) = chars.next() {
        if c != '%' {
            out.push(c);
            continue;
        }
        if chars.peek() == Some(&'%') {
            chars.next();
            out.push('%');
            continue;
        }
        if converted {
            return Err(format!("\"{template}\" has more than one % conversion"));
        }
        let (mut left, mut zero, mut plus, mut space) = (false, false, false, false);
        while let Some(&f) = chars.peek() {
            match f {
                '-' => left = true,
                '0' => zero = true,
                '+' => plus = true,
                ' ' => space = true,
                _ => break,
            }
            chars.next();
        }
        let mut width = 0usize;
        while let Some(d) = chars.peek().and_then(|c| c.to_digit(10)) {
            width = width.saturating_mul(10).saturating_add(d as usize);
            chars.next();
        }
        if width > 64 {
            return Err(format!("\"{template}\": field width {width} is too large"));
        }
        match chars.next() {
            Some('d' | 'i') => {}
            other => {
                return Err(format!(
                    "\"{template}\": only %d conversions are supported, not %{}",
                    other.map(String::from).unwrap_or_default()
                ));
            }
        }
        let sign = if value < 0 {
            "-"
        } else if plus {
            "+"
        } else if space {
            " "
        } else {
            ""
        };
        let digits = value.unsigned_abs().to_string();
        let len = sign.len() + digits.len();
        let pad = width.saturating_sub(len);
        if left {
            out.push_str(sign);
            out.push_str(&digits);
            out.extend(std::iter::repeat_n(' ', pad));
        } else if zero {
            out.push_str(sign);
            out.extend(std::iter::repeat_n('0', pad));
            out.push_str(&digits);
        } else {
            out.extend(std::iter::repeat_n(' ', pad));
            out.push_str(sign);
            out.push_str(&digits);
        }
        converted = true;
    }
    if !converted {
        return Err(format!("\"{template}\" has no %d conversion"));
    }
    Ok(out)
}

/// Most data files a header may name: bounds the list of names a lying
/// numbered series could make up before any file is opened.
pub(crate) const MAX_FILES: u64 = 1 << 20;

/// How many numbers `min, min + step, ...` reach up to and including
/// `max` (NRRD and MetaImage numbered data files), or `None` if `step` is
/// 0 or points away from `max`.
pub(crate) fn number_range(min: i64, max: i64, step: i64) -> Option<u64> {
    let span = i128::from(max) - i128::from(min);
    if step == 0 || span.signum() * i128::from(step.signum()) < 0 {
        return None;
    }
    u64::try_from(span / i128::from(step)).ok()?.checked_add(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn layout(dtype: DType, encoding: Encoding) -> Layout {
        Layout {
            dtype,
            endian: Endian::Little,
            encoding,
            inflated_skip: 0,
        }
    }

    fn region_of(dir: &Path, name: &str, bytes: &[u8]) -> Region {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        Region::locate(&path, 0, 0, Skip::Forward(0), 0, "skip").unwrap()
    }

    #[test]
    fn printf_templates() {
        assert_eq!(format_number("s%03d.raw", 7).unwrap(), "s007.raw");
        assert_eq!(format_number("s%d.raw", -12).unwrap(), "s-12.raw");
        assert_eq!(format_number("%-4d|", 5).unwrap(), "5   |");
        assert_eq!(format_number("%4d|", 5).unwrap(), "   5|");
        assert_eq!(format_number("%+05i", 5).unwrap(), "+0005");
        assert_eq!(format_number("100%%_%d", 1).unwrap(), "100%_1");
        assert!(format_number("a%s", 1).unwrap_err().contains("%s"));
        assert!(
            format_number("a%d%d", 1)
                .unwrap_err()
                .contains("more than one")
        );
        assert!(format_number("plain", 1).unwrap_err().contains("no %d"));
        assert!(format_number("%999999999999d", 1).is_err());
    }

    #[test]
    fn number_ranges() {
        assert_eq!(number_range(1, 5, 1), Some(5));
        assert_eq!(number_range(0, 8, 2), Some(5));
        assert_eq!(number_range(0, 9, 2), Some(5));
        assert_eq!(number_range(5, 1, -1), Some(5));
        assert_eq!(number_range(3, 3, 1), Some(1));
        assert_eq!(number_range(1, 5, 0), None);
        assert_eq!(number_range(1, 5, -1), None);
        assert_eq!(number_range(i64::MIN, i64::MAX, 1), None);
        assert_eq!(number_range(i64::MIN, i64::MAX, 2), Some(1 << 63));
    }

    #[test]
    fn line_and_byte_skips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d");
        std::fs::write(&path, b"head\nline one\nline two\nXYdata").unwrap();
        let r = Region::locate(&path, 5, 2, Skip::Forward(2), 0, "line skip").unwrap();
        assert_eq!((r.start, r.len), (25, 4));
        let r = Region::locate(&path, 0, 0, Skip::BeforeEnd(0), 4, "byte skip").unwrap();
        assert_eq!((r.start, r.len), (25, 4));
        let r = Region::locate(&path, 0, 0, Skip::BeforeEnd(2), 2, "byte skip").unwrap();
        assert_eq!((r.start, r.len), (25, 2));
        let err = Region::locate(&path, 5, 4, Skip::Forward(0), 0, "line skip").unwrap_err();
        assert!(
            err.to_string()
                .contains("4 lines to skip but the file ends after 2"),
            "{err}"
        );
        let err = Region::locate(&path, 0, 0, Skip::Forward(30), 0, "byte skip").unwrap_err();
        assert!(
            err.to_string()
                .contains("passes the end of the file (29 bytes)"),
            "{err}"
        );
        let err = Region::locate(&path, 20, 0, Skip::BeforeEnd(0), 10, "byte skip").unwrap_err();
        assert!(err.to_string().contains("only 9 bytes follow"), "{err}");
    }

    #[test]
    fn raw_sizes_are_checked_and_frames_selected() {
        let dir = tempfile::tempdir().unwrap();
        let bytes: Vec<u8> = (0..12u16).flat_map(|v| v.to_le_bytes()).collect();
        let r = region_of(dir.path(), "r", &bytes);
        let l = layout(DType::U16, Encoding::Raw);
        let mut notes = Vec::new();
        check_region(&r, 12, &l, &mut notes).unwrap();
        assert!(notes.is_empty());
        check_region(&r, 11, &l, &mut notes).unwrap();
        assert!(
            notes[0].ends_with("2 bytes after the data ignored"),
            "{notes:?}"
        );
        let err = check_region(&r, 13, &l, &mut notes).unwrap_err();
        assert!(
            err.to_string().contains("13 samples of u16 (26 bytes)"),
            "{err}"
        );

        // Frames of 2 along a fastest axis of 3: samples 3..5 and 9..11 are frame 1.
        let select = FrameSelect {
            stride: 1,
            count: 3,
            index: 1,
        };
        let got = read_regions(std::slice::from_ref(&r), 12, &l, select)
            .unwrap()
            .to_f32_vec();
        assert_eq!(got, [1.0, 4.0, 7.0, 10.0]);
        let select = FrameSelect {
            stride: 6,
            count: 2,
            index: 1,
        };
        let got = read_regions(&[r.clone(), r], 12, &l, select)
            .unwrap()
            .to_f32_vec();
        assert_eq!(
            got,
            [
                6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0
            ]
        );
    }

    #[test]
    fn compressed_streams_must_inflate_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let data: Vec<u8> = (0..100u8).collect();
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        gz.write_all(&data).unwrap();
        let gz = gz.finish().unwrap();
        let r = region_of(dir.path(), "g", &gz);
        let mut l = layout(DType::U8, Encoding::Gzip);
        let got = read_regions(std::slice::from_ref(&r), 100, &l, FrameSelect::ALL)
            .unwrap()
            .to_f32_vec();
        assert_eq!(got, (0..100).map(|v| v as f32).collect::<Vec<_>>());
        let err = read_regions(std::slice::from_ref(&r), 101, &l, FrameSelect::ALL).unwrap_err();
        assert!(
            err.to_string()
                .contains("inflates to 100 bytes, but the header declares 101"),
            "{err}"
        );
        let err = read_regions(std::slice::from_ref(&r), 99, &l, FrameSelect::ALL).unwrap_err();
        assert!(
            err.to_string().contains("inflates past the 99 bytes"),
            "{err}"
        );
        l.inflated_skip = 10;
        let got = read_regions(std::slice::from_ref(&r), 90, &l, FrameSelect::ALL)
            .unwrap()
            .to_f32_vec();
        assert_eq!(got[0], 10.0);

        // zlib, and gzip found by its magic where zlib is declared.
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        z.write_all(&data).unwrap();
        let z = z.finish().unwrap();
        let rz = region_of(dir.path(), "z", &z);
        let lz = layout(DType::U8, Encoding::Zlib);
        assert_eq!(
            read_regions(&[rz], 100, &lz, FrameSelect::ALL)
                .unwrap()
                .to_f32_vec()[99],
            99.0
        );
        assert_eq!(
            read_regions(std::slice::from_ref(&r), 100, &lz, FrameSelect::ALL)
                .unwrap()
                .to_f32_vec()[99],
            99.0
        );

        // A lying size beyond deflate's ratio is refused before reading.
        let mut notes = Vec::new();
        let err = check_region(&r, usize::MAX / 2, &lz, &mut notes).unwrap_err();
        assert!(
            err.to_string().contains("cannot inflate to more than"),
            "{err}"
        );
        let corrupt = region_of(dir.path(), "c", &gz[..gz.len() / 2]);
        let err = read_regions(
            &[corrupt],
            100,
            &layout(DType::U8, Encoding::Gzip),
            FrameSelect::ALL,
        )
        .unwrap_err();
        assert!(!err.is_io_failure(), "{err}");
    }

    #[test]
    fn text_and_hex() {
        let dir = tempfile::tempdir().unwrap();
        let r = region_of(dir.path(), "t", b" 1, 2.5\n-3e2\t4 trailing words");
        let l = layout(DType::F32, Encoding::Text);
        assert_eq!(
            read_regions(std::slice::from_ref(&r), 4, &l, FrameSelect::ALL)
                .unwrap()
                .to_f32_vec(),
            [1.0, 2.5, -300.0, 4.0]
        );
        let err = read_regions(std::slice::from_ref(&r), 5, &l, FrameSelect::ALL).unwrap_err();
        assert!(
            err.to_string()
                .ends_with("t: line 2 of the data: text value 5 is \"trailing\", not a number"),
            "{err}"
        );
        let short = region_of(dir.path(), "s", b"1 2 3");
        let err = read_regions(std::slice::from_ref(&short), 4, &l, FrameSelect::ALL).unwrap_err();
        assert!(
            err.to_string().ends_with(
                "s: file ends at line 1 of the data after 3 of the 4 values of the text data"
            ),
            "{err}"
        );
        let mut notes = Vec::new();
        let err = check_region(&short, 4, &l, &mut notes).unwrap_err();
        assert!(err.to_string().contains("cannot hold that many"), "{err}");

        let h = region_of(dir.path(), "h", b"0100 ff\n7f 0080");
        let mut lh = layout(DType::I16, Encoding::Hex);
        lh.endian = Endian::Big;
        assert_eq!(
            read_regions(&[h], 3, &lh, FrameSelect::ALL)
                .unwrap()
                .to_f32_vec(),
            [256.0, -129.0, 128.0]
        );
        let bad = region_of(dir.path(), "b", b"01zz");
        let err = read_regions(&[bad], 1, &lh, FrameSelect::ALL).unwrap_err();
        assert!(err.to_string().contains("'z', not a hex digit"), "{err}");
    }
}
