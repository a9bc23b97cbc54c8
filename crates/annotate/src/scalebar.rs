//! A scale bar: a round length in the volume's units (1, 2 or 5 times a
//! power of ten, about a fifth of the frame's width), drawn as a bar of
//! that many pixels in the frame's lower left corner, with its length
//! written over it.
//!
//! A pixel is one size only in an orthographic view (its size in world
//! units is the view's); in perspective a pixel's size depends on depth,
//! so a scale bar there holds only at one depth, and says so: the caller
//! marks it approximate (`≈`), for the depth of the volume's centre.

use crate::colorbar::Layout;
use crate::text::{Font, blend};
use crate::ticks::{label, nice_step};
use volray_core::Image;

/// A scale bar.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleBar<'a> {
    /// World units per pixel.
    pub pixel_size: f64,
    /// The length to show, in world units; `None`: a round one.
    pub length: Option<f64>,
    /// The volume's unit (`mm`, `Å`); `None`: none written.
    pub unit: Option<&'a str>,
    /// Written with `≈`: the length holds at one depth only (perspective).
    pub approximate: bool,
}

/// Where a scale bar was drawn: its first and one-past-last column, its
/// row, and the length it shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drawn {
    pub x0: usize,
    pub x1: usize,
    pub y: usize,
    pub length: f64,
}

impl ScaleBar<'_> {
    /// The round length about a fifth of an image `width` pixels wide.
    pub fn round_length(pixel_size: f64, width: usize) -> f64 {
        let target = pixel_size * width as f64 / 5.0;
        let step = nice_step(target, 1);
        // Not longer than two fifths of the frame.
        if step / pixel_size > 0.4 * width as f64 {
            step / 2.0
        } else {
            step
        }
    }

    /// Draws the bar into `image` in `ink`.
    pub fn draw(&self, image: &mut Image, ink: [f32; 3]) -> Drawn {
        let l = Layout::of(image);
        let (w, h) = (image.width(), image.height());
        let length = self
            .length
            .unwrap_or_else(|| Self::round_length(self.pixel_size, w));
        let pixels = (length / self.pixel_size).round() as usize;
        let x0 = l.margin;
        let x1 = (x0 + pixels).min(w);
        let thick = (2 * l.line).max(2);
        let y = h.saturating_sub(l.margin + thick);
        for x in x0..x1 {
            for t in 0..thick {
                blend(image, x as i64, (y + t) as i64, ink, 1.0);
            }
        }
        // End marks, then the length over the middle of the bar.
        for x in [x0, x1.saturating_sub(1)] {
            for t in 0..3 * thick {
                blend(image, x as i64, (y + thick) as i64 - t as i64, ink, 1.0);
            }
        }
        let mut text = label(length, length);
        if let Some(unit) = self.unit {
            text = format!("{text} {unit}");
        }
        if self.approximate {
            text = format!("≈ {text}");
        }
        let font = Font::embedded();
        let (tw, _, descent) = font.measure(&text, l.text);
        let tx = ((x0 + x1) as f32 / 2.0 - tw / 2.0).max(1.0);
        let ty = y as f32 - 2.0 * thick as f32 - descent;
        font.draw(image, &text, l.text, (tx, ty), ink);
        Drawn { x0, x1, y, length }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bar_is_its_length_over_the_pixel_size_within_a_pixel() {
        for (side, pixel) in [(240, 0.37), (1024, 0.05), (4096, 2.5e-3)] {
            let mut image = Image::new(side, side, [0.0, 0.0, 0.0, 1.0]);
            let bar = ScaleBar {
                pixel_size: pixel,
                length: None,
                unit: Some("mm"),
                approximate: false,
            };
            let d = bar.draw(&mut image, [1.0; 3]);
            let want = d.length / pixel;
            assert!(
                ((d.x1 - d.x0) as f64 - want).abs() <= 1.0,
                "{side}: {d:?} {want}"
            );
            // A round length, about a fifth of the width.
            let mantissa = d.length / 10f64.powf(d.length.log10().floor());
            assert!(
                [1.0, 2.0, 5.0].iter().any(|m| (m - mantissa).abs() < 1e-9),
                "{d:?}"
            );
            assert!(
                want > side as f64 / 12.0 && want < side as f64 * 0.4,
                "{d:?}"
            );
            // The bar's pixels are ink; the row under it is not.
            let mid = (d.x0 + d.x1) / 2;
            assert_eq!(image.get(mid, d.y), [1.0; 4]);
            assert_eq!(image.get(mid, d.y + 2 * (side / 240).max(1) + 2)[0], 0.0);
        }
    }

    #[test]
    fn a_given_length_is_drawn_as_given() {
        let mut image = Image::new(500, 300, [1.0; 4]);
        let d = ScaleBar {
            pixel_size: 0.1,
            length: Some(25.0),
            unit: Some("µm"),
            approximate: true,
        }
        .draw(&mut image, [0.0; 3]);
        assert_eq!(d.x1 - d.x0, 250);
    }
}
