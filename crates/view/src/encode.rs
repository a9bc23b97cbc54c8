//! Frames as image files for the page: JPEG while the view moves (small,
//! quick to encode and decode), PNG once it stops. Both quantise as
//! `volray render` writes its PNGs ([`volray_io::quantize_8`]), so the
//! still frame's pixels are the command's.

use volray_core::Image;
use volray_io::rgb8;

/// The JPEG quality of frames shown while the view moves.
pub const DRAFT_QUALITY: u8 = 80;

/// The encoders' failures.
#[derive(Debug, thiserror::Error)]
pub enum EncodeError {
    #[error("JPEG encoding failed: {0}")]
    Jpeg(#[from] jpeg_encoder::EncodingError),
    #[error("PNG encoding failed: {0}")]
    Png(#[from] png::EncodingError),
    #[error("a {0}x{1} frame is too large for a JPEG")]
    TooLarge(usize, usize),
}

/// `image` as a JPEG of `quality` (1 to 100).
pub fn jpeg(image: &Image, quality: u8, rgb: &mut Vec<u8>) -> Result<Vec<u8>, EncodeError> {
    let (width, height) = (image.width(), image.height());
    let (Ok(w), Ok(h)) = (u16::try_from(width), u16::try_from(height)) else {
        return Err(EncodeError::TooLarge(width, height));
    };
    rgb8(image, rgb);
    let mut out = Vec::with_capacity(rgb.len() / 8);
    jpeg_encoder::Encoder::new(&mut out, quality).encode(
        rgb,
        w,
        h,
        jpeg_encoder::ColorType::Rgb,
    )?;
    Ok(out)
}

/// `image` as an 8-bit RGB PNG, compressed quickly.
pub fn png(image: &Image, rgb: &mut Vec<u8>) -> Result<Vec<u8>, EncodeError> {
    rgb8(image, rgb);
    let mut out = Vec::with_capacity(rgb.len() / 2);
    let mut encoder = png::Encoder::new(&mut out, image.width() as u32, image.height() as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient() -> Image {
        let mut image = Image::new(40, 30, [0.0; 4]);
        for y in 0..30 {
            for x in 0..40 {
                image.set(x, y, [x as f32 / 39.0, y as f32 / 29.0, 0.5, 1.0]);
            }
        }
        image
    }

    #[test]
    fn png_holds_the_quantised_pixels_exactly() {
        let image = gradient();
        let bytes = png(&image, &mut Vec::new()).unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (40, 30));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let mut expected = Vec::new();
        rgb8(&image, &mut expected);
        assert_eq!(&buf[..info.buffer_size()], &expected[..]);
        // 39/39 is 255, 0 is 0, 0.5 rounds to 128.
        assert_eq!(&expected[39 * 3..39 * 3 + 3], &[255, 0, 128]);
    }

    #[test]
    fn jpeg_is_a_jpeg_of_the_frame_size() {
        let bytes = jpeg(&gradient(), DRAFT_QUALITY, &mut Vec::new()).unwrap();
        assert_eq!(&bytes[..2], &[0xFF, 0xD8]);
        // The SOF0 marker carries height then width.
        let sof = bytes.windows(2).position(|w| w == [0xFF, 0xC0]).unwrap();
        let h = u16::from_be_bytes([bytes[sof + 5], bytes[sof + 6]]);
        let w = u16::from_be_bytes([bytes[sof + 7], bytes[sof + 8]]);
        assert_eq!((w, h), (40, 30));
        assert!(jpeg(&Image::new(70000, 1, [0.0; 4]), 80, &mut Vec::new()).is_err());
    }
}
