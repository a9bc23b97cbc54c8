//! Anti-aliased straight lines, for the outline and the axes: a segment
//! of width `w` covers a pixel by `w/2 + 1/2 − d`, clamped to `[0, 1]`,
//! where `d` is the distance from the pixel's centre to the segment (one
//! pixel of soft edge, a full pixel of ink on the segment itself), and is
//! blended over the frame ([`blend`]). A segment is first clipped to the
//! frame (Liang–Barsky): endpoints far outside it, or not finite, cost
//! nothing and never panic.

use crate::text::blend;
use volray_core::Image;

/// A point in image coordinates: (column, row), pixel `(c, r)` covering
/// `[c, c+1) × [r, r+1)`, as [`volray_core::camera::View::project`] gives.
pub type Point = (f64, f64);

/// The part of the segment `a`–`b` within `[x0, x1] × [y0, y1]`, if any.
pub fn clip(a: Point, b: Point, (x0, y0): Point, (x1, y1): Point) -> Option<(Point, Point)> {
    if ![a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
        return None;
    }
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    // Exact at the ends (t = 0, 1), and checked: coordinates so large
    // that rounding moves the cut points are dropped, not drawn.
    let at = |t: f64| ((1.0 - t) * a.0 + t * b.0, (1.0 - t) * a.1 + t * b.1);
    let (p, q) = (at(t0), at(t1));
    let inside =
        |p: Point| p.0 >= x0 - 1.0 && p.0 <= x1 + 1.0 && p.1 >= y0 - 1.0 && p.1 <= y1 + 1.0;
    (inside(p) && inside(q)).then_some((p, q))
}

/// How much of the pixel whose centre is `p` a segment `a`–`b` of
/// `width` pixels covers.
pub fn coverage(p: Point, a: Point, b: Point, width: f64) -> f32 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let length2 = dx * dx + dy * dy;
    let t = if length2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy);
    (width / 2.0 + 0.5 - d).clamp(0.0, 1.0) as f32
}

/// Draws the segment `a`–`b`, `width` pixels wide, in `colour` over
/// `image`; the pixels it touched (for tests and callers that avoid them).
pub fn line(image: &mut Image, a: Point, b: Point, width: f64, colour: [f32; 3]) -> usize {
    let pad = width / 2.0 + 1.0;
    let (w, h) = (image.width() as f64, image.height() as f64);
    let Some((a, b)) = clip(a, b, (-pad, -pad), (w + pad, h + pad)) else {
        return 0;
    };
    let left = (a.0.min(b.0) - pad).floor().max(0.0) as usize;
    let right = ((a.0.max(b.0) + pad).ceil().min(w)) as usize;
    let top = (a.1.min(b.1) - pad).floor().max(0.0) as usize;
    let bottom = ((a.1.max(b.1) + pad).ceil().min(h)) as usize;
    let mut touched = 0;
    for y in top..bottom {
        for x in left..right {
            let c = coverage((x as f64 + 0.5, y as f64 + 0.5), a, b, width);
            if c > 0.0 {
                blend(image, x as i64, y as i64, colour, c);
                touched += 1;
            }
        }
    }
    touched
}

/// The line width for a frame: 1.5 pixels up to 600² frames, 2 beyond.
pub fn width_for(image: &Image) -> f64 {
    if image.width().min(image.height()) > 600 {
        2.0
    } else {
        1.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_inks_its_pixels_and_nothing_far_from_it() {
        let mut image = Image::new(40, 30, [0.0, 0.0, 0.0, 1.0]);
        line(&mut image, (5.0, 5.5), (35.0, 5.5), 1.5, [1.0; 3]);
        for x in 5..35 {
            assert_eq!(image.get(x, 5), [1.0; 4], "{x}");
            assert_eq!(image.get(x, 8), [0.0, 0.0, 0.0, 1.0], "{x}");
        }
        // The soft edge: a quarter covered beside it.
        assert!((image.get(20, 6)[0] - 0.25).abs() < 1e-6);
        // A diagonal: every pixel its centre lies on carries full ink.
        let mut image = Image::new(40, 40, [0.0, 0.0, 0.0, 1.0]);
        line(&mut image, (2.5, 2.5), (30.5, 30.5), 1.0, [1.0; 3]);
        for i in 2..=30 {
            assert_eq!(image.get(i, i)[0], 1.0, "{i}");
        }
        assert_eq!(image.get(30, 10)[0], 0.0);
    }

    #[test]
    fn segments_far_outside_or_not_finite_are_clipped_without_panicking() {
        let mut image = Image::new(20, 20, [0.0, 0.0, 0.0, 1.0]);
        let before = image.clone();
        assert_eq!(
            line(&mut image, (-1e300, 5.0), (-1e10, 5.0), 2.0, [1.0; 3]),
            0
        );
        assert_eq!(
            line(&mut image, (f64::NAN, 5.0), (10.0, 5.0), 2.0, [1.0; 3]),
            0
        );
        assert_eq!(
            line(
                &mut image,
                (5.0, 1e308),
                (5.0, f64::INFINITY),
                2.0,
                [1.0; 3]
            ),
            0
        );
        assert_eq!(image, before);
        // Crossing the frame from far outside: only its part inside is drawn.
        let touched = line(&mut image, (-1e12, 10.5), (1e12, 10.5), 1.0, [1.0; 3]);
        assert!((20..=60).contains(&touched), "{touched}");
        for x in 0..20 {
            assert_eq!(image.get(x, 10)[0], 1.0);
        }
        let clipped = clip((-10.0, 0.0), (30.0, 20.0), (0.0, 0.0), (20.0, 20.0)).unwrap();
        assert_eq!(clipped, ((0.0, 5.0), (20.0, 15.0)));
        assert_eq!(
            clip((-10.0, -1.0), (-5.0, 30.0), (0.0, 0.0), (20.0, 20.0)),
            None
        );
    }
}
