//! Pieces of partial images on the wire: the non-empty rectangle of a
//! range of rows, and compositing one into an image.
//!
//! A message is a 17-byte header, the kind (`0` composited, `1`
//! projected) and the rectangle's rows `r0..r1` and columns `c0..c1` as
//! little-endian `u32`s, then its pixels row by row: `[r, g, b, T]` as
//! four `f32`s, or a projection's value (`f64`) and sample count (`u64`).
//! Pixels outside the rectangle are empty (nothing composited, no sample
//! projected), so they are not sent: a piece of the volume covers a small
//! part of the image, and after each swap round a smaller one still.

use std::ops::Range;
use thiserror::Error;
use volray_core::kernels::composite::{EMPTY, over};
use volray_core::kernels::projection::Projected;
use volray_core::{PartialImage, PartialPixels};

const HEADER: usize = 17;

/// A message that is not a piece of this image.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum WireError {
    #[error("a message of {0} bytes is shorter than its header")]
    Short(usize),
    #[error("a message of kind {0}, not of this image's blend")]
    Kind(u8),
    #[error("rectangle rows {rows:?} columns {cols:?} outside a {width}x{height} image")]
    Outside {
        rows: Range<usize>,
        cols: Range<usize>,
        width: usize,
        height: usize,
    },
    #[error("a rectangle of {pixels} pixels sent in {bytes} bytes")]
    Length { pixels: usize, bytes: usize },
}

fn kind(image: &PartialImage) -> u8 {
    match image.pixels() {
        PartialPixels::Composite(_) => 0,
        PartialPixels::Projection { .. } => 1,
    }
}

/// The bounding rectangle `(rows, cols)` of the pixels in `rows` that
/// are not empty; empty ranges if none is.
pub fn non_empty(image: &PartialImage, rows: Range<usize>) -> (Range<usize>, Range<usize>) {
    let width = image.width();
    let filled = |i: usize| match image.pixels() {
        PartialPixels::Composite(p) => p[i] != EMPTY,
        PartialPixels::Projection { pixels, .. } => pixels[i].count > 0,
    };
    let (mut r0, mut r1, mut c0, mut c1) = (usize::MAX, 0, usize::MAX, 0);
    for row in rows {
        let base = row * width;
        let Some(first) = (0..width).find(|&c| filled(base + c)) else {
            continue;
        };
        let last = (first..width)
            .rev()
            .find(|&c| filled(base + c))
            .unwrap_or(first);
        r0 = r0.min(row);
        r1 = row + 1;
        c0 = c0.min(first);
        c1 = c1.max(last + 1);
    }
    if r0 == usize::MAX {
        return (0..0, 0..0);
    }
    (r0..r1, c0..c1)
}

/// The non-empty rectangle of `rows` of `image`, as a message.
pub fn encode(image: &PartialImage, rows: Range<usize>) -> Vec<u8> {
    let (rows, cols) = non_empty(image, rows);
    let width = image.width();
    let pixel_bytes = match image.pixels() {
        PartialPixels::Composite(_) => 16,
        PartialPixels::Projection { .. } => 16,
    };
    let mut out = Vec::with_capacity(HEADER + rows.len() * cols.len() * pixel_bytes);
    out.push(kind(image));
    for v in [rows.start, rows.end, cols.start, cols.end] {
        out.extend_from_slice(&(v as u32).to_le_bytes());
    }
    for row in rows {
        let span = row * width + cols.start..row * width + cols.end;
        match image.pixels() {
            PartialPixels::Composite(p) => {
                for px in &p[span] {
                    for c in px {
                        out.extend_from_slice(&c.to_le_bytes());
                    }
                }
            }
            PartialPixels::Projection { pixels, .. } => {
                for px in &pixels[span] {
                    out.extend_from_slice(&px.value.to_le_bytes());
                    out.extend_from_slice(&px.count.to_le_bytes());
                }
            }
        }
    }
    out
}

/// Composites the message `bytes` into `image`: this image's pixels in
/// front of the message's if `mine_in_front`, else behind them
/// (projections merge either way). Returns the rectangle's pixel count.
pub fn combine_into(
    image: &mut PartialImage,
    bytes: &[u8],
    mine_in_front: bool,
) -> Result<usize, WireError> {
    if bytes.len() < HEADER {
        return Err(WireError::Short(bytes.len()));
    }
    if bytes[0] != kind(image) {
        return Err(WireError::Kind(bytes[0]));
    }
    let field = |i: usize| {
        let at = 1 + 4 * i;
        u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize
    };
    let (rows, cols) = (field(0)..field(1), field(2)..field(3));
    let (width, height) = (image.width(), image.height());
    if rows.start > rows.end || cols.start > cols.end || rows.end > height || cols.end > width {
        return Err(WireError::Outside {
            rows,
            cols,
            width,
            height,
        });
    }
    let count = rows.len() * cols.len();
    let body = &bytes[HEADER..];
    if body.len() != count * 16 {
        return Err(WireError::Length {
            pixels: count,
            bytes: body.len(),
        });
    }
    let mut chunks = body.chunks_exact(16);
    let f32_at = |c: &[u8], i: usize| f32::from_le_bytes(c[4 * i..4 * i + 4].try_into().unwrap());
    for row in rows {
        let span = row * width + cols.start..row * width + cols.end;
        match image.pixels_mut() {
            PartialPixels::Composite(p) => {
                for (mine, c) in p[span].iter_mut().zip(&mut chunks) {
                    let theirs = [f32_at(c, 0), f32_at(c, 1), f32_at(c, 2), f32_at(c, 3)];
                    *mine = if mine_in_front {
                        over(*mine, theirs)
                    } else {
                        over(theirs, *mine)
                    };
                }
            }
            PartialPixels::Projection { blend, pixels } => {
                for (mine, c) in pixels[span].iter_mut().zip(&mut chunks) {
                    let theirs = Projected {
                        value: f64::from_le_bytes(c[0..8].try_into().unwrap()),
                        count: u64::from_le_bytes(c[8..16].try_into().unwrap()),
                    };
                    *mine = if mine_in_front {
                        mine.merge(*blend, theirs)
                    } else {
                        theirs.merge(*blend, *mine)
                    };
                }
            }
        }
    }
    Ok(count)
}

/// Sets the pixels of `rows` of `image` to empty.
pub fn clear(image: &mut PartialImage, rows: Range<usize>) {
    let width = image.width();
    let span = rows.start * width..rows.end * width;
    match image.pixels_mut() {
        PartialPixels::Composite(p) => p[span].fill(EMPTY),
        PartialPixels::Projection { blend, pixels } => pixels[span].fill(Projected::empty(*blend)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_core::Blend;

    fn set(image: &mut PartialImage, i: usize, px: [f32; 4]) {
        let PartialPixels::Composite(p) = image.pixels_mut() else {
            unreachable!()
        };
        p[i] = px;
    }

    #[test]
    fn only_the_non_empty_rectangle_is_sent_and_it_composites_in_order() {
        let mut a = PartialImage::composite(5, 4);
        set(&mut a, 5 + 1, [0.5, 0.0, 0.0, 0.5]);
        set(&mut a, 2 * 5 + 3, [0.0, 0.25, 0.0, 0.75]);
        assert_eq!(non_empty(&a, 0..4), (1..3, 1..4));
        let bytes = encode(&a, 0..4);
        assert_eq!(bytes.len(), HEADER + 2 * 3 * 16);
        // Rows outside the range asked for are not sent.
        assert_eq!(encode(&a, 3..4).len(), HEADER);

        let mut b = PartialImage::composite(5, 4);
        set(&mut b, 5 + 1, [0.0, 0.0, 0.2, 0.8]);
        let mut front = b.clone();
        combine_into(&mut front, &bytes, true).unwrap();
        let mut behind = b.clone();
        combine_into(&mut behind, &bytes, false).unwrap();
        let PartialPixels::Composite(f) = front.pixels() else {
            unreachable!()
        };
        let PartialPixels::Composite(k) = behind.pixels() else {
            unreachable!()
        };
        assert_eq!(f[6], over([0.0, 0.0, 0.2, 0.8], [0.5, 0.0, 0.0, 0.5]));
        assert_eq!(k[6], over([0.5, 0.0, 0.0, 0.5], [0.0, 0.0, 0.2, 0.8]));
        assert_eq!(f[13], [0.0, 0.25, 0.0, 0.75]);
        assert_eq!(f[0], EMPTY);
    }

    #[test]
    fn projections_merge_sums_and_counts() {
        let mut a = PartialImage::projection(2, 1, Blend::Average);
        let PartialPixels::Projection { pixels, .. } = a.pixels_mut() else {
            unreachable!()
        };
        pixels[1] = Projected {
            value: 3.0,
            count: 2,
        };
        let bytes = encode(&a, 0..1);
        let mut b = a.clone();
        combine_into(&mut b, &bytes, false).unwrap();
        let PartialPixels::Projection { pixels, .. } = b.pixels() else {
            unreachable!()
        };
        assert_eq!(
            pixels[1],
            Projected {
                value: 6.0,
                count: 4
            }
        );
        assert_eq!(pixels[0].count, 0);
    }

    #[test]
    fn malformed_messages_are_refused() {
        let mut a = PartialImage::composite(2, 2);
        assert_eq!(
            combine_into(&mut a, &[0; 3], true),
            Err(WireError::Short(3))
        );
        let mut bytes = encode(&PartialImage::composite(2, 2), 0..2);
        bytes[0] = 1;
        assert_eq!(combine_into(&mut a, &bytes, true), Err(WireError::Kind(1)));
        let mut big = vec![0u8; HEADER];
        big[1..5].copy_from_slice(&0u32.to_le_bytes());
        big[5..9].copy_from_slice(&9u32.to_le_bytes());
        assert!(matches!(
            combine_into(&mut a, &big, true),
            Err(WireError::Outside { .. })
        ));
        big[5..9].copy_from_slice(&1u32.to_le_bytes());
        big[13..17].copy_from_slice(&2u32.to_le_bytes());
        assert!(matches!(
            combine_into(&mut a, &big, true),
            Err(WireError::Length { pixels: 2, .. })
        ));
    }
}
