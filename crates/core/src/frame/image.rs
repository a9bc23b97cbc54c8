//! The `Image`: an RGBA `f32` frame buffer, row 0 at the top.
//!
//! Colour channels hold linear values in [0, 1] (the paper's colour model
//! has no gamma); writers quantise them. The alpha channel holds the
//! accumulated opacity of the volume alone, `1 − Π(1 − αᵢ)` over the ray's
//! samples, background excluded: the colour already has the opaque
//! background composited in, so alpha tells how much of a pixel the volume
//! covers.

/// An RGBA `f32` frame buffer, row-major, row 0 at the top of the picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    width: usize,
    height: usize,
    pixels: Vec<[f32; 4]>,
}

impl Image {
    /// A `width × height` image filled with `fill`.
    ///
    /// # Panics
    /// If `width · height` overflows `usize` (callers validate sizes first).
    pub fn new(width: usize, height: usize, fill: [f32; 4]) -> Self {
        let count = width
            .checked_mul(height)
            .expect("image size overflows usize");
        Image {
            width,
            height,
            pixels: vec![fill; count],
        }
    }

    /// An image from row-major pixels; `None` if the count is not `width · height`.
    pub fn from_pixels(width: usize, height: usize, pixels: Vec<[f32; 4]>) -> Option<Self> {
        (width.checked_mul(height) == Some(pixels.len())).then_some(Image {
            width,
            height,
            pixels,
        })
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Pixel at column `x`, row `y` (row 0 at the top).
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> [f32; 4] {
        self.pixels[x + self.width * y]
    }

    #[inline]
    pub fn set(&mut self, x: usize, y: usize, rgba: [f32; 4]) {
        self.pixels[x + self.width * y] = rgba;
    }

    /// All pixels, row-major.
    pub fn pixels(&self) -> &[[f32; 4]] {
        &self.pixels
    }

    pub fn pixels_mut(&mut self) -> &mut [[f32; 4]] {
        &mut self.pixels
    }

    /// The pixels, row-major, giving up the image.
    pub fn into_pixels(self) -> Vec<[f32; 4]> {
        self.pixels
    }

    /// Largest absolute difference over all pixels and channels, or `None`
    /// when the sizes differ.
    pub fn max_abs_diff(&self, other: &Image) -> Option<f32> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let diff = self
            .pixels
            .iter()
            .zip(&other.pixels)
            .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        Some(diff)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_start_at_the_top() {
        let mut im = Image::new(3, 2, [0.0; 4]);
        im.set(2, 1, [1.0, 0.5, 0.25, 1.0]);
        assert_eq!(im.pixels()[5], [1.0, 0.5, 0.25, 1.0]);
        assert_eq!(im.get(2, 1), [1.0, 0.5, 0.25, 1.0]);
    }

    #[test]
    fn diff_measures_largest_channel_error() {
        let a = Image::new(2, 2, [0.5; 4]);
        let mut b = a.clone();
        b.set(1, 1, [0.5, 0.5, 0.75, 0.5]);
        assert_eq!(a.max_abs_diff(&b), Some(0.25));
        assert_eq!(a.max_abs_diff(&Image::new(1, 4, [0.5; 4])), None);
        assert!(Image::from_pixels(2, 2, vec![[0.0; 4]; 3]).is_none());
    }
}
