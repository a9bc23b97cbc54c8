//! Writing an [`Image`] as an RGB PNG.
//!
//! The image's colours already have the opaque background composited in,
//! so only red, green and blue are written (PNG colour type RGB); the
//! alpha channel, the volume's own coverage, is dropped. Linear values in
//! [0, 1] are clamped and rounded to the nearest code, NaN to 0; no gamma
//! is applied.

use std::io;
use std::path::Path;

use volray_core::Image;

use crate::atomic::{PendingFile, write_pending};
use crate::error::IoError;

/// Bits per channel of a written PNG.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BitDepth {
    #[default]
    Eight,
    Sixteen,
}

/// `round(clamp(c, 0, 1) · 255)`, with NaN mapped to 0.
pub fn quantize_8(c: f32) -> u8 {
    if c.is_nan() {
        0
    } else {
        (c.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// `image`'s RGB bytes, 8 bits a channel ([`quantize_8`], as the PNGs
/// `volray render` writes), top row first, written into `rgb` (its
/// allocation reused): what the viewer encodes, a movie pipes to ffmpeg
/// and Python hands over.
pub fn rgb8(image: &Image, rgb: &mut Vec<u8>) {
    rgb.clear();
    rgb.reserve(image.pixels().len() * 3);
    for px in image.pixels() {
        rgb.extend(px[..3].iter().map(|&c| quantize_8(c)));
    }
}

/// `round(clamp(c, 0, 1) · 65535)`, with NaN mapped to 0.
pub fn quantize_16(c: f32) -> u16 {
    if c.is_nan() {
        0
    } else {
        (c.clamp(0.0, 1.0) * 65535.0).round() as u16
    }
}

/// Largest width or height PNG allows.
const PNG_MAX_SIDE: usize = (1 << 31) - 1;

/// Writes `image` to `path` as an RGB PNG of the given bit depth, top row
/// first, atomically (see [`write_atomically`](crate::write_atomically)).
pub fn write_png(path: &Path, image: &Image, depth: BitDepth) -> Result<(), IoError> {
    crate::atomic::publish_all(vec![write_png_pending(path, image, depth)?]).map(|_| ())
}

/// Encodes `image` as [`write_png`] does into a complete temporary file
/// for `path`, published later (frames of a PNG sequence).
pub(crate) fn write_png_pending(
    path: &Path,
    image: &Image,
    depth: BitDepth,
) -> Result<PendingFile, IoError> {
    let (width, height) = (image.width(), image.height());
    let side_ok = |n: usize| (1..=PNG_MAX_SIDE).contains(&n);
    if !side_ok(width) || !side_ok(height) {
        return Err(IoError::ImageSize {
            path: path.to_path_buf(),
            width,
            height,
        });
    }

    let bytes_per_sample = match depth {
        BitDepth::Eight => 1,
        BitDepth::Sixteen => 2,
    };
    let size = image
        .pixels()
        .len()
        .checked_mul(3 * bytes_per_sample)
        .ok_or(IoError::ImageSize {
            path: path.to_path_buf(),
            width,
            height,
        })?;
    let mut data = Vec::with_capacity(size);
    for px in image.pixels() {
        for &c in &px[..3] {
            match depth {
                BitDepth::Eight => data.push(quantize_8(c)),
                BitDepth::Sixteen => data.extend_from_slice(&quantize_16(c).to_be_bytes()),
            }
        }
    }

    write_pending(path, |w| {
        // Sides were checked to be at most 2^31 − 1, so they fit in u32.
        let mut encoder = ::png::Encoder::new(w, width as u32, height as u32);
        encoder.set_color(::png::ColorType::Rgb);
        encoder.set_depth(match depth {
            BitDepth::Eight => ::png::BitDepth::Eight,
            BitDepth::Sixteen => ::png::BitDepth::Sixteen,
        });
        let mut writer = encoder.write_header().map_err(encoding_to_io)?;
        writer.write_image_data(&data).map_err(encoding_to_io)?;
        writer.finish().map_err(encoding_to_io)
    })
}

fn encoding_to_io(e: ::png::EncodingError) -> io::Error {
    match e {
        ::png::EncodingError::IoError(e) => e,
        other => io::Error::other(other),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;
    use std::io::BufReader;

    fn decode(path: &Path) -> (::png::OutputInfo, Vec<u8>) {
        let file = BufReader::new(fs::File::open(path).unwrap());
        let mut reader = ::png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info, buf)
    }

    /// A 3×2 image whose pixels differ in every channel, alpha not 1.
    fn test_image() -> Image {
        let pixels = vec![
            [0.0, 0.5, 1.0, 0.3],
            [1.0 / 255.0, 2.0, -1.0, 0.0],
            [f32::NAN, 0.25, 0.75, 1.0],
            [0.1, 0.2, 0.3, 0.5],
            [0.9999, 0.0001, 0.5019608, 0.5],
            [1.0, 1.0, 1.0, 0.0],
        ];
        Image::from_pixels(3, 2, pixels).unwrap()
    }

    #[test]
    fn quantisation_rounds_clamps_and_zeroes_nan() {
        assert_eq!(quantize_8(0.0), 0);
        assert_eq!(quantize_8(1.0), 255);
        assert_eq!(quantize_8(0.5), 128); // 127.5 rounds away from zero
        assert_eq!(quantize_8(0.499 / 255.0), 0);
        assert_eq!(quantize_8(0.501 / 255.0), 1);
        assert_eq!(quantize_8(-3.0), 0);
        assert_eq!(quantize_8(7.0), 255);
        assert_eq!(quantize_8(f32::NAN), 0);
        assert_eq!(quantize_8(f32::INFINITY), 255);
        assert_eq!(quantize_8(f32::NEG_INFINITY), 0);
        assert_eq!(quantize_16(1.0), 65535);
        assert_eq!(quantize_16(0.5), 32768);
        assert_eq!(quantize_16(f32::NAN), 0);
        assert_eq!(quantize_16(-0.1), 0);
    }

    #[test]
    fn eight_bit_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("im.png");
        write_png(&p, &test_image(), BitDepth::Eight).unwrap();
        let (info, buf) = decode(&p);
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(info.color_type, ::png::ColorType::Rgb);
        assert_eq!(info.bit_depth, ::png::BitDepth::Eight);
        #[rustfmt::skip]
        let want: Vec<u8> = vec![
            0, 128, 255,   1, 255, 0,   0, 64, 191,
            26, 51, 77,   255, 0, 128,   255, 255, 255,
        ];
        assert_eq!(buf, want);
    }

    #[test]
    fn sixteen_bit_round_trip_is_big_endian() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("im16.png");
        write_png(&p, &test_image(), BitDepth::Sixteen).unwrap();
        let (info, buf) = decode(&p);
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(info.color_type, ::png::ColorType::Rgb);
        assert_eq!(info.bit_depth, ::png::BitDepth::Sixteen);
        let got: Vec<u16> = buf
            .chunks_exact(2)
            .map(|c| u16::from_be_bytes([c[0], c[1]]))
            .collect();
        #[rustfmt::skip]
        let want: Vec<u16> = vec![
            0, 32768, 65535,   257, 65535, 0,   0, 16384, 49151,
            6554, 13107, 19661,   65528, 7, 32896,   65535, 65535, 65535,
        ];
        assert_eq!(got, want);
    }

    #[test]
    fn rows_are_written_top_first() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("rows.png");
        let mut im = Image::new(1, 3, [0.0, 0.0, 0.0, 1.0]);
        im.set(0, 0, [1.0, 0.0, 0.0, 1.0]);
        im.set(0, 2, [0.0, 0.0, 1.0, 1.0]);
        write_png(&p, &im, BitDepth::Eight).unwrap();
        let (_, buf) = decode(&p);
        assert_eq!(buf, [255, 0, 0, 0, 0, 0, 0, 0, 255]);
    }

    #[test]
    fn empty_image_is_refused_and_nothing_written() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("empty.png");
        let err = write_png(&p, &Image::new(0, 4, [0.0; 4]), BitDepth::Eight).unwrap_err();
        assert!(!err.is_io_failure());
        assert!(err.to_string().contains("0x4"), "{err}");
        assert!(!p.exists());
    }

    #[test]
    fn missing_directory_is_an_io_failure() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing").join("im.png");
        let err = write_png(&p, &test_image(), BitDepth::Eight).unwrap_err();
        assert!(err.is_io_failure());
        assert!(matches!(err, IoError::NoSuchDirectory { .. }));
    }
}
