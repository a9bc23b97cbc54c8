//! A tiny built-in bitmap font for the montages' panel labels such as
//! `(5,3)`: the digits, parentheses and the comma, 5 × 7 pixels each, drawn
//! at one pixel per font pixel. Enough for the labels and nothing more, so
//! no font file or rasteriser is needed.

use thiserror::Error;
use volray_core::Image;

/// Pixels across one glyph.
pub const GLYPH_WIDTH: usize = 5;
/// Pixels down one glyph.
pub const GLYPH_HEIGHT: usize = 7;
/// Pixels from one glyph's left edge to the next: one blank column between.
pub const ADVANCE: usize = GLYPH_WIDTH + 1;

/// A character the font has no glyph for.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[error("the label font has no glyph for {0:?} (it has 0-9, '(', ')', ',' and ' ')")]
pub struct MissingGlyph(pub char);

/// The glyph of `c`: seven rows, top first, each the five pixels of a row in
/// the low bits, the leftmost pixel in bit 4.
pub fn glyph(c: char) -> Option<[u8; GLYPH_HEIGHT]> {
    Some(match c {
        '0' => [
            0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110,
        ],
        '1' => [
            0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110,
        ],
        '2' => [
            0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111,
        ],
        '3' => [
            0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110,
        ],
        '4' => [
            0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010,
        ],
        '5' => [
            0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110,
        ],
        '6' => [
            0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110,
        ],
        '7' => [
            0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000,
        ],
        '8' => [
            0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110,
        ],
        '9' => [
            0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100,
        ],
        '(' => [
            0b00010, 0b00100, 0b01000, 0b01000, 0b01000, 0b00100, 0b00010,
        ],
        ')' => [
            0b01000, 0b00100, 0b00010, 0b00010, 0b00010, 0b00100, 0b01000,
        ],
        ',' => [
            0b00000, 0b00000, 0b00000, 0b00000, 0b01100, 0b00100, 0b01000,
        ],
        ' ' => [0; GLYPH_HEIGHT],
        _ => return None,
    })
}

/// Width in pixels of `text` drawn with [`draw_text`] (no trailing blank
/// column); 0 for the empty string.
pub fn text_width(text: &str) -> usize {
    (text.chars().count() * ADVANCE).saturating_sub(1)
}

/// Draws `text` with its top-left corner at column `x`, row `y` in `color`
/// (alpha 1), clipped to the image. Every character is checked before
/// anything is drawn, so an unknown one leaves the image untouched.
pub fn draw_text(
    image: &mut Image,
    x: usize,
    y: usize,
    text: &str,
    color: [f32; 3],
) -> Result<(), MissingGlyph> {
    let glyphs = text
        .chars()
        .map(|c| glyph(c).ok_or(MissingGlyph(c)))
        .collect::<Result<Vec<_>, _>>()?;
    let [r, g, b] = color;
    for (i, rows) in glyphs.iter().enumerate() {
        let left = x + i * ADVANCE;
        for (dy, bits) in rows.iter().enumerate() {
            for dx in 0..GLYPH_WIDTH {
                let (px, py) = (left + dx, y + dy);
                if bits & (1 << (GLYPH_WIDTH - 1 - dx)) != 0
                    && px < image.width()
                    && py < image.height()
                {
                    image.set(px, py, [r, g, b, 1.0]);
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHARS: &str = "0123456789(),";

    fn lit(image: &Image) -> Vec<(usize, usize)> {
        (0..image.height())
            .flat_map(|y| (0..image.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| image.get(x, y)[3] == 1.0)
            .collect()
    }

    #[test]
    fn glyphs_fit_their_box_and_are_all_different() {
        let glyphs: Vec<_> = CHARS.chars().map(|c| glyph(c).unwrap()).collect();
        for (c, g) in CHARS.chars().zip(&glyphs) {
            assert!(g.iter().all(|row| *row < 1 << GLYPH_WIDTH), "{c}");
            assert!(g.iter().any(|row| *row != 0), "{c} is blank");
        }
        for i in 0..glyphs.len() {
            for j in 0..i {
                assert_ne!(glyphs[i], glyphs[j]);
            }
        }
        assert_eq!(glyph(' '), Some([0; GLYPH_HEIGHT]));
        assert_eq!(glyph('x'), None);
    }

    #[test]
    fn parentheses_mirror_each_other() {
        let open = glyph('(').unwrap();
        let close = glyph(')').unwrap();
        for (a, b) in open.iter().zip(&close) {
            let mirrored = (0..GLYPH_WIDTH).fold(0u8, |m, i| m | ((a >> i) & 1) << (4 - i));
            assert_eq!(mirrored, *b);
        }
    }

    #[test]
    fn text_is_laid_out_left_to_right_one_column_apart() {
        assert_eq!(text_width(""), 0);
        assert_eq!(text_width("1"), GLYPH_WIDTH);
        assert_eq!(text_width("(5,3)"), 5 * ADVANCE - 1);

        let mut image = Image::new(40, 12, [0.0; 4]);
        draw_text(&mut image, 3, 2, "(1,0)", [1.0, 0.5, 0.25]).unwrap();
        let pixels = lit(&image);
        let bits: u32 = "(1,0)"
            .chars()
            .flat_map(|c| glyph(c).unwrap())
            .map(u8::count_ones)
            .sum();
        assert_eq!(pixels.len(), bits as usize);
        let (xmin, xmax) = pixels
            .iter()
            .fold((usize::MAX, 0), |(a, b), &(x, _)| (a.min(x), b.max(x)));
        let (ymin, ymax) = pixels
            .iter()
            .fold((usize::MAX, 0), |(a, b), &(_, y)| (a.min(y), b.max(y)));
        // '(' starts in its column 1; ')' ends in its column 3.
        assert_eq!((xmin, xmax), (3 + 1, 3 + 4 * ADVANCE + 3));
        assert_eq!((ymin, ymax), (2, 2 + GLYPH_HEIGHT - 1));
        assert_eq!(image.get(xmin, 2 + 2), [1.0, 0.5, 0.25, 1.0]);
        // The '1' of "(1,0)" is glyph 1: its stem is column 2 of that glyph.
        for dy in 0..GLYPH_HEIGHT {
            assert_eq!(image.get(3 + ADVANCE + 2, 2 + dy)[3], 1.0);
        }
    }

    #[test]
    fn drawing_is_clipped_and_unknown_characters_draw_nothing() {
        let mut image = Image::new(4, 4, [0.0; 4]);
        draw_text(&mut image, 2, 1, "88", [1.0; 3]).unwrap();
        assert!(!lit(&image).is_empty());
        let mut clean = Image::new(20, 10, [0.0; 4]);
        assert_eq!(
            draw_text(&mut clean, 0, 0, "(1,x)", [1.0; 3]),
            Err(MissingGlyph('x'))
        );
        assert!(lit(&clean).is_empty());
    }
}
