//! `--outline`: the twelve edges of a volume's box, projected through
//! the view the frame was rendered with (orthographic or perspective, the
//! renderer's own [`View::project`]) and drawn as anti-aliased lines over
//! the frame. An edge that leaves the frame is clipped to it; in
//! perspective, the part of an edge behind the eye is cut off at a plane
//! just in front of it before projecting, so an eye inside the box still
//! draws what it sees of the edges and nothing panics.

use crate::line::{Point, line};
use volray_core::Image;
use volray_core::camera::View;
use volray_core::glam::DVec3;

/// The box's corners: corner `i` takes its x from `max` where bit 0 of
/// `i` is set, y where bit 1 is, z where bit 2 is.
pub fn corners((lo, hi): (DVec3, DVec3)) -> [DVec3; 8] {
    std::array::from_fn(|i| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// The box's edges, as pairs of [`corners`]: those differing in one bit.
pub const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// The segment `a`–`b` in image coordinates, as `view` projects it; in
/// perspective, the part of it behind the eye (nearer than a thousandth
/// of the farther end's depth) cut off first. `None` if nothing of it is
/// in front of the eye.
pub fn project_segment(view: &View, a: DVec3, b: DVec3) -> Option<(Point, Point)> {
    match view {
        View::Orthographic(_) => Some((view.project(a)?, view.project(b)?)),
        View::Perspective(v) => {
            let (da, db) = ((a - v.eye).dot(v.direction), (b - v.eye).dot(v.direction));
            let near = da.max(db) * 1e-3;
            if near.is_nan() || near <= 0.0 {
                return None;
            }
            let cut = |p: DVec3, dp: f64, q: DVec3, dq: f64| {
                if dp >= near {
                    p
                } else {
                    p + (q - p) * ((near - dp) / (dq - dp))
                }
            };
            let (a2, b2) = (cut(a, da, b, db), cut(b, db, a, da));
            Some((view.project(a2)?, view.project(b2)?))
        }
    }
}

/// Draws the edges of `bounds` as `view` sees them into `image`, `width`
/// pixels wide, in `ink`; each edge's segment in image coordinates (before
/// clipping to the frame), or `None` where it lies behind the eye.
pub fn draw(
    image: &mut Image,
    view: &View,
    bounds: (DVec3, DVec3),
    width: f64,
    ink: [f32; 3],
) -> Vec<Option<(Point, Point)>> {
    let c = corners(bounds);
    EDGES
        .iter()
        .map(|&(i, j)| {
            let segment = project_segment(view, c[i], c[j]);
            if let Some((a, b)) = segment {
                line(image, a, b, width, ink);
            }
            segment
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_core::camera::Camera;
    use volray_core::{Fit, Projection};

    #[test]
    fn every_edge_joins_two_corners_that_differ_along_one_axis() {
        let c = corners((DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)));
        let mut seen = std::collections::HashSet::new();
        for &(i, j) in &EDGES {
            let d = c[j] - c[i];
            assert_eq!(
                (d.x != 0.0) as u8 + (d.y != 0.0) as u8 + (d.z != 0.0) as u8,
                1
            );
            assert!(seen.insert((i, j)));
        }
    }

    /// The distance from `p` to the segment `a`–`b`.
    fn distance(p: Point, (a, b): (Point, Point)) -> f64 {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
    }

    #[test]
    fn the_edges_join_the_projected_corners_and_ink_only_their_pixels() {
        let bounds = (DVec3::new(-1.0, -2.0, -0.5), DVec3::new(1.0, 2.0, 0.5));
        for projection in [
            Projection::Orthographic,
            Projection::Perspective { fov_degrees: 40.0 },
        ] {
            let camera = Camera {
                azimuth: 35.0,
                elevation: 25.0,
                projection,
                zoom: 1.3,
                ..Camera::default()
            };
            let (w, h) = (160, 120);
            let view = View::frame(&camera, bounds, w, h).unwrap();
            let mut image = Image::new(w, h, [0.0, 0.0, 0.0, 1.0]);
            let drawn = draw(&mut image, &view, bounds, 1.5, [1.0; 3]);
            let c = corners(bounds);
            let segments: Vec<(Point, Point)> = drawn.iter().map(|s| s.unwrap()).collect();
            for (k, &(i, j)) in EDGES.iter().enumerate() {
                let (a, b) = segments[k];
                let (pa, pb) = (view.project(c[i]).unwrap(), view.project(c[j]).unwrap());
                assert!((a.0 - pa.0).abs() < 1e-9 && (a.1 - pa.1).abs() < 1e-9);
                assert!((b.0 - pb.0).abs() < 1e-9 && (b.1 - pb.1).abs() < 1e-9);
                // Along the edge, the pixels carry the ink.
                for f in 1..20 {
                    let f = f as f64 / 20.0;
                    let p = (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
                    if p.0 >= 0.0 && p.1 >= 0.0 && p.0 < w as f64 && p.1 < h as f64 {
                        let ink = image.get(p.0 as usize, p.1 as usize)[0];
                        assert!(ink > 0.5, "{projection:?}: edge {k} at {p:?}: {ink}");
                    }
                }
            }
            // Far from every edge, the frame is as it was.
            let mut far = 0;
            for y in 0..h {
                for x in 0..w {
                    let p = (x as f64 + 0.5, y as f64 + 0.5);
                    let near = segments.iter().any(|&s| distance(p, s) < 1.5);
                    if !near {
                        assert_eq!(image.get(x, y), [0.0, 0.0, 0.0, 1.0], "({x}, {y})");
                        far += 1;
                    }
                }
            }
            assert!(far > w * h / 2, "{far}");
        }
    }

    #[test]
    fn edges_beyond_the_frame_are_clipped() {
        // Zoomed in: the box's edges run far outside the frame.
        let bounds = (DVec3::splat(-1.0), DVec3::ONE);
        for projection in [
            Projection::Orthographic,
            Projection::Perspective { fov_degrees: 30.0 },
        ] {
            let camera = Camera {
                azimuth: 20.0,
                elevation: 10.0,
                zoom: 40.0,
                projection,
                ..Camera::default()
            };
            let view = View::frame(&camera, bounds, 50, 50).unwrap();
            let mut image = Image::new(50, 50, [0.0, 0.0, 0.0, 1.0]);
            draw(&mut image, &view, bounds, 2.0, [1.0; 3]);
        }
    }

    #[test]
    fn an_eye_inside_the_box_draws_what_is_in_front_without_panicking() {
        let bounds = (DVec3::splat(-1.0), DVec3::ONE);
        let camera = Camera {
            view_point: Some(DVec3::new(0.5, 0.1, 0.2)),
            look_at: Some(DVec3::new(-1.0, 0.0, 0.0)),
            projection: Projection::Perspective { fov_degrees: 60.0 },
            fit: Fit::Box,
            ..Camera::default()
        };
        let view = View::frame(&camera, bounds, 64, 48).unwrap();
        let mut image = Image::new(64, 48, [0.0, 0.0, 0.0, 1.0]);
        let drawn = draw(&mut image, &view, bounds, 1.5, [1.0; 3]);
        // The four edges of the far face (x = −1) are in front; some
        // behind the eye are not.
        assert!(drawn.iter().filter(|s| s.is_some()).count() >= 4);
        assert!(image.pixels().iter().any(|p| p[0] > 0.5));
    }
}
