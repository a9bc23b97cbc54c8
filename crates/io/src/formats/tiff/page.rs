//! What each page (IFD) of a TIFF declares: its size, its greyscale
//! sample type ([`Sample`]), compression and subfile kind, and the tags
//! shown by `volray info`; with the `tiff` crate's errors as volray's.

use std::fs::File;
use std::io::{BufReader, ErrorKind};
use std::path::Path;

use tiff::decoder::Decoder;
use tiff::tags::Tag;
use tiff::{ColorType, TiffError};
use volray_core::SampleType;

use crate::error::IoError;

/// Header values longer than this are shortened in [`FileInfo::header`].
const MAX_HEADER_VALUE: usize = 200;

/// What one page (IFD) declares.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Page {
    /// Position of the IFD in the file's chain, counted from 0.
    pub(super) ifd: usize,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) sample: Result<Sample, String>,
    /// `NewSubfileType`: bit 0 reduced resolution, bit 2 mask.
    pub(super) subfile: u32,
    pub(super) compression: u16,
    /// `PhotometricInterpretation`: 0 WhiteIsZero, 1 BlackIsZero, ...
    pub(super) photometric: Option<u32>,
}

/// A greyscale sample type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Sample {
    Uint(u8),
    Int(u8),
    Float(u8),
}

impl Sample {
    pub(super) fn name(self) -> String {
        match self {
            Sample::Uint(b) => format!("uint{b}"),
            Sample::Int(b) => format!("int{b}"),
            Sample::Float(b) => format!("float{b}"),
        }
    }

    pub(super) fn bytes(self) -> u64 {
        let (Sample::Uint(b) | Sample::Int(b) | Sample::Float(b)) = self;
        u64::from(b) / 8
    }

    /// The type the volume keeps: 8- and 16-bit integers as they are,
    /// the rest as `f32`.
    pub(super) fn stored(self) -> SampleType {
        match self {
            Sample::Uint(8) => SampleType::U8,
            Sample::Uint(16) => SampleType::U16,
            Sample::Int(8) => SampleType::I8,
            Sample::Int(16) => SampleType::I16,
            _ => SampleType::F32,
        }
    }
}
/// What the current page declares.
pub(super) fn page_info(
    path: &Path,
    decoder: &mut Decoder<BufReader<File>>,
    ifd: usize,
) -> Result<Page, IoError> {
    let (width, height) = decoder
        .dimensions()
        .map_err(|e| tiff_error(path, &format!("page {ifd}"), e))?;
    let subfile = find_u32(decoder, Tag::NewSubfileType).unwrap_or(0);
    let compression = find_u32(decoder, Tag::Compression).unwrap_or(1) as u16;
    let format = find_u32(decoder, Tag::SampleFormat).unwrap_or(1);
    let photometric = find_u32(decoder, Tag::PhotometricInterpretation);
    let sample = match decoder.colortype() {
        Ok(ColorType::Gray(bits)) => greyscale(bits, format, photometric),
        Ok(ColorType::RGB(_) | ColorType::YCbCr(_)) => Err(
            "RGB pixels (3 samples each): volray reads greyscale stacks only; convert to greyscale first"
                .to_string(),
        ),
        Ok(ColorType::Palette(_)) => Err(
            "palette-colour pixels: volray reads greyscale stacks only".to_string(),
        ),
        Ok(other) => Err(format!(
            "{other:?} pixels: volray reads greyscale stacks (one sample per pixel) only"
        )),
        Err(e) => Err(format!("unsupported pixel layout: {e}")),
    };
    Ok(Page {
        ifd,
        width,
        height,
        sample,
        subfile,
        compression,
        photometric,
    })
}

/// The sample type of a greyscale page of `bits` per sample and TIFF
/// `SampleFormat` `format` (1 unsigned, 2 signed, 3 IEEE float).
pub(super) fn greyscale(bits: u8, format: u32, photometric: Option<u32>) -> Result<Sample, String> {
    if photometric == Some(4) {
        return Err("transparency-mask pixels (PhotometricInterpretation 4)".into());
    }
    let sample = match (format, bits) {
        (1, 8 | 16 | 32 | 64) => Sample::Uint(bits),
        (2, 8 | 16 | 32 | 64) => Sample::Int(bits),
        (3, 16 | 32 | 64) => Sample::Float(bits),
        (1..=3, _) => {
            return Err(format!(
                "{bits}-bit samples are not supported (8, 16, 32 or 64 bits)"
            ));
        }
        _ => {
            return Err(format!(
                "SampleFormat {format} is not supported (1 unsigned, 2 signed, 3 float)"
            ));
        }
    };
    Ok(sample)
}
/// The first page's tags as written, in file order, values shortened.
pub(super) fn header_fields(decoder: &mut Decoder<BufReader<File>>) -> Vec<(String, String)> {
    let tags: Vec<_> = decoder.tag_iter().filter_map(Result::ok).collect();
    tags.into_iter()
        .map(|(tag, value)| {
            let name = match tag {
                Tag::Unknown(n) => format!("tag {n}"),
                t => format!("{t:?}"),
            };
            let text = match value.clone().into_string() {
                Ok(s) => s.trim_end_matches('\0').replace('\n', "; "),
                Err(_) => format!("{value:?}"),
            };
            (name, shorten(&text))
        })
        .collect()
}

fn shorten(text: &str) -> String {
    if text.chars().count() <= MAX_HEADER_VALUE {
        return text.to_string();
    }
    let head: String = text.chars().take(MAX_HEADER_VALUE).collect();
    format!("{head}... ({} characters)", text.chars().count())
}

fn find_u32(decoder: &mut Decoder<BufReader<File>>, tag: Tag) -> Option<u32> {
    decoder.find_tag_unsigned::<u32>(tag).ok().flatten()
}

/// A numeric tag (RATIONAL, as resolutions are written, or any number).
pub(super) fn find_f64(decoder: &mut Decoder<BufReader<File>>, tag: Tag) -> Option<f64> {
    use tiff::decoder::ifd::Value;
    match decoder.find_tag(tag).ok().flatten()? {
        Value::Rational(n, d) => Some(f64::from(n) / f64::from(d)),
        Value::SRational(n, d) => Some(f64::from(n) / f64::from(d)),
        Value::Double(v) => Some(v),
        Value::Float(v) => Some(f64::from(v)),
        Value::Short(v) => Some(f64::from(v)),
        Value::Unsigned(v) => Some(f64::from(v)),
        _ => None,
    }
}

pub(super) fn find_ascii(decoder: &mut Decoder<BufReader<File>>, tag: Tag) -> Option<String> {
    decoder.find_tag(tag).ok().flatten()?.into_string().ok()
}

pub(super) fn compression_name(code: u16) -> String {
    match code {
        1 => "uncompressed".into(),
        5 => "LZW".into(),
        6 | 7 => "JPEG".into(),
        8 | 0x80b2 => "deflate".into(),
        0x8005 => "PackBits".into(),
        0xc350 => "zstd".into(),
        n => format!("compression {n}"),
    }
}
/// A `tiff` crate error while reading `what`: an operating-system failure
/// stays one; a short or corrupt file is bad input.
pub(super) fn tiff_error(path: &Path, what: &str, error: TiffError) -> IoError {
    match error {
        // An offset from the file that cannot be sought to (2^63 or more)
        // fails in the operating system, but the file is what is wrong.
        TiffError::IoError(e) if e.kind() == ErrorKind::InvalidInput => IoError::invalid(
            path,
            format!("TIFF {what}: an offset in the file lies beyond any file's end ({e})"),
        ),
        TiffError::IoError(e) if e.kind() != ErrorKind::UnexpectedEof => {
            IoError::os(path, "read", e)
        }
        TiffError::IoError(_) => {
            IoError::invalid(path, format!("TIFF {what}: file ends early (truncated?)"))
        }
        TiffError::LimitsExceeded => IoError::invalid(
            path,
            format!(
                "TIFF {what}: a page or tag is larger than the decoder's limits (256 MiB per page, 1 MiB per tag)"
            ),
        ),
        e => IoError::invalid(path, format!("TIFF {what}: {e}")),
    }
}
