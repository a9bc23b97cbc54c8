//! Partial images: a frame's pixels before the background is applied,
//! what the casters produce and what compositors combine.
//!
//! A composited frame holds per pixel the premultiplied colour and the
//! transmittance of the ray's samples, `[r, g, b, T]`
//! ([`PartialPixel`]); a projection (maximum, minimum, average) holds the
//! ray's running projection of the scalar ([`Projected`]). Two partial
//! images of the same view, rendered from two pieces of the volume,
//! [`combine`](PartialImage::combine) into the partial image of both:
//! the front one over the back one (composite; [`over`], associative, so
//! any grouping of pieces in visibility order gives the same image within
//! rounding), or the projections merged (any order). [`PartialImage::finish`]
//! then applies the opaque background once, at the very end, and maps
//! projected values to colour. Distributed and tiled renderers exchange
//! exactly these.

use crate::frame::image::Image;
use crate::kernels::composite::{EMPTY, PartialPixel, over, over_background};
use crate::kernels::projection::Projected;
use crate::settings::Blend;
use rayon::prelude::*;

/// A frame's partial pixels, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct PartialImage {
    width: usize,
    height: usize,
    pixels: PartialPixels,
}

/// The pixels of a [`PartialImage`], by blend mode.
#[derive(Debug, Clone, PartialEq)]
pub enum PartialPixels {
    /// Composited: premultiplied colour and transmittance per pixel.
    Composite(Vec<PartialPixel>),
    /// A projection of the scalar (`blend` is not [`Blend::Composite`]):
    /// each ray's running maximum, minimum or sum.
    Projection {
        blend: Blend,
        pixels: Vec<Projected>,
    },
}

impl PartialImage {
    /// A composited `width × height` frame with nothing composited yet
    /// (every pixel `[0, 0, 0, 1]`).
    ///
    /// # Panics
    /// If `width · height` overflows `usize` (callers validate sizes first).
    pub fn composite(width: usize, height: usize) -> Self {
        Self::from_composite(width, height, Vec::new())
    }

    /// A composited frame that reuses the allocation of `buffer` (the
    /// pixels of an earlier frame, say), every pixel set to nothing
    /// composited yet.
    pub fn from_composite(width: usize, height: usize, mut buffer: Vec<PartialPixel>) -> Self {
        buffer.clear();
        Self::reusing(width, height, buffer)
    }

    /// A composited frame in `buffer`'s allocation whose pixels are left
    /// as they are (those past the buffer's length are nothing composited
    /// yet): for a caster that writes every pixel, which the fast casters
    /// do, so that a frame does not pay for clearing it first.
    pub(crate) fn reusing(width: usize, height: usize, mut buffer: Vec<PartialPixel>) -> Self {
        let count = width
            .checked_mul(height)
            .expect("image size overflows usize");
        buffer.resize(count, EMPTY);
        PartialImage {
            width,
            height,
            pixels: PartialPixels::Composite(buffer),
        }
    }

    /// A `width × height` projection `blend` with no sample yet.
    ///
    /// # Panics
    /// If `blend` is [`Blend::Composite`], or the size overflows.
    pub fn projection(width: usize, height: usize, blend: Blend) -> Self {
        assert!(blend.is_projection(), "{blend:?} is not a projection");
        let count = width
            .checked_mul(height)
            .expect("image size overflows usize");
        PartialImage {
            width,
            height,
            pixels: PartialPixels::Projection {
                blend,
                pixels: vec![Projected::empty(blend); count],
            },
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub fn pixels(&self) -> &PartialPixels {
        &self.pixels
    }

    pub fn pixels_mut(&mut self) -> &mut PartialPixels {
        &mut self.pixels
    }

    /// The pixels of a composited frame, giving up the image; `None` for
    /// a projection.
    pub fn into_composite(self) -> Option<Vec<PartialPixel>> {
        match self.pixels {
            PartialPixels::Composite(pixels) => Some(pixels),
            PartialPixels::Projection { .. } => None,
        }
    }

    /// Combines `self`, rendered from a piece of the volume in front, with
    /// `behind`, from a piece behind it (for projections the order does
    /// not matter): afterwards `self` is the partial image of both.
    ///
    /// # Panics
    /// If the two differ in size or blend mode.
    pub fn combine(&mut self, behind: &PartialImage) {
        assert_eq!(
            (self.width, self.height),
            (behind.width, behind.height),
            "partial images of different sizes"
        );
        match (&mut self.pixels, &behind.pixels) {
            (PartialPixels::Composite(front), PartialPixels::Composite(back)) => {
                for (f, b) in front.iter_mut().zip(back) {
                    *f = over(*f, *b);
                }
            }
            (
                PartialPixels::Projection { blend, pixels },
                PartialPixels::Projection {
                    blend: other,
                    pixels: back,
                },
            ) if blend == other => {
                for (f, b) in pixels.iter_mut().zip(back) {
                    *f = f.merge(*blend, *b);
                }
            }
            _ => panic!("partial images of different blend modes"),
        }
    }

    /// The finished image: composited pixels over the opaque `background`
    /// (alpha the volume's opacity, `1 − T`); projected values through
    /// `colour` (the transfer function's map of a value), opaque, or the
    /// background where a ray took no sample (alpha 0).
    pub fn finish(self, background: [f32; 3], colour: impl Fn(f32) -> [f32; 3] + Sync) -> Image {
        let pixels: Vec<[f32; 4]> = match self.pixels {
            PartialPixels::Composite(mut pixels) => {
                (pixels.par_iter_mut()).for_each(|p| *p = over_background(*p, background));
                pixels
            }
            PartialPixels::Projection { blend, pixels } => (pixels.par_iter())
                .map(|p| match p.value(blend) {
                    Some(f) => {
                        let [r, g, b] = colour(f as f32);
                        [r, g, b, 1.0]
                    }
                    None => [background[0], background[1], background[2], 0.0],
                })
                .collect(),
        };
        Image::from_pixels(self.width, self.height, pixels).expect("the partial image's size")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composited_pieces_combine_front_to_back_then_take_the_background() {
        let mut front = PartialImage::composite(2, 1);
        let mut back = PartialImage::composite(2, 1);
        let PartialPixels::Composite(f) = front.pixels_mut() else {
            unreachable!()
        };
        // Pixel 0: a half-transparent red in front; pixel 1: nothing.
        f[0] = [0.5, 0.0, 0.0, 0.5];
        let PartialPixels::Composite(b) = back.pixels_mut() else {
            unreachable!()
        };
        b[0] = [0.0, 0.25, 0.0, 0.75];
        b[1] = [0.0, 0.0, 0.5, 0.5];
        front.combine(&back);
        let image = front.finish([0.0, 0.0, 1.0], |_| unreachable!());
        // 0.5 red, then 0.5·0.25 green, then 0.5·0.75 of the blue background.
        assert_eq!(image.get(0, 0), [0.5, 0.125, 0.375, 1.0 - 0.375]);
        assert_eq!(image.get(1, 0), [0.0, 0.0, 1.0, 0.5]);
    }

    #[test]
    fn projections_merge_then_map_their_values_to_colour() {
        let mut a = PartialImage::projection(3, 1, Blend::Maximum);
        let mut b = PartialImage::projection(3, 1, Blend::Maximum);
        let set = |img: &mut PartialImage, i: usize, value: f64| {
            let PartialPixels::Projection { pixels, .. } = img.pixels_mut() else {
                unreachable!()
            };
            pixels[i] = Projected { value, count: 1 };
        };
        set(&mut a, 0, 2.0);
        set(&mut b, 0, 5.0);
        set(&mut b, 1, -1.0);
        a.combine(&b);
        let image = a.finish([0.1, 0.2, 0.3], |f| [f / 10.0; 3]);
        assert_eq!(image.get(0, 0), [0.5, 0.5, 0.5, 1.0]);
        assert_eq!(image.get(1, 0), [-0.1, -0.1, -0.1, 1.0]);
        assert_eq!(image.get(2, 0), [0.1, 0.2, 0.3, 0.0]);
    }

    #[test]
    #[should_panic(expected = "different blend modes")]
    fn a_projection_does_not_combine_with_a_composite() {
        let mut a = PartialImage::projection(1, 1, Blend::Average);
        a.combine(&PartialImage::composite(1, 1));
    }
}
