//! Text in a frame: one embedded open font (DejaVu Sans, subset to Latin-1,
//! Greek and the symbols units and numbers need: `fonts/`), laid out on a
//! baseline with the font's advances and kerning, rasterised by `ab_glyph`
//! (exact area coverage of each pixel by the glyphs' outlines), and
//! blended over the frame's pixels. Any size: the outlines are scaled, not
//! bitmaps, so text is as crisp at 4096² as at 240².

use ab_glyph::{Font as _, FontRef, PxScale, ScaleFont, point};
use std::sync::OnceLock;
use volray_core::Image;

/// The embedded font's file: DejaVu Sans (Bitstream Vera licence, see
/// `fonts/LICENSE-DejaVu`), subset with fontTools' `pyftsubset` to
/// U+0020–007E, U+00A0–00FF, Greek, super- and subscript digits, and
/// − × ± ≈ ≤ ≥ ∞ ‰ Å – — ….
const FONT: &[u8] = include_bytes!("../fonts/DejaVuSans-subset.ttf");

/// The embedded font.
pub struct Font {
    font: FontRef<'static>,
}

/// Text rasterised: each pixel's coverage by the glyphs, in `[0, 1]`,
/// row by row; the baseline's row and the text's left edge are at
/// `origin` within it.
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    pub width: usize,
    pub height: usize,
    /// Where the pen started: the left end of the baseline, in the
    /// coverage's pixels (`x` may be negative for a glyph reaching left).
    pub origin: (i32, i32),
    pub alpha: Vec<f32>,
}

impl Font {
    /// The embedded font (parsed once).
    pub fn embedded() -> &'static Font {
        static FONT_CELL: OnceLock<Font> = OnceLock::new();
        FONT_CELL.get_or_init(|| Font {
            font: FontRef::try_from_slice(FONT).expect("the embedded font parses"),
        })
    }

    /// `(width, ascent, descent)` of `text` at `size` pixels per em: the
    /// pen's advance, and how far the font rises above and falls below the
    /// baseline (descent ≥ 0).
    pub fn measure(&self, text: &str, size: f32) -> (f32, f32, f32) {
        let scaled = self.font.as_scaled(PxScale::from(size));
        let width = self
            .positions(text, size)
            .last()
            .map_or(0.0, |&(id, x)| x + scaled.h_advance(id));
        (width, scaled.ascent(), -scaled.descent())
    }

    /// Each glyph of `text` and its pen position along the baseline.
    fn positions(&self, text: &str, size: f32) -> Vec<(ab_glyph::GlyphId, f32)> {
        let scaled = self.font.as_scaled(PxScale::from(size));
        let mut x = 0.0;
        let mut last = None;
        let mut out = Vec::with_capacity(text.len());
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            if let Some(prev) = last {
                x += scaled.kern(prev, id);
            }
            out.push((id, x));
            x += scaled.h_advance(id);
            last = Some(id);
        }
        out
    }

    /// `text` at `size` pixels per em, rasterised (the pen starting at
    /// `fraction`, a sub-pixel offset of the baseline's left end).
    pub fn coverage(&self, text: &str, size: f32, fraction: (f32, f32)) -> Coverage {
        let (width, ascent, descent) = self.measure(text, size);
        // A margin for glyphs reaching past their advance (italics, `j`).
        let margin = (size / 4.0).ceil() as i32 + 1;
        let origin = (margin, ascent.ceil() as i32 + 1);
        let w = (width.ceil() as i32 + 2 * margin).max(1) as usize;
        let h = (origin.1 + descent.ceil() as i32 + 2).max(1) as usize;
        let mut alpha = vec![0.0f32; w * h];
        let scale = PxScale::from(size);
        for (id, x) in self.positions(text, size) {
            let pen = point(
                origin.0 as f32 + fraction.0 + x,
                origin.1 as f32 + fraction.1,
            );
            let glyph = id.with_scale_and_position(scale, pen);
            if let Some(outlined) = self.font.outline_glyph(glyph) {
                let b = outlined.px_bounds();
                outlined.draw(|gx, gy, c| {
                    let (px, py) = (b.min.x as i32 + gx as i32, b.min.y as i32 + gy as i32);
                    if px >= 0 && py >= 0 && (px as usize) < w && (py as usize) < h {
                        let a = &mut alpha[py as usize * w + px as usize];
                        // Glyphs of one string do not overlap but by
                        // anti-aliased edges: coverage adds, to 1.
                        *a = (*a + c).min(1.0);
                    }
                });
            }
        }
        Coverage {
            width: w,
            height: h,
            origin,
            alpha,
        }
    }

    /// Draws `text` in `colour` at `size` pixels per em into `image`, the
    /// baseline's left end at `(x, y)` (pixels, y down), blended over
    /// what is there ([`blend`]).
    pub fn draw(
        &self,
        image: &mut Image,
        text: &str,
        size: f32,
        (x, y): (f32, f32),
        colour: [f32; 3],
    ) {
        let (fx, fy) = (x.floor(), y.floor());
        let coverage = self.coverage(text, size, (x - fx, y - fy));
        let left = fx as i64 - i64::from(coverage.origin.0);
        let top = fy as i64 - i64::from(coverage.origin.1);
        for row in 0..coverage.height {
            for col in 0..coverage.width {
                let a = coverage.alpha[row * coverage.width + col];
                if a > 0.0 {
                    blend(image, left + col as i64, top + row as i64, colour, a);
                }
            }
        }
    }
}

/// `colour` over pixel `(x, y)` of `image` with opacity `a` (nothing
/// outside the image): `c·a + dst·(1 − a)`, and the pixel's opacity
/// `a + dst·(1 − a)`.
pub fn blend(image: &mut Image, x: i64, y: i64, colour: [f32; 3], a: f32) {
    if x < 0 || y < 0 || x as usize >= image.width() || y as usize >= image.height() {
        return;
    }
    let (x, y) = (x as usize, y as usize);
    let p = image.get(x, y);
    let a = a.clamp(0.0, 1.0);
    image.set(
        x,
        y,
        [
            colour[0] * a + p[0] * (1.0 - a),
            colour[1] * a + p[1] * (1.0 - a),
            colour[2] * a + p[2] * (1.0 - a),
            a + p[3] * (1.0 - a),
        ],
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_the_fonts_own_rasterisation_blended_in_place() {
        // Drawn at a whole pixel, the pixels are exactly the coverage's
        // blend of white over the background.
        let font = Font::embedded();
        for (size, side) in [(11.0f32, 240), (96.0, 4096)] {
            let mut image = Image::new(side, side / 8, [0.1, 0.2, 0.3, 1.0]);
            let text = "10 mm · ψ₆₂₁ Å";
            let baseline: f32 = (size * 1.2_f32).floor();
            font.draw(&mut image, text, size, (5.0, baseline), [1.0; 3]);
            let c = font.coverage(text, size, (0.0, 0.0));
            let (left, top) = (5 - c.origin.0 as i64, baseline as i64 - c.origin.1 as i64);
            let mut inked = 0;
            for row in 0..c.height {
                for col in 0..c.width {
                    let a = c.alpha[row * c.width + col];
                    let (x, y) = (left + col as i64, top + row as i64);
                    if x < 0 || y < 0 {
                        continue;
                    }
                    let p = image.get(x as usize, y as usize);
                    let want = 0.1 * (1.0 - a) + a;
                    assert!((p[0] - want).abs() < 1e-6, "{size}: ({x}, {y}) {p:?} {a}");
                    inked += (a > 0.5) as usize;
                }
            }
            // Legible: a good share of the text's box is ink, not a blur.
            let (w, ascent, _) = font.measure(text, size);
            let ink = inked as f32 / (w * ascent);
            assert!(ink > 0.08 && ink < 0.6, "{size}: {ink}");
        }
    }

    #[test]
    fn different_text_rasterises_differently_and_width_grows_with_size() {
        let font = Font::embedded();
        let a = font.coverage("o", 20.0, (0.0, 0.0));
        let b = font.coverage("c", 20.0, (0.0, 0.0));
        assert_eq!(a.height, b.height);
        // An o is a c closed on the right: more ink, and where the c has
        // none.
        let ink = |c: &Coverage| c.alpha.iter().sum::<f32>();
        assert!(ink(&a) > ink(&b) * 1.1, "{} {}", ink(&a), ink(&b));
        let (w10, _, _) = font.measure("0123456789", 10.0);
        let (w40, _, _) = font.measure("0123456789", 40.0);
        assert!((w40 / w10 - 4.0).abs() < 0.05, "{w10} {w40}");
        // Every character the labels need is in the subset.
        for c in "0123456789.-−+×±µÅ°²³ψφθ mm nm µm Å HU".chars() {
            let id = font.font.glyph_id(c);
            assert!(c == ' ' || id.0 != 0, "{c:?} is missing");
        }
    }
}
