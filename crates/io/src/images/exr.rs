//! OpenEXR output: the frame buffer as linear 32-bit float RGBA, for
//! compositing and for analysis without 8/16-bit quantisation.

use std::io::Cursor;
use std::path::Path;

use ::exr::prelude::{Image as ExrImage, SpecificChannels, Vec2, WritableImage};
use volray_core::Image;

use crate::atomic::write_atomically;
use crate::error::IoError;

/// Writes `image` to `path` as a single-part scan-line OpenEXR file with
/// f32 channels R, G, B, A exactly as the frame buffer holds them (colour
/// with the background composited in, alpha the volume's accumulated
/// opacity: see [`Image`]), top row first, atomically.
pub fn write_exr(path: &Path, image: &Image) -> Result<(), IoError> {
    let (width, height) = (image.width(), image.height());
    if width == 0 || height == 0 {
        return Err(IoError::ImageSize {
            path: path.to_path_buf(),
            width,
            height,
        });
    }
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let [r, g, b, a] = image.get(x, y);
        (r, g, b, a)
    });
    let exr = ExrImage::from_channels((width, height), channels);
    let mut bytes = Cursor::new(Vec::new());
    exr.write()
        .to_buffered(&mut bytes)
        .map_err(|e| IoError::invalid(path, format!("cannot encode OpenEXR: {e}")))?;
    let bytes = bytes.into_inner();
    write_atomically(path, |w| w.write_all(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ::exr::prelude::read_first_rgba_layer_from_file;

    #[test]
    fn round_trip_keeps_floats_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.exr");
        let mut img = Image::new(3, 2, [0.0; 4]);
        img.set(0, 0, [0.125, 1.5, -0.25, 0.5]);
        img.set(2, 1, [1e-7, 0.333, 7.0, 1.0]);
        write_exr(&p, &img).unwrap();
        let read = read_first_rgba_layer_from_file(
            &p,
            |res, _| vec![[0f32; 4]; res.width() * res.height()],
            |px: &mut Vec<[f32; 4]>, Vec2(x, y), (r, g, b, a): (f32, f32, f32, f32)| {
                px[y * 3 + x] = [r, g, b, a]
            },
        )
        .unwrap();
        let px = &read.layer_data.channel_data.pixels;
        assert_eq!(px[0], [0.125, 1.5, -0.25, 0.5]);
        assert_eq!(px[5], [1e-7, 0.333, 7.0, 1.0]);
        assert_eq!(px[1], [0.0; 4]);
    }
}
