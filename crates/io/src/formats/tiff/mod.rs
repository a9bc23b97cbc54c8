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
//!   slice, then time point); `--frame` picks the time point and
//!   `--channel` the channel (`axes.rs`);
//! - the spacing: x and y from `XResolution`/`YResolution` (pixels per
//!   `unit`), z from `spacing=`; the origin from `xorigin=`, `yorigin=`,
//!   `zorigin=` (in pixels, as ImageJ's `Calibration` stores it);
//! - a linear value calibration `cf=0` with `c0=`, `c1=` (ImageJ stores
//!   signed 16-bit data as unsigned with `c0=-32768`): applied, with a note.
//!
//! OME-TIFF (an `ImageDescription` holding OME-XML, as tifffile's
//! `ome=True`, Bio-Formats and OMERO write it; `ome.rs`) gives the pages'
//! order (`DimensionOrder` with `SizeZ`, `SizeC`, `SizeT`: the time point
//! and channel picked as for ImageJ)
//! and the spacing from `PhysicalSizeX`/`Y`/`Z` and their units, converted
//! to one unit. ImageJ metadata, where present, is read first, as before.
//!
//! Without either, the resolution tags give the spacing where they name
//! a physical unit and are not a print default (`resolution.rs`, with z
//! taken equal to x), else it is 1; the origin is 0.

mod imagej;
mod ome;
mod page;
mod resolution;

use std::io::BufReader;
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use volray_core::glam::DVec3;

use self::imagej::{ImageJ, Shape, calibration, imagej_geometry, stack_shape};
use self::ome::{Ome, is_ome};
use self::page::{
    Sample, compression_name, find_ascii, find_f64, header_fields, page_info, tiff_error,
};
use self::resolution::spacing_from_tags;
use crate::dtype::{Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::open_input;
use crate::shared::limits::{F32_BYTES, check_dims};
use crate::shared::rescale::rescale;
use crate::{AxisNames, FileInfo, Loaded, ReadOptions, VolumeFormat, Volumes};

/// A compressed page may decode to more bytes than the file holds; a stack
/// whose pages claim more decoded bytes than this many times the file
/// length is refused before anything is allocated (deflate, the strongest
/// of TIFF's lossless codecs, inflates at most about 1032:1).
const MAX_INFLATION: u64 = crate::shared::compress::MAX_DEFLATE_RATIO;

/// Small files may decode to this many bytes whatever their length, so
/// that a tiny but highly compressible stack is still read.
const SMALL_FILE_ALLOWANCE: u64 = 64 << 20;
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
    // A SHORT of 1, 2 or 3: anything else is named in the note.
    let resolution_unit = find_f64(&mut decoder, Tag::ResolutionUnit).map(|u| {
        if (0.0..=65535.0).contains(&u) {
            u as u16
        } else {
            u16::MAX
        }
    });
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
    let ome = match description.as_deref() {
        Some(d) if imagej.is_none() && is_ome(d) => Some(Ome::parse(path, d)?),
        _ => None,
    };
    let shape = match &ome {
        Some(o) => ome_shape(path, o, &mut pages, &mut info)?,
        None => stack_shape(path, imagej.as_ref(), pages.len())?,
    };
    // The time point and channel asked for (`axes.rs`).
    let volumes = Volumes::new(shape.times, shape.channels);
    let picked = volumes.pick(
        path,
        opts,
        AxisNames {
            holder: "the stack",
            time: if ome.is_some() {
                "SizeT"
            } else {
                "ImageJ frames"
            },
            channel: if ome.is_some() {
                "SizeC"
            } else {
                "ImageJ channels"
            },
        },
    )?;
    info.set_volumes(volumes, picked);
    let (t, c) = (picked.time_point, picked.channel);
    if volumes.count() > 1 {
        info.notes.push(match &ome {
            Some(o) => format!(
                "time point {t} of {}, channel {c} of {} read (pages in OME DimensionOrder {})",
                shape.times, shape.channels, o.dimension_order
            ),
            None => format!(
                "time point {t} of {}, channel {c} of {} read (ImageJ page order: channel fastest, then slice, then time)",
                shape.times, shape.channels
            ),
        });
    }
    let page_of = |z: usize| match &ome {
        Some(o) => o.page(z, c, t),
        None => (t * shape.slices + z) * shape.channels + c,
    };
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
    // The volume in its own type, beside one decoded page at a time; an
    // ImageJ calibration builds the calibrated values beside it.
    let (calibration, calibration_note) = imagej.as_ref().map_or((None, None), calibration);
    let kept = sample.stored().bytes() as u64;
    check_dims(
        path,
        "ImageWidth x ImageLength x pages",
        &dims,
        kept + if calibration.is_some() { F32_BYTES } else { 0 },
        opts.max_memory,
    )?;

    let data = read_as_stored!(sample.stored(), |T| {
        let mut data: Vec<T> = Vec::with_capacity(voxels);
        for z in 0..shape.slices {
            let page = &pages[page_of(z)];
            let what = format!("page {}", page.ifd);
            decoder
                .seek_to_image(page.ifd)
                .map_err(|e| tiff_error(path, &what, e))?;
            let image = decoder
                .read_image()
                .map_err(|e| tiff_error(path, &what, e))?;
            let before = data.len();
            extend_page(&mut data, image);
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
        Ok(data)
    })?;

    let mut spacing = DVec3::ONE;
    let mut origin = DVec3::ZERO;
    let data = match calibration {
        Some((c0, c1)) => rescale(data, c1, c0),
        None => data,
    };
    info.notes.extend(calibration_note);
    if let Some(o) = &ome {
        spacing = o.geometry(path, &mut info)?;
    }
    match &imagej {
        Some(ij) => {
            imagej_geometry(
                ij,
                [x_resolution, y_resolution],
                &mut spacing,
                &mut origin,
                &mut info,
            );
        }
        None if ome.is_some() => {}
        None => {
            let tags = [x_resolution, y_resolution];
            if let Some(s) = spacing_from_tags(tags, resolution_unit, &mut info) {
                spacing = s;
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
/// The stack's shape from OME-XML, checked against the full-resolution
/// `pages`: the first image's planes, the pages of other images (a file of
/// several series) dropped with a note.
fn ome_shape(
    path: &Path,
    ome: &Ome,
    pages: &mut Vec<page::Page>,
    info: &mut FileInfo,
) -> Result<Shape, IoError> {
    let planes = ome.planes();
    if planes > pages.len() || (planes < pages.len() && ome.images < 2) {
        return Err(IoError::invalid(
            path,
            format!(
                "OME-XML says SizeZ={} SizeC={} SizeT={} ({planes} planes) but the file has {} full-resolution page(s)",
                ome.shape.slices,
                ome.shape.channels,
                ome.shape.times,
                pages.len()
            ),
        ));
    }
    if planes < pages.len() {
        info.notes.push(format!(
            "OME-XML describes {} images: the first read ({planes} of {} pages)",
            ome.images,
            pages.len()
        ));
        pages.truncate(planes);
    }
    Ok(ome.shape)
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
/// Appends a decoded page to `out`, as `T`: the page's own type where
/// [`Sample::stored`] keeps it, `f32` (rounded once, as `as f32` does)
/// otherwise.
fn extend_page<T: Stored>(out: &mut Vec<T>, image: DecodingResult) {
    fn keep<T: Stored>(out: &mut Vec<T>, values: impl Iterator<Item = f32>) {
        out.extend(values.map(|v| T::from_f64(f64::from(v))));
    }
    match image {
        DecodingResult::U8(v) => keep(out, v.into_iter().map(f32::from)),
        DecodingResult::U16(v) => keep(out, v.into_iter().map(f32::from)),
        DecodingResult::U32(v) => keep(out, v.into_iter().map(|x| x as f32)),
        DecodingResult::U64(v) => keep(out, v.into_iter().map(|x| x as f32)),
        DecodingResult::I8(v) => keep(out, v.into_iter().map(f32::from)),
        DecodingResult::I16(v) => keep(out, v.into_iter().map(f32::from)),
        DecodingResult::I32(v) => keep(out, v.into_iter().map(|x| x as f32)),
        DecodingResult::I64(v) => keep(out, v.into_iter().map(|x| x as f32)),
        DecodingResult::F16(v) => keep(out, v.into_iter().map(|x| x.to_f32())),
        DecodingResult::F32(v) => keep(out, v.into_iter()),
        DecodingResult::F64(v) => keep(out, v.into_iter().map(|x| x as f32)),
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
#[cfg(test)]
mod tests {
    use super::imagej::Shape;
    use super::page::greyscale;
    use super::*;
    use volray_core::Samples;

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
        let (scale, note) = calibration(&ij);
        assert_eq!(scale, Some((-32768.0, 1.0)));
        assert!(note.unwrap().contains("-32768 + 1 x stored (HU)"));
        // A 16-bit stack calibrated to -32768..32767 stays 16-bit.
        let data = rescale(Samples::from(vec![0u16, 32768, 65535]), 1.0, -32768.0);
        assert_eq!(data, Samples::from(vec![-32768i16, 0, 32767]));

        let ij = ImageJ::parse("ImageJ=1.53\ncf=1\nc0=3\nc1=2\n");
        let (scale, note) = calibration(&ij);
        assert_eq!(scale, None);
        assert!(note.unwrap().contains("cf=1"));
        assert_eq!(calibration(&ImageJ::parse("ImageJ=1.53\n")), (None, None));
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
