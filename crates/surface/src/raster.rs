//! Triangle rasterisation into a z-buffer: hidden-surface removal.
//!
//! Triangles arrive in continuous image coordinates — pixel (c, r) covers
//! `[c, c + 1) × [r, r + 1)`, row 0 at the top, as
//! `volray_core::camera::OrthographicView::project` gives them — with a
//! depth per corner (larger is farther) and a normal per corner. A pixel
//! belongs to a triangle when its centre `(c + ½, r + ½)` is inside; the
//! triangle's depth and normal there are the barycentric interpolations of
//! its corners' (exact for depth under an orthographic projection). The
//! z-buffer keeps, per pixel, the nearest fragment.
//!
//! **No gaps, no double hits.** Inside is decided by the three edge
//! functions `E_ab(p) = (b − a) × (p − a)`. Each is computed from its
//! endpoints in a canonical order, so the two triangles that share an edge
//! get exactly opposite values (`E_ba = −E_ab` bit for bit) and no pixel
//! centre can fall between them through rounding. A centre exactly on an
//! edge (`E = 0`) goes to one side only, by the top-left rule of Direct3D
//! and OpenGL (the edge is owned when it runs upwards, or rightwards along a
//! row, on a triangle turned to positive area); this is the same as moving
//! the centre by an infinitesimal `(ε, ε²)`, so a centre on a shared vertex
//! also goes to exactly one of the triangles around it. So a tessellated
//! region covers each pixel centre inside it exactly once.
//!
//! Work is split into bands of rows drawn in parallel; within a band the
//! triangles are drawn in their given order and a fragment replaces the
//! stored one only when strictly nearer, so the result does not depend on
//! the thread count.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

/// Rows per parallel band.
const BAND_ROWS: usize = 16;

/// A triangle in image coordinates with depth and normal per corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenTriangle {
    /// (column, row) of each corner, continuous.
    pub corners: [DVec2; 3],
    /// Distance of each corner along the rays (larger is farther).
    pub depth: [f64; 3],
    /// Each corner's normal (interpolated, then normalised by the shader).
    pub normals: [DVec3; 3],
}

/// One edge function `E(p) = sign · d × (p − o)`, with `o`, `d` taken from
/// the endpoints in canonical order so that the reversed edge has the exactly
/// opposite value.
#[derive(Debug, Clone, Copy)]
struct Edge {
    origin: DVec2,
    direction: DVec2,
    sign: f64,
    /// Whether a point exactly on the edge belongs to this triangle.
    owns_ties: bool,
}

impl Edge {
    fn new(from: DVec2, to: DVec2) -> Self {
        let (origin, direction, sign) = if (from.x, from.y) <= (to.x, to.y) {
            (from, to - from, 1.0)
        } else {
            (to, from - to, -1.0)
        };
        // Traversed from → to on a triangle of positive area, the inside is
        // where E > 0; the tie goes to the side an offset (ε, ε²) reaches:
        // (to − from) × (1, ε) > 0.
        let t = to - from;
        Edge {
            origin,
            direction,
            sign,
            owns_ties: t.y < 0.0 || (t.y == 0.0 && t.x > 0.0),
        }
    }

    #[inline]
    fn at(&self, p: DVec2) -> f64 {
        self.sign * self.direction.perp_dot(p - self.origin)
    }

    #[inline]
    fn covers(&self, value: f64) -> bool {
        value > 0.0 || (value == 0.0 && self.owns_ties)
    }
}

/// Calls `hit(column, row, barycentrics)` for every pixel in rows `rows`
/// (and columns `0..width`) whose centre `triangle` covers; the
/// barycentric weights belong to the corners in their given order.
/// Triangles of zero area cover nothing.
pub fn cover(
    triangle: [DVec2; 3],
    width: usize,
    rows: std::ops::Range<usize>,
    mut hit: impl FnMut(usize, usize, [f64; 3]),
) {
    let [a, b, c] = triangle;
    let area = Edge::new(a, b).at(c);
    // Turn to positive area; `order` maps the turned corners back.
    let (b, c, order) = if area > 0.0 {
        (b, c, [0, 1, 2])
    } else if area < 0.0 {
        (c, b, [0, 2, 1])
    } else {
        return; // zero area (or NaN)
    };
    // Edge opposite each corner: bc opposite a, ca opposite b, ab opposite c.
    let edges = [Edge::new(b, c), Edge::new(c, a), Edge::new(a, b)];
    let lo = a.min(b).min(c);
    let hi = a.max(b).max(c);
    // Pixel centres k + ½ within [lo, hi]; `as` saturates far-off values.
    let first = |x: f64| (x - 0.5).ceil().max(0.0) as usize;
    let last = |x: f64| (x - 0.5).floor();
    let row_end = last(hi.y);
    let col_end = last(hi.x);
    if row_end < 0.0 || col_end < 0.0 {
        return;
    }
    let rows = first(lo.y).max(rows.start)..(row_end as usize).saturating_add(1).min(rows.end);
    let cols = first(lo.x)..(col_end as usize).saturating_add(1).min(width);
    for row in rows {
        for col in cols.clone() {
            let p = DVec2::new(col as f64 + 0.5, row as f64 + 0.5);
            let e = edges.map(|edge| edge.at(p));
            if !(0..3).all(|k| edges[k].covers(e[k])) {
                continue;
            }
            let sum = e[0] + e[1] + e[2];
            if sum <= 0.0 {
                continue; // only on a triangle too thin to have an inside
            }
            let mut weights = [0.0; 3];
            for k in 0..3 {
                weights[order[k]] = e[k] / sum;
            }
            hit(col, row, weights);
        }
    }
}

/// Per pixel, the nearest fragment drawn: its depth (`+∞` where none) and
/// its interpolated, unnormalised normal.
#[derive(Debug, Clone, PartialEq)]
pub struct ZBuffer {
    width: usize,
    height: usize,
    depth: Vec<f64>,
    normal: Vec<Vec3>,
}

impl ZBuffer {
    /// Draws `triangles` into a `width × height` z-buffer.
    pub fn draw(triangles: &[ScreenTriangle], width: usize, height: usize) -> ZBuffer {
        if width == 0 || height == 0 {
            return ZBuffer {
                width,
                height,
                depth: Vec::new(),
                normal: Vec::new(),
            };
        }
        let bands = height.div_ceil(BAND_ROWS);
        let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (index, t) in triangles.iter().enumerate() {
            let lo = t.corners.iter().map(|c| c.y).fold(f64::INFINITY, f64::min);
            let hi = t
                .corners
                .iter()
                .map(|c| c.y)
                .fold(f64::NEG_INFINITY, f64::max);
            // Rows whose centres lie in [lo, hi], clamped to the image.
            let (first, last) = ((lo - 0.5).ceil(), (hi - 0.5).floor());
            if !(first <= last && last >= 0.0 && first < height as f64) {
                continue;
            }
            let (first, last) = (first.max(0.0) as usize, (last as usize).min(height - 1));
            for band in binned
                .iter_mut()
                .take(last / BAND_ROWS + 1)
                .skip(first / BAND_ROWS)
            {
                band.push(index as u32);
            }
        }
        let mut depth = vec![f64::INFINITY; width * height];
        let mut normal = vec![Vec3::ZERO; width * height];
        depth
            .par_chunks_mut(BAND_ROWS * width)
            .zip(normal.par_chunks_mut(BAND_ROWS * width))
            .zip(&binned)
            .enumerate()
            .for_each(|(band, ((depth, normal), list))| {
                let top = band * BAND_ROWS;
                let rows = top..(top + BAND_ROWS).min(height);
                for &index in list {
                    let t = &triangles[index as usize];
                    cover(t.corners, width, rows.clone(), |col, row, w| {
                        let z = w[0] * t.depth[0] + w[1] * t.depth[1] + w[2] * t.depth[2];
                        let i = col + width * (row - top);
                        if z < depth[i] {
                            depth[i] = z;
                            normal[i] =
                                (w[0] * t.normals[0] + w[1] * t.normals[1] + w[2] * t.normals[2])
                                    .as_vec3();
                        }
                    });
                }
            });
        ZBuffer {
            width,
            height,
            depth,
            normal,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The nearest depth at (`col`, `row`), `+∞` where nothing was drawn.
    #[inline]
    pub fn depth(&self, col: usize, row: usize) -> f64 {
        self.depth[col + self.width * row]
    }

    /// The interpolated normal of the nearest fragment (not normalised).
    #[inline]
    pub fn normal(&self, col: usize, row: usize) -> Vec3 {
        self.normal[col + self.width * row]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coverage count per pixel of `triangles` on a `w × h` image.
    fn coverage(triangles: &[[DVec2; 3]], w: usize, h: usize) -> Vec<u32> {
        let mut count = vec![0u32; w * h];
        for t in triangles {
            cover(*t, w, 0..h, |c, r, _| count[c + w * r] += 1);
        }
        count
    }

    #[test]
    fn a_grid_of_triangles_aligned_with_pixel_centres_covers_each_once() {
        // The square [2.5, 12.5]² cut into unit cells through pixel centres,
        // each cell split both ways: every edge and vertex lies on centres.
        let mut tris = Vec::new();
        for i in 0..10 {
            for j in 0..10 {
                let p =
                    |di: usize, dj: usize| DVec2::new(2.5 + (i + di) as f64, 2.5 + (j + dj) as f64);
                let (a, b, c, d) = (p(0, 0), p(1, 0), p(0, 1), p(1, 1));
                if (i + j) % 2 == 0 {
                    tris.extend([[a, b, d], [a, d, c]]);
                } else {
                    tris.extend([[a, c, b], [b, c, d]]); // other diagonal, other winding
                }
            }
        }
        let count = coverage(&tris, 16, 16);
        for r in 0..16 {
            for c in 0..16 {
                // The half-open square [2.5, 12.5) covers centres 2..=11 of
                // each axis: top-left rule, like a pixel's own extent.
                let inside = (2..12).contains(&c) && (2..12).contains(&r);
                assert_eq!(count[c + 16 * r], u32::from(inside), "pixel {c},{r}");
            }
        }
    }

    #[test]
    fn a_fan_around_a_pixel_centre_covers_it_once() {
        // 7 triangles around the centre of pixel (5, 5) at odd angles, and
        // 8 around (12, 5) along the axes and diagonals.
        for (centre, n, phase) in [
            (DVec2::new(5.5, 5.5), 7, 0.3),
            (DVec2::new(12.5, 5.5), 8, 0.0),
        ] {
            let ring: Vec<DVec2> = (0..n)
                .map(|k| {
                    let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
                    centre + 3.0 * DVec2::new(a.cos(), a.sin())
                })
                .collect();
            let tris: Vec<_> = (0..n)
                .map(|k| [centre, ring[k], ring[(k + 1) % n]])
                .collect();
            let count = coverage(&tris, 18, 12);
            assert!(count.iter().all(|&c| c <= 1));
            assert_eq!(count[centre.x as usize + 18 * centre.y as usize], 1);
        }
    }

    #[test]
    fn random_meshes_have_no_gaps_or_overlaps() {
        // A jittered grid of vertices triangulated: every pixel centre in
        // the interior of the mesh is covered exactly once, whatever the
        // rounding of the edge functions.
        let mut seed = 12345u64;
        let mut random = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = 9;
        let mut grid = vec![DVec2::ZERO; n * n];
        for j in 0..n {
            for i in 0..n {
                let jitter = if i == 0 || j == 0 || i == n - 1 || j == n - 1 {
                    DVec2::ZERO
                } else {
                    DVec2::new(random() - 0.5, random() - 0.5) * 1.6
                };
                grid[i + n * j] = DVec2::new(4.0 * i as f64, 4.0 * j as f64) + jitter + 0.25;
            }
        }
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let v = |di: usize, dj: usize| grid[i + di + n * (j + dj)];
                tris.extend([[v(0, 0), v(1, 0), v(1, 1)], [v(0, 0), v(1, 1), v(0, 1)]]);
            }
        }
        let count = coverage(&tris, 40, 40);
        let edge = 0.25 + 4.0 * (n - 1) as f64;
        for r in 0..40 {
            for c in 0..40 {
                let (x, y) = (c as f64 + 0.5, r as f64 + 0.5);
                let inside = x > 0.25 && y > 0.25 && x < edge && y < edge;
                assert_eq!(count[c + 40 * r], u32::from(inside), "pixel {c},{r}");
            }
        }
    }

    #[test]
    fn barycentrics_reproduce_a_linear_function() {
        let t = [
            DVec2::new(1.2, 0.7),
            DVec2::new(9.3, 3.1),
            DVec2::new(4.4, 8.8),
        ];
        let f = |p: DVec2| 3.0 * p.x - 2.0 * p.y + 0.5;
        let mut hits = 0;
        cover(t, 12, 0..12, |c, r, w| {
            hits += 1;
            let p = DVec2::new(c as f64 + 0.5, r as f64 + 0.5);
            let interpolated = w[0] * f(t[0]) + w[1] * f(t[1]) + w[2] * f(t[2]);
            assert!((interpolated - f(p)).abs() < 1e-12);
            assert!(w.iter().all(|&x| (0.0..=1.0).contains(&x)));
        });
        // Area (shoelace) 31.59 pixels; the centres inside number about that.
        assert!((25..=38).contains(&hits), "{hits}");
    }

    #[test]
    fn the_nearer_triangle_wins_whatever_the_order() {
        let square = |depth: f64, n: DVec3| {
            let [a, b, c, d] =
                [(1.0, 1.0), (9.0, 1.0), (9.0, 9.0), (1.0, 9.0)].map(|(x, y)| DVec2::new(x, y));
            [
                ScreenTriangle {
                    corners: [a, b, c],
                    depth: [depth; 3],
                    normals: [n; 3],
                },
                ScreenTriangle {
                    corners: [a, c, d],
                    depth: [depth; 3],
                    normals: [n; 3],
                },
            ]
        };
        let near = square(-1.0, DVec3::X);
        let far = square(2.0, DVec3::Y);
        for list in [[near, far].concat(), [far, near].concat()] {
            let z = ZBuffer::draw(&list, 10, 40);
            assert_eq!(z.depth(5, 5), -1.0);
            assert_eq!(z.normal(5, 5), Vec3::X);
            assert_eq!(z.depth(0, 0), f64::INFINITY);
            assert_eq!(z.depth(5, 30), f64::INFINITY);
        }
        // Intersecting planes: depth x − 5 against 0: each wins its half.
        let tilted = ScreenTriangle {
            corners: [
                DVec2::new(0.0, 0.0),
                DVec2::new(10.0, 0.0),
                DVec2::new(0.0, 30.0),
            ],
            depth: [-5.0, 5.0, -5.0],
            normals: [DVec3::Z; 3],
        };
        let flat = ScreenTriangle {
            corners: [
                DVec2::new(0.0, 0.0),
                DVec2::new(10.0, 0.0),
                DVec2::new(0.0, 30.0),
            ],
            depth: [0.0; 3],
            normals: [DVec3::Y; 3],
        };
        let z = ZBuffer::draw(&[tilted, flat], 10, 40);
        assert!((z.depth(2, 1) + 2.5).abs() < 1e-12);
        assert_eq!(z.normal(2, 1), Vec3::Z);
        assert_eq!(z.depth(7, 1), 0.0);
        assert_eq!(z.normal(7, 1), Vec3::Y);
    }

    #[test]
    fn bands_do_not_change_the_picture() {
        // A triangle spanning several bands draws the same as one drawn
        // pixel by pixel with `cover`.
        let t = ScreenTriangle {
            corners: [
                DVec2::new(-3.0, 2.2),
                DVec2::new(30.5, 14.0),
                DVec2::new(6.0, 61.7),
            ],
            depth: [1.0, 2.0, 3.0],
            normals: [DVec3::X, DVec3::Y, DVec3::Z],
        };
        let z = ZBuffer::draw(&[t], 24, 50);
        let mut expect = vec![f64::INFINITY; 24 * 50];
        cover(t.corners, 24, 0..50, |c, r, w| {
            expect[c + 24 * r] = w[0] + 2.0 * w[1] + 3.0 * w[2];
        });
        for r in 0..50 {
            for c in 0..24 {
                assert_eq!(z.depth(c, r), expect[c + 24 * r]);
            }
        }
        assert!(expect.iter().filter(|d| d.is_finite()).count() > 300);
    }
}
