//! `--axes`: an orientation triad, three short lines from one point for
//! the world's +x, +y and +z, turned as the camera is turned (their
//! directions on the screen are the view's right and up vectors dotted
//! with each axis: the orientation, not the perspective, so the triad
//! reads the same wherever it sits), red, green and blue, each named at
//! its tip in the embedded font. The names are the volume's own where its
//! world has them (`R`, `A`, `S` for a NIfTI file's RAS+), else x, y, z.
//!
//! It sits in the bottom right corner (left of a colour bar there). An
//! axis along the view is a dot with its
//! name beside it; the axes pointing away are drawn first, so the nearer
//! ones lie over them.

use crate::colorbar::Layout;
use crate::line::{Point, line, width_for};
use crate::text::Font;
use volray_core::Image;
use volray_core::camera::View;
use volray_core::glam::DVec3;

/// The axes' colours: x red, y green, z blue (light enough to read on a
/// dark background).
pub const COLOURS: [[f32; 3]; 3] = [[0.95, 0.25, 0.2], [0.3, 0.85, 0.3], [0.35, 0.5, 1.0]];

/// Where the triad was drawn: its origin, each axis's tip (image
/// coordinates) and its length in pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drawn {
    pub origin: Point,
    pub tips: [Point; 3],
    pub length: f64,
}

/// The unit vectors of the screen (right, up) and the view direction.
fn orientation(view: &View) -> (DVec3, DVec3, DVec3) {
    match view {
        View::Orthographic(v) => (v.right, v.up, v.direction),
        View::Perspective(v) => (v.right, v.up, v.direction),
    }
}

/// Draws the triad of `view` into `image`, the axes named `names`, at
/// the bottom of the frame, its names reaching to column `right` (the
/// frame's margin, or a colour bar's edge).
pub fn draw(image: &mut Image, view: &View, names: [&str; 3], right: f64) -> Drawn {
    let l = Layout::of(image);
    let h = image.height() as f64;
    let side = (image.width() as f64).min(h);
    let length = (side / 14.0).max(10.0);
    let text = l.text;
    let reach = length + f64::from(text);
    let origin = (right - reach, h - l.margin as f64 - reach);
    let (screen_right, up, direction) = orientation(view);
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let tips: [Point; 3] = std::array::from_fn(|i| {
        (
            origin.0 + length * axes[i].dot(screen_right),
            origin.1 - length * axes[i].dot(up),
        )
    });
    // Farthest first: the axis pointing most into the screen.
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| axes[b].dot(direction).total_cmp(&axes[a].dot(direction)));
    let font = Font::embedded();
    let width = width_for(image);
    for i in order {
        let tip = tips[i];
        line(image, origin, tip, width, COLOURS[i]);
        // The name beyond the tip, along the axis (beside the origin for
        // an axis along the view).
        let (dx, dy) = (tip.0 - origin.0, tip.1 - origin.1);
        let d = dx.hypot(dy);
        let (ux, uy) = if d > 0.2 * length {
            (dx / d, dy / d)
        } else {
            (0.6, 0.6)
        };
        let reach = 0.3 * length + 0.5 * f64::from(text);
        let centre = (tip.0 + ux * reach, tip.1 + uy * reach);
        let (tw, ascent, _) = font.measure(names[i], text);
        let baseline = centre.1 as f32 + 0.35 * ascent;
        font.draw(
            image,
            names[i],
            text,
            (centre.0 as f32 - tw / 2.0, baseline),
            COLOURS[i],
        );
    }
    Drawn {
        origin,
        tips,
        length,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_core::camera::Camera;

    /// The mean offset from the triad's origin of the pixels in axis
    /// `i`'s colour.
    fn mean_offset(image: &Image, origin: Point, i: usize) -> Option<Point> {
        let mut sum = (0.0, 0.0, 0.0);
        for y in 0..image.height() {
            for x in 0..image.width() {
                let p = image.get(x, y);
                let c = COLOURS[i];
                let others = (0..3).filter(|&k| k != i);
                // Ink of this axis: its dominant channel well above the
                // others.
                let k = (0..3).max_by(|&a, &b| c[a].total_cmp(&c[b])).unwrap();
                if p[k] > 0.4 && others.clone().all(|o| o == k || p[o] < 0.7 * p[k]) {
                    let a = f64::from(p[k]);
                    sum.0 += a * (x as f64 + 0.5 - origin.0);
                    sum.1 += a * (y as f64 + 0.5 - origin.1);
                    sum.2 += a;
                }
            }
        }
        (sum.2 > 0.0).then(|| (sum.0 / sum.2, sum.1 / sum.2))
    }

    /// The image direction `view` projects the world axis `axis` along,
    /// from the box's centre.
    fn projected(view: &View, axis: DVec3) -> Point {
        let a = view.project(DVec3::ZERO).unwrap();
        let b = view.project(axis).unwrap();
        (b.0 - a.0, b.1 - a.1)
    }

    fn angle(a: Point, b: Point) -> f64 {
        let cos = (a.0 * b.0 + a.1 * b.1) / (a.0.hypot(a.1) * b.0.hypot(b.1));
        cos.clamp(-1.0, 1.0).acos().to_degrees()
    }

    #[test]
    fn each_axis_points_where_the_view_projects_it() {
        let bounds = (DVec3::splat(-1.0), DVec3::ONE);
        for (azimuth, elevation) in [(0.0, 0.0), (90.0, 0.0), (30.0, 20.0), (-120.0, -35.0)] {
            let camera = Camera {
                azimuth,
                elevation,
                ..Camera::default()
            };
            let view = View::frame(&camera, bounds, 240, 240).unwrap();
            let mut image = Image::new(240, 240, [0.0, 0.0, 0.0, 1.0]);
            let drawn = draw(&mut image, &view, ["x", "y", "z"], 230.0);
            for (i, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
                let want = projected(&view, axis);
                let tip = (
                    drawn.tips[i].0 - drawn.origin.0,
                    drawn.tips[i].1 - drawn.origin.1,
                );
                let pixels = mean_offset(&image, drawn.origin, i).expect("no ink");
                if want.0.hypot(want.1) < 1e-9 {
                    // Along the view: a dot.
                    assert!(tip.0.hypot(tip.1) < 1e-6, "{azimuth}: {i} {tip:?}");
                    continue;
                }
                assert!(angle(tip, want) < 1e-6, "{azimuth} {elevation}: {i}");
                assert!(
                    angle(pixels, want) < 12.0,
                    "{azimuth} {elevation}: axis {i}: ink {pixels:?}, projected {want:?}"
                );
            }
        }
        // Azimuth 0: the paper's view along −x, y to the right, z up.
        let view = View::frame(&Camera::default(), bounds, 240, 240).unwrap();
        assert!(angle(projected(&view, DVec3::Y), (1.0, 0.0)) < 1e-9);
        assert!(angle(projected(&view, DVec3::Z), (0.0, -1.0)) < 1e-9);
    }

    #[test]
    fn the_triad_stays_in_its_corner_and_names_its_axes() {
        let view = View::frame(
            &Camera {
                azimuth: 30.0,
                elevation: 20.0,
                ..Camera::default()
            },
            (DVec3::ZERO, DVec3::ONE),
            300,
            200,
        )
        .unwrap();
        for right in [292.0, 230.0] {
            let mut image = Image::new(300, 200, [0.0, 0.0, 0.0, 1.0]);
            let drawn = draw(&mut image, &view, ["R", "A", "S"], right);
            for y in 0..200 {
                for x in 0..300 {
                    if image.get(x, y) != [0.0, 0.0, 0.0, 1.0] {
                        assert!(x > 150 && (x as f64) < right + 1.0 && y > 120, "({x}, {y})");
                    }
                }
            }
            // Other names, other pixels.
            let mut other = Image::new(300, 200, [0.0, 0.0, 0.0, 1.0]);
            assert_eq!(draw(&mut other, &view, ["x", "y", "z"], right), drawn);
            assert_ne!(other, image);
        }
    }
}
