//! Multi-page TIFF stacks (`.tif`, `.tiff`, BigTIFF too): each page is one
//! z slice, as microscopes, ImageJ/Fiji and tifffile write them.
//!
//! Layout: voxel (x, y, z) is column x of row y of page z, with row 0 the
//! first row stored (the top of the image) at y = 0, the way ImageJ and
//! `tifffile.imread(...)[z, y, x]` index it.
//!
//! Greyscale pages only: unsigned and signed 8/16/32/64-bit integers and
//! 16/32/64-bit floats, every page the same size and type. RGB, palette
//! and multi-sample pages are refused. Reduced-resolution pages
//! (thumbnails, pyramid levels: `NewSubfileType` bit 0) and transparency
//! masks (bit 2) are skipped with a note.
//!
//! ImageJ metadata (an `ImageDescription` starting with `ImageJ=`) gives:
//! - the hyperstack shape: pages are ordered TZC (channel fastest, then
//!   slice, then time point); each (time point, channel) pair is one volume,
//!   numbered `t·channels + c` for `--frame`;
//! - the spacing: x and y from `XResolution`/`YResolution` (pixels per
//!   `unit`), z from `spacing=`; the origin from `xorigin=`, `yorigin=`,
//!   `zorigin=` (in pixels, as ImageJ's `Calibration` stores it);
//! - a linear value calibration `cf=0` with `c0=`, `c1=` (ImageJ stores
//!   signed 16-bit data as unsigned with `c0=-32768`): applied, with a note.
//!
//! Without ImageJ metadata the spacing is 1 (the resolution tags of a
//! plain TIFF describe print size, not voxel size) and the origin is 0.

use std::fs::File;
use std::io::{BufReader, ErrorKind};
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use tiff::{ColorType, TiffError};
use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::open_input;
use crate::shared::limits::{F32_BYTES, check_dims};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// A compressed page may decode to more bytes than the file holds; a stack
/// whose pages claim more decoded bytes than this many times the file
/// length is refused before anything is allocated (deflate, the strongest
/// of TIFF's lossless codecs, inflates at most about 1032:1).
const MAX_INFLATION: u64 = crate::shared::compress::MAX_DEFLATE_RATIO;

/// Small files may decode to this many bytes whatever their length, so
/// that a tiny but highly compressible stack is still read.
const SMALL_FILE_ALLOWANCE: u64 = 64 << 20;

/// Header values longer than this are shortened in [`FileInfo::header`].
const MAX_HEADER_VALUE: usize = 200;

/// What one page (IFD) declares.
#[derive(Debug, Clone, PartialEq)]
struct Page {
    /// Position of the IFD in the file's chain, counted from 0.
    ifd: usize,
    width: u32,
    height: u32,
    sample: Result<Sample, String>,
    /// `NewSubfileType`: bit 0 reduced resolution, bit 2 mask.
    subfile: u32,
    compression: u16,
    /// `PhotometricInterpretation`: 0 WhiteIsZero, 1 BlackIsZero, ...
    photometric: Option<u32>,
}

/// A greyscale sample type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sample {
    Uint(u8),
    Int(u8),
    Float(u8),
}

impl Sample {
    fn name(self) -> String {
        match self {
            Sample::Uint(b) => format!("uint{b}"),
            Sample::Int(b) => format!("int{b}"),
            Sample::Float(b) => format!("float{b}"),
        }
    }

    fn bytes(self) -> u64 {
        let (Sample::Uint(b) | Sample::Int(b) | Sample::Float(b)) = self;
        u64::from(b) / 8
    }
}

/// Reads the TIFF stack at `path` (see the module documentation).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (file, file_len) = open_input(path)?;
    let mut decoder = Decoder::new(BufReader::new(file))
        .map_err(|e| tiff_error(path, "header", e))?
        .with_limits(Limits::default());

    // Walk every IFD first: sizes and types are checked, and the total
    // compared to the file length, before any pixel is decoded.
    let mut info = FileInfo::new("");
    info.header = header_fields(&mut decoder);
    let description = find_ascii(&mut decoder, Tag::ImageDescription);
    let x_resolution = find_f64(&mut decoder, Tag::XResolution);
    let y_resolution = find_f64(&mut decoder, Tag::YResolution);
    let mut pages = Vec::new();
    loop {
        let ifd = pages.len();
        pages.push(page_info(path, &mut decoder, ifd)?);
        if !decoder.more_images() {
            break;
        }
        decoder
            .next_image()
            .map_err(|e| tiff_error(path, &format!("page {}", ifd + 1), e))?;
    }
    let total_ifds = pages.len();
    let skipped: Vec<usize> = pages
        .iter()
        .filter(|p| p.subfile & 0b101 != 0)
        .map(|p| p.ifd)
        .collect();
    pages.retain(|p| p.subfile & 0b101 == 0);
    info.header
        .insert(0, ("pages".into(), total_ifds.to_string()));
    if !skipped.is_empty() {
        info.notes.push(format!(
            "{} reduced-resolution or mask page(s) skipped (NewSubfileType bits 0 or 2): {}",
            skipped.len(),
            list_indices(&skipped)
        ));
    }
    let first = pages.first().cloned().ok_or_else(|| {
        IoError::invalid(
            path,
            "TIFF holds only reduced-resolution or mask pages, no full-resolution image",
        )
    })?;
    let sample = first
        .sample
        .clone()
        .map_err(|reason| IoError::invalid(path, format!("TIFF page 0: {reason}")))?;
    for p in &pages {
        if p.width != first.width || p.height != first.height {
            return Err(IoError::invalid(
                path,
                format!(
                    "TIFF page {} is {}x{} pixels but page {} is {}x{}: every page of a stack must be the same size",
                    p.ifd, p.width, p.height, first.ifd, first.width, first.height
                ),
            ));
        }
        if p.sample != first.sample {
            let name = |s: &Result<Sample, String>| match s {
                Ok(s) => s.name(),
                Err(e) => e.clone(),
            };
            return Err(IoError::invalid(
                path,
                format!(
                    "TIFF page {} holds {} samples but page {} holds {}: every page of a stack must have the same type",
                    p.ifd,
                    name(&p.sample),
                    first.ifd,
                    sample.name()
                ),
            ));
        }
    }
    if first.photometric == Some(0) {
        info.notes.push(
            "PhotometricInterpretation WhiteIsZero: values kept as stored (not inverted)".into(),
        );
    }
    let endian = match decoder.byte_order() {
        tiff::tags::ByteOrder::LittleEndian => "little-endian",
        tiff::tags::ByteOrder::BigEndian => "big-endian",
    };
    info.stored_type = format!(
        "{} ({endian}, {})",
        sample.name(),
        compression_name(first.compression)
    );

    let imagej = description
        .as_deref()
        .filter(|d| d.starts_with("ImageJ="))
        .map(ImageJ::parse);
    let shape = stack_shape(path, imagej.as_ref(), pages.len())?;
    info.frames = shape.channels * shape.times;
    let frame = opts.frame.unwrap_or(0);
    if frame >= info.frames {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the stack holds {} volume(s) ({} channel(s) x {} time point(s)), numbered from 0",
                info.frames, shape.channels, shape.times
            ),
        ));
    }
    info.frame = frame;
    let (t, c) = (frame / shape.channels, frame % shape.channels);
    if info.frames > 1 {
        info.notes.push(format!(
            "volume {frame} of {} read: time point {t}, channel {c} (ImageJ page order: channel fastest, then slice, then time)",
            info.frames
        ));
    }
    // One page per volume is a 2-D image: read, and described rather
    // than rendered (`grid_to_volume`).

    let (w, h) = (first.width as usize, first.height as usize);
    let dims = [w, h, shape.slices];
    let voxels = volray_core::checked_point_count(dims)
        .filter(|&n| n.checked_mul(4).is_some())
        .ok_or_else(|| {
            IoError::invalid(
                path,
                format!(
                    "TIFF stack of {w}x{h}x{} voxels is too large to address",
                    shape.slices
                ),
            )
        })?;
    check_budget(path, dims, voxels, sample, file_len)?;
    // The f32 volume, beside one decoded page at a time.
    check_dims(
        path,
        "ImageWidth x ImageLength x pages",
        &dims,
        F32_BYTES,
        opts.max_memory,
    )?;

    let mut data = Vec::with_capacity(voxels);
    for z in 0..shape.slices {
        let page = &pages[(t * shape.slices + z) * shape.channels + c];
        let what = format!("page {}", page.ifd);
        decoder
            .seek_to_image(page.ifd)
            .map_err(|e| tiff_error(path, &what, e))?;
        let image = decoder
            .read_image()
            .map_err(|e| tiff_error(path, &what, e))?;
        let before = data.len();
        extend_samples(&mut data, image);
        if data.len() - before != w * h {
            return Err(IoError::invalid(
                path,
                format!(
                    "TIFF {what} decoded to {} samples, but {w}x{h} pixels were declared",
                    data.len() - before
                ),
            ));
        }
    }

    let mut spacing = DVec3::ONE;
    let mut origin = DVec3::ZERO;
    match &imagej {
        Some(ij) => {
            calibrate(ij, &mut data, &mut info);
            imagej_geometry(
                ij,
                [x_resolution, y_resolution],
                &mut spacing,
                &mut origin,
                &mut info,
            );
        }
        None => {
            if x_resolution.is_some() || y_resolution.is_some() {
                info.notes.push(
                    "no ImageJ metadata: spacing 1, 1, 1; XResolution/YResolution (print size) ignored"
                        .into(),
                );
            }
        }
    }
    let steps = [
        DVec3::X * spacing.x,
        DVec3::Y * spacing.y,
        DVec3::Z * spacing.z,
    ];
    let volume = grid_to_volume(path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Tiff,
        info,
    })
}

/// Refuses a stack whose `voxels` samples would decode to more bytes than
/// a `file_len`-byte file can plausibly hold (see [`MAX_INFLATION`]).
fn check_budget(
    path: &Path,
    dims: [usize; 3],
    voxels: usize,
    sample: Sample,
    file_len: u64,
) -> Result<(), IoError> {
    let decoded = (voxels as u64).saturating_mul(sample.bytes());
    let budget = file_len
        .saturating_mul(MAX_INFLATION)
        .max(SMALL_FILE_ALLOWANCE);
    if decoded > budget {
        return Err(IoError::invalid(
            path,
            format!(
                "TIFF pages declare {}x{}x{} {} samples ({decoded} bytes), more than a {file_len}-byte file can hold even compressed",
                dims[0],
                dims[1],
                dims[2],
                sample.name()
            ),
        ));
    }
    Ok(())
}

/// The hyperstack layout: how many channels, slices and time points the
/// pages hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Shape {
    channels: usize,
    slices: usize,
    times: usize,
}

/// The stack's shape from ImageJ's counts, checked against the pages.
fn stack_shape(path: &Path, imagej: Option<&ImageJ>, pages: usize) -> Result<Shape, IoError> {
    let Some(ij) = imagej else {
        return Ok(Shape {
            channels: 1,
            slices: pages,
            times: 1,
        });
    };
    let count = |key: &str| -> Result<Option<usize>, IoError> {
        match ij.get(key) {
            None => Ok(None),
            Some(v) => match v.parse::<usize>() {
                Ok(n) if n >= 1 => Ok(Some(n)),
                _ => Err(IoError::invalid(
                    path,
                    format!("ImageJ description field \"{key}\": \"{v}\" is not a positive count"),
                )),
            },
        }
    };
    let channels = count("channels")?.unwrap_or(1);
    let times = count("frames")?.unwrap_or(1);
    let images = count("images")?;
    let slices = match count("slices")? {
        Some(s) => s,
        None => {
            let n = images.unwrap_or(pages);
            n / (channels * times).max(1)
        }
    };
    let declared = channels
        .checked_mul(slices)
        .and_then(|n| n.checked_mul(times));
    if declared != Some(pages) {
        let hint = if pages == 1 {
            " (ImageJ's contiguous layout for stacks over 4 GB, with one page, is not supported)"
        } else {
            ""
        };
        return Err(IoError::invalid(
            path,
            format!(
                "ImageJ description says channels={channels} slices={slices} frames={times} but the file has {pages} full-resolution page(s){hint}"
            ),
        ));
    }
    Ok(Shape {
        channels,
        slices,
        times,
    })
}

/// The `key=value` lines of an ImageJ `ImageDescription`, in order.
#[derive(Debug, Clone, Default, PartialEq)]
struct ImageJ {
    fields: Vec<(String, String)>,
}

impl ImageJ {
    fn parse(description: &str) -> Self {
        let fields = description
            .lines()
            .filter_map(|line| {
                let (k, v) = line.split_once('=')?;
                Some((k.trim().to_string(), v.trim().to_string()))
            })
            .collect();
        ImageJ { fields }
    }

    fn get(&self, key: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// A finite number under `key`, if present and readable.
    fn number(&self, key: &str) -> Option<f64> {
        self.get(key)?.parse::<f64>().ok().filter(|v| v.is_finite())
    }

    /// The length unit, with ImageJ's `\u00B5` escape decoded.
    fn unit(&self) -> Option<String> {
        let raw = self.get("unit")?;
        Some(
            raw.replace("\\u00B5", "\u{b5}")
                .replace("\\u00b5", "\u{b5}"),
        )
    }
}

/// Applies ImageJ's linear calibration `value = c0 + c1·stored` (`cf=0`,
/// ImageJ's `Calibration.STRAIGHT_LINE`).
fn calibrate(ij: &ImageJ, data: &mut [f32], info: &mut FileInfo) {
    let Some(cf) = ij.get("cf") else {
        return;
    };
    if cf != "0" {
        info.notes.push(format!(
            "ImageJ calibration function cf={cf} (not a straight line) ignored: stored values kept"
        ));
        return;
    }
    let (c0, c1) = (
        ij.number("c0").unwrap_or(0.0),
        ij.number("c1").unwrap_or(1.0),
    );
    if c0 == 0.0 && c1 == 1.0 {
        return;
    }
    for v in data.iter_mut() {
        *v = (c0 + c1 * f64::from(*v)) as f32;
    }
    let unit = ij
        .get("vunit")
        .map(|u| format!(" ({u})"))
        .unwrap_or_default();
    info.notes.push(format!(
        "ImageJ calibration applied: value = {c0} + {c1} x stored{unit}"
    ));
}

/// Spacing and origin from ImageJ's calibration: see the module docs.
fn imagej_geometry(
    ij: &ImageJ,
    resolution: [Option<f64>; 2],
    spacing: &mut DVec3,
    origin: &mut DVec3,
    info: &mut FileInfo,
) {
    let unit = ij.unit().filter(|u| u != "pixel" && !u.is_empty());
    let Some(unit) = unit else {
        info.notes
            .push("ImageJ stack without a length unit: spacing 1, 1, 1 (pixels)".into());
        return;
    };
    for (a, res) in resolution.into_iter().enumerate() {
        match res {
            Some(r) if r.is_finite() && r > 0.0 => spacing[a] = 1.0 / r,
            Some(r) => info.notes.push(format!(
                "{} {r} is not a positive number of pixels per {unit}: spacing 1 used",
                ["XResolution", "YResolution"][a]
            )),
            None => {}
        }
    }
    match ij.number("spacing") {
        Some(s) if s > 0.0 => spacing.z = s,
        Some(s) => info.notes.push(format!(
            "ImageJ spacing={s} is not positive: z spacing 1 used"
        )),
        None => {}
    }
    for (a, key) in ["xorigin", "yorigin", "zorigin"].into_iter().enumerate() {
        if let Some(o) = ij.number(key) {
            origin[a] = -o * spacing[a];
        }
    }
    info.notes.push(format!(
        "spacing {}, {}, {} {unit} from ImageJ metadata (x, y: 1/XResolution, 1/YResolution; z: spacing=){}",
        spacing.x,
        spacing.y,
        spacing.z,
        if *origin != DVec3::ZERO {
            format!(
                "; origin {}, {}, {} from xorigin/yorigin/zorigin (pixels)",
                origin.x, origin.y, origin.z
            )
        } else {
            String::new()
        }
    ));
    info.length_unit = Some(unit);
}

/// What the current page declares.
fn page_info(
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
fn greyscale(bits: u8, format: u32, photometric: Option<u32>) -> Result<Sample, String> {
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

/// Appends a decoded page to `out` as `f32`.
fn extend_samples(out: &mut Vec<f32>, image: DecodingResult) {
    match image {
        DecodingResult::U8(v) => out.extend(v.into_iter().map(f32::from)),
        DecodingResult::U16(v) => out.extend(v.into_iter().map(f32::from)),
        DecodingResult::U32(v) => out.extend(v.into_iter().map(|x| x as f32)),
        DecodingResult::U64(v) => out.extend(v.into_iter().map(|x| x as f32)),
        DecodingResult::I8(v) => out.extend(v.into_iter().map(f32::from)),
        DecodingResult::I16(v) => out.extend(v.into_iter().map(f32::from)),
        DecodingResult::I32(v) => out.extend(v.into_iter().map(|x| x as f32)),
        DecodingResult::I64(v) => out.extend(v.into_iter().map(|x| x as f32)),
        DecodingResult::F16(v) => out.extend(v.into_iter().map(|x| x.to_f32())),
        DecodingResult::F32(v) => out.extend(v),
        DecodingResult::F64(v) => out.extend(v.into_iter().map(|x| x as f32)),
    }
}

/// The first page's tags as written, in file order, values shortened.
fn header_fields(decoder: &mut Decoder<BufReader<File>>) -> Vec<(String, String)> {
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
fn find_f64(decoder: &mut Decoder<BufReader<File>>, tag: Tag) -> Option<f64> {
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

fn find_ascii(decoder: &mut Decoder<BufReader<File>>, tag: Tag) -> Option<String> {
    decoder.find_tag(tag).ok().flatten()?.into_string().ok()
}

fn compression_name(code: u16) -> String {
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

/// "0, 2, 5" for up to 10 indices, then "and N more".
fn list_indices(indices: &[usize]) -> String {
    let shown: Vec<String> = indices.iter().take(10).map(|i| i.to_string()).collect();
    let more = indices.len().saturating_sub(10);
    if more > 0 {
        format!("pages {} and {more} more", shown.join(", "))
    } else {
        format!("pages {}", shown.join(", "))
    }
}

/// A `tiff` crate error while reading `what`: an operating-system failure
/// stays one; a short or corrupt file is bad input.
fn tiff_error(path: &Path, what: &str, error: TiffError) -> IoError {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imagej_description_fields() {
        let ij = ImageJ::parse(
            "ImageJ=1.11a\nimages=6\nchannels=2\nslices=3\nunit=\\u00B5m\nspacing=2.5\nxorigin=4\n",
        );
        assert_eq!(ij.get("images"), Some("6"));
        assert_eq!(ij.unit().as_deref(), Some("\u{b5}m"));
        assert_eq!(ij.number("spacing"), Some(2.5));
        assert_eq!(ij.number("unit"), None);
        let shape = stack_shape(Path::new("s.tif"), Some(&ij), 6).unwrap();
        assert_eq!(
            shape,
            Shape {
                channels: 2,
                slices: 3,
                times: 1
            }
        );
        let err = stack_shape(Path::new("s.tif"), Some(&ij), 5).unwrap_err();
        assert!(
            err.to_string()
                .contains("channels=2 slices=3 frames=1 but the file has 5"),
            "{err}"
        );
        // Without slices=, the slice count is images / (channels·frames).
        let ij = ImageJ::parse("ImageJ=1.53\nimages=8\nframes=2\n");
        let shape = stack_shape(Path::new("s.tif"), Some(&ij), 8).unwrap();
        assert_eq!((shape.slices, shape.times), (4, 2));
        let ij = ImageJ::parse("ImageJ=1.53\nslices=-3\n");
        let err = stack_shape(Path::new("s.tif"), Some(&ij), 3).unwrap_err();
        assert!(err.to_string().contains("\"slices\": \"-3\""), "{err}");
    }

    #[test]
    fn calibration_is_linear_and_noted() {
        let ij = ImageJ::parse("ImageJ=1.53\ncf=0\nc0=-32768\nc1=1\nvunit=HU\n");
        let mut info = FileInfo::default();
        let mut data = vec![0.0, 32768.0, 65535.0];
        calibrate(&ij, &mut data, &mut info);
        assert_eq!(data, [-32768.0, 0.0, 32767.0]);
        assert!(
            info.notes[0].contains("-32768 + 1 x stored (HU)"),
            "{:?}",
            info.notes
        );

        let ij = ImageJ::parse("ImageJ=1.53\ncf=1\nc0=3\nc1=2\n");
        let mut info = FileInfo::default();
        let mut data = vec![5.0];
        calibrate(&ij, &mut data, &mut info);
        assert_eq!(data, [5.0]);
        assert!(info.notes[0].contains("cf=1"), "{:?}", info.notes);
    }

    #[test]
    fn decoded_size_is_bounded_by_the_file_length() {
        let p = Path::new("big.tif");
        let dims = [60000, 60000, 10];
        let voxels = 60000 * 60000 * 10;
        let err = check_budget(p, dims, voxels, Sample::Uint(16), 1000).unwrap_err();
        assert_eq!(
            err.to_string(),
            "big.tif: TIFF pages declare 60000x60000x10 uint16 samples (72000000000 bytes), more than a 1000-byte file can hold even compressed"
        );
        // Small stacks pass whatever the file length; large ones need a
        // file at least 1/1032 of their decoded size.
        assert!(check_budget(p, [1024, 1024, 16], 1 << 24, Sample::Float(32), 10).is_ok());
        let big = [4096, 4096, 64];
        let n = 4096 * 4096 * 64;
        assert!(check_budget(p, big, n, Sample::Uint(8), (n / 1032) as u64 + 1).is_ok());
        assert!(check_budget(p, big, n, Sample::Uint(8), (n / 1032) as u64 - 1).is_err());
    }

    #[test]
    fn sample_types() {
        assert_eq!(greyscale(16, 1, Some(1)), Ok(Sample::Uint(16)));
        assert_eq!(greyscale(32, 2, None), Ok(Sample::Int(32)));
        assert_eq!(greyscale(64, 3, None), Ok(Sample::Float(64)));
        assert!(greyscale(8, 3, None).is_err());
        assert!(greyscale(12, 1, None).unwrap_err().contains("12-bit"));
        assert!(
            greyscale(8, 4, None)
                .unwrap_err()
                .contains("SampleFormat 4")
        );
        assert_eq!(list_indices(&[1, 3]), "pages 1, 3");
        assert!(list_indices(&(0..12).collect::<Vec<_>>()).ends_with("and 2 more"));
    }
}
