//! Per frame: which occupied bricks each image tile's rays may cross, in
//! front-to-back order, for orthographic and perspective views.
//!
//! A brick (the box of its occupied cells, see
//! [`ClassifiedBricks::occupied_box`]) can only be crossed by the rays whose
//! pixel centres lie inside its projection, so each occupied brick is
//! projected once and listed in every tile its screen bounding box touches.
//! The ray caster then walks only its tile's list instead of stepping
//! through every brick along the ray, so empty space costs nothing at all,
//! and neighbouring rays share one list.
//!
//! **Projection.** Orthographic: the eight corners of the box, projected
//! along the rays. Perspective: the part of the box in front of the eye,
//! projected from the eye. A box that reaches to or behind the plane of the
//! eye projects to an unbounded region, so it is first cut by a plane a
//! little in front of the eye, at the depth `ε` below which every point of
//! the box projects outside the image (see `perspective_bounds`); the
//! projection of the cut box (a convex polytope) is the convex hull of its
//! vertices' projections, which is bounded. A box holding the eye is
//! listed in every tile: every ray starts inside it.
//!
//! **Order.** Orthographic: bricks are listed by the depth of their centre
//! along the index-space ray direction `D`. Along any one ray this is the
//! order in which the ray meets its bricks: a ray passes from a brick to a
//! face neighbour one brick further along some axis `a` in the direction of
//! `D_a`, and that neighbour's centre is deeper by `8·|D_a| > 0`.
//! Perspective: by the world distance from the eye to the centre of the
//! brick's full 8³-cell box (its site). The bricks of the grid are the
//! Voronoi cells of these sites (a rectangular lattice: each cell is the box
//! about its site), and a ray from the eye that passes from cell `A` into
//! cell `B` crosses their bisector plane from `A`'s side once, so the eye is
//! on `A`'s side: `A`'s site is nearer. Sorting by that distance is
//! therefore the order in which every ray from the eye meets the cells
//! (Edelsbrunner, "An acyclicity theorem for cell complexes in d
//! dimensions", *Combinatorica* 10, 1990, for Voronoi diagrams in general;
//! Max, Hanrahan & Crawfis, "Area and volume coherence for efficient
//! visualization of 3D scalar functions", 1990, sort cells for perspective
//! this way). The last brick along an axis may be cut short by the volume:
//! it lies inside its full box, so the order holds for it too. Bricks in a
//! list that a ray misses are rejected by the ray's own box test, and
//! samples behind the eye by its range (`t ≥ 0`).
//!
//! Bricks wholly outside the crop box or wholly behind a clip plane are
//! left out: no sample of theirs is taken.

use crate::bricks::BRICK;
use crate::bricks::occupied::ClassifiedBricks;
use crate::camera::PerspectiveView;
use crate::camera::{OrthographicView, View};
use crate::sampling::Sampling;
use crate::sampling::grid::GridFrame;
use glam::DVec3;

/// Bytes one occupied brick takes while a frame is binned, beside its
/// entries in the tiles' lists ([`BYTES_PER_ENTRY`] each): its depth and
/// its tile rectangle.
pub(crate) const BYTES_PER_OCCUPIED_BRICK: usize =
    size_of::<(f64, u32)>() + size_of::<Option<[u16; 4]>>();
/// Bytes of one brick's entry in one tile's list.
pub(crate) const BYTES_PER_ENTRY: usize = size_of::<u32>();
/// Bytes per tile: its list's start, and its count while binning.
pub(crate) const BYTES_PER_TILE: usize = 2 * size_of::<u32>();

/// Tile edge in pixels.
pub const TILE: usize = 16;

// Tile numbers are kept as `u16`.
const _: () = assert!(crate::settings::MAX_IMAGE_SIDE / TILE <= u16::MAX as usize);

/// Slack, in pixels, around each brick's projected box: pixel centres on
/// its edge are listed whatever the rounding.
const SLACK: f64 = 1e-3;

/// Slack, in steps, around each box before a perspective projection (on
/// top of [`SLACK`]): the ray caster takes a sample up to a thousandth of a
/// step outside a box as inside it (clamped onto its face).
const STEP_SLACK: f64 = 1e-2;

/// The occupied bricks per tile, tiles in row-major order.
#[derive(Debug, Clone, PartialEq)]
pub struct TileBins {
    pub tiles_x: usize,
    pub tiles_y: usize,
    /// Tile `t`'s bricks are `entries[start[t]..start[t + 1]]`.
    start: Vec<u32>,
    /// Occupied-brick numbers (see [`ClassifiedBricks::occupied`]).
    entries: Vec<u32>,
}

impl TileBins {
    /// Bins the occupied bricks of `bricks` for `view`, leaving out those
    /// whose samples `sampling` cuts away.
    pub fn new(bricks: &ClassifiedBricks, sampling: &Sampling, view: &View) -> Self {
        Self::of_boxes(
            bricks.len(),
            |n| bricks.brick(n),
            |n| bricks.occupied_box(n),
            sampling,
            view,
        )
    }

    /// Bins `count` bricks, brick `n` being brick `brick(n)` of the grid
    /// and its samples lying in the index-space box `cells(n)` (within
    /// the brick's), for `view`, leaving out those whose samples
    /// `sampling` cuts away; the lists hold the numbers `n`.
    pub fn of_boxes(
        count: usize,
        brick: impl Fn(usize) -> [usize; 3],
        cells: impl Fn(usize) -> ([usize; 3], [usize; 3]),
        sampling: &Sampling,
        view: &View,
    ) -> Self {
        let grid = &sampling.grid;
        let tiles_x = view.width().div_ceil(TILE);
        let tiles_y = view.height().div_ceil(TILE);
        let mut order: Vec<(f64, u32)> = match view {
            View::Orthographic(v) => {
                let direction = v.direction / grid.spacing;
                (0..count)
                    .map(|n| (site(brick(n)).dot(direction), n as u32))
                    .collect()
            }
            View::Perspective(v) => (0..count)
                .map(|n| {
                    let world = grid.origin + site(brick(n)) * grid.spacing;
                    (world.distance_squared(v.eye), n as u32)
                })
                .collect(),
        };
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));

        // Each brick's tile rectangle, then a counting sort into the tiles.
        let clipping = &sampling.clipping;
        let world = |i: [usize; 3]| {
            grid.origin + DVec3::new(i[0] as f64, i[1] as f64, i[2] as f64) * grid.spacing
        };
        let kept = |(lo, hi): ([usize; 3], [usize; 3])| {
            // The box in world space, a step larger all round: a sample a
            // rounding error outside the kept part still counts as inside.
            let margin = DVec3::splat(sampling.step);
            clipping.may_keep_box((world(lo) - margin, world(hi) + margin))
        };
        let margin = DVec3::splat(STEP_SLACK * sampling.step + 1e-3 * grid.spacing.max_element());
        let rects: Vec<Option<[u16; 4]>> = order
            .iter()
            .map(|&(_, n)| {
                let cells = cells(n as usize);
                if clipping.is_active() && !kept(cells) {
                    return None;
                }
                let bounds = match view {
                    View::Orthographic(v) => Some(orthographic_bounds(cells, grid, v)),
                    View::Perspective(v) => {
                        perspective_bounds((world(cells.0) - margin, world(cells.1) + margin), v)
                    }
                };
                tile_rect(bounds?, view.width(), view.height())
            })
            .collect();
        let mut count = vec![0u32; tiles_x * tiles_y + 1];
        for &[x0, x1, y0, y1] in rects.iter().flatten() {
            let [x0, x1, y0, y1] = [x0, x1, y0, y1].map(usize::from);
            for ty in y0..=y1 {
                for tx in x0..=x1 {
                    count[ty * tiles_x + tx + 1] += 1;
                }
            }
        }
        for t in 1..count.len() {
            count[t] += count[t - 1];
        }
        let start = count.clone();
        let mut entries = vec![0u32; *count.last().unwrap_or(&0) as usize];
        for (&(_, n), rect) in order.iter().zip(&rects) {
            if let Some(rect) = *rect {
                let [x0, x1, y0, y1] = rect.map(usize::from);
                for ty in y0..=y1 {
                    for tx in x0..=x1 {
                        let t = ty * tiles_x + tx;
                        entries[count[t] as usize] = n;
                        count[t] += 1;
                    }
                }
            }
        }
        TileBins {
            tiles_x,
            tiles_y,
            start,
            entries,
        }
    }

    /// The bricks of tile (`tx`, `ty`), front to back.
    #[inline]
    pub fn list(&self, tx: usize, ty: usize) -> &[u32] {
        let t = ty * self.tiles_x + tx;
        &self.entries[self.start[t] as usize..self.start[t + 1] as usize]
    }

    /// Every tile's list, one after the other: each occupied brick once
    /// per tile that lists it.
    pub fn entries(&self) -> &[u32] {
        &self.entries
    }

    /// Entries in all lists.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.entries.len()
    }
}

/// Index-space centre of brick `b`'s full box of 8³ cells (its site in the
/// lattice of bricks, even where the volume cuts the brick short).
fn site(b: [usize; 3]) -> DVec3 {
    DVec3::new(b[0] as f64, b[1] as f64, b[2] as f64) * BRICK as f64
        + DVec3::splat(BRICK as f64 / 2.0)
}

/// The corners of the box `(lo, hi)`, corner `c` taking `hi` on the axes
/// whose bit is set.
fn corner(lo: DVec3, hi: DVec3, c: usize) -> DVec3 {
    DVec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo)
}

/// The bounds `[c0, c1, r0, r1]`, in continuous image coordinates, of the
/// orthographic projection of the index-space box `(lo, hi)`.
fn orthographic_bounds(
    (lo, hi): ([usize; 3], [usize; 3]),
    grid: &GridFrame,
    view: &OrthographicView,
) -> [f64; 4] {
    let to_f64 = |i: [usize; 3]| DVec3::new(i[0] as f64, i[1] as f64, i[2] as f64);
    let (lo, hi) = (to_f64(lo), to_f64(hi));
    let mut bounds = [f64::MAX, f64::MIN, f64::MAX, f64::MIN];
    for c in 0..8 {
        let (col, row) = view.project(grid.origin + corner(lo, hi, c) * grid.spacing);
        extend(&mut bounds, col, row);
    }
    bounds
}

/// The bounds `[c0, c1, r0, r1]`, in continuous image coordinates, of the
/// part of the world box `(lo, hi)` that a ray from the eye through a pixel
/// centre can reach in front of the eye; `None` if no such ray reaches it.
/// Infinite bounds (every pixel) for a box holding the eye.
///
/// A point of the box at distance `ρ ≥ r` from the eye (`r` the box's
/// distance) and depth `z` along the view direction projects
/// `√(ρ² − z²)/z` from the image centre on the plane one unit in front of
/// the eye; every pixel centre lies within `R` of it. Below the depth
/// `ε = r / (2·√(1 + R²))` that ratio exceeds `√3·√(1 + R²) > R`: no
/// pixel's ray meets the box there. The box is cut at depth `ε` (keeping
/// the corners at least that deep and the points where its twelve edges
/// cross that depth) and those vertices are projected.
fn perspective_bounds((lo, hi): (DVec3, DVec3), view: &PerspectiveView) -> Option<[f64; 4]> {
    let eye = view.eye;
    let r = eye.clamp(lo, hi).distance(eye);
    if r == 0.0 {
        let inf = f64::INFINITY;
        return Some([-inf, inf, -inf, inf]);
    }
    let reach = 0.5 * view.pixel_size * (view.width as f64).hypot(view.height as f64);
    let near = 0.5 * r / (1.0 + reach * reach).sqrt();
    let (half_w, half_h) = (0.5 * view.width as f64, 0.5 * view.height as f64);
    let mut bounds = [f64::MAX, f64::MIN, f64::MAX, f64::MIN];
    let mut add = |q: DVec3, depth: f64| {
        // As PerspectiveView::project, `q` relative to the eye.
        let col = q.dot(view.right) / depth / view.pixel_size + half_w;
        let row = -q.dot(view.up) / depth / view.pixel_size + half_h;
        extend(&mut bounds, col, row);
    };
    let at = |c: usize| corner(lo, hi, c) - eye;
    let depth = |q: DVec3| q.dot(view.direction);
    let mut any = false;
    for c in 0..8 {
        let q = at(c);
        if depth(q) >= near {
            add(q, depth(q));
            any = true;
        }
    }
    // The edges from corner c to the corner one bit higher along axis a.
    for a in 0..3 {
        for c in (0..8).filter(|c| c >> a & 1 == 0) {
            let (p, q) = (at(c), at(c | 1 << a));
            let (zp, zq) = (depth(p), depth(q));
            if (zp < near) != (zq < near) {
                let s = (near - zp) / (zq - zp);
                add(p + s * (q - p), near);
            }
        }
    }
    any.then_some(bounds)
}

fn extend(bounds: &mut [f64; 4], col: f64, row: f64) {
    bounds[0] = bounds[0].min(col);
    bounds[1] = bounds[1].max(col);
    bounds[2] = bounds[2].min(row);
    bounds[3] = bounds[3].max(row);
}

/// The tiles `[x0, x1] × [y0, y1]` holding a pixel centre inside the
/// image-coordinate bounds `[c0, c1, r0, r1]` of a `width × height` image,
/// or `None` if none does. (Tile numbers fit `u16`: an image side is at
/// most [`MAX_IMAGE_SIDE`](crate::MAX_IMAGE_SIDE) pixels.)
fn tile_rect([c0, c1, r0, r1]: [f64; 4], width: usize, height: usize) -> Option<[u16; 4]> {
    // Pixel (c, r) has its centre at (c + 0.5, r + 0.5).
    let first = |x: f64| (x - 0.5 - SLACK).ceil().max(0.0);
    let last = |x: f64, n: usize| (x - 0.5 + SLACK).floor().min(n as f64 - 1.0);
    let (x0, x1) = (first(c0), last(c1, width));
    let (y0, y1) = (first(r0), last(r1, height));
    (x0 <= x1 && y0 <= y1).then_some([x0, x1, y0, y1].map(|p| (p as usize / TILE) as u16))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bricks::macrocells::Macrocells;
    use crate::bricks::occupied::{ClassifiedBricks, Source};
    use crate::camera::Camera;
    use crate::sampling::clipping::Clipping;
    use crate::transfer::classifier::{Classifier, OpacityMap};
    use crate::volume::Volume;

    #[test]
    fn bricks_land_in_the_tiles_they_cover_front_to_back() {
        // Everything visible on a 33³ grid: 4³ bricks. Viewed along −x (the
        // default) onto 64 × 64 pixels, each brick covers 16 × 16 pixels, one
        // tile; the four bricks along x share it, nearest (largest x) first.
        let v = Volume::new([33, 33, 33], vec![1.0; 33 * 33 * 33]).unwrap();
        let c = Classifier::new((0.0, 1.0), OpacityMap::Ramp { p: 0.1, q: 0.5 }, None, 1.0);
        let source = Source {
            volume: &v,
            classifier: &c,
            masked: &|_| false,
        };
        let bricks = ClassifiedBricks::new(&source, &Macrocells::new(&v), usize::MAX);
        assert_eq!(bricks.len(), 64);
        let sampling = Sampling {
            grid: GridFrame {
                dims: v.dims(),
                origin: v.origin(),
                spacing: v.spacing(),
            },
            step: 1.0,
            clipping: Clipping::default(),
            jitter: false,
            from_eye: false,
            ownership: None,
        };
        let view = View::frame(&Camera::default(), v.bounds(), 64, 64).unwrap();
        let bins = TileBins::new(&bricks, &sampling, &view);
        assert_eq!((bins.tiles_x, bins.tiles_y), (4, 4));
        // Brick faces fall exactly between pixels 15 and 16: no brick leaks
        // into a neighbouring tile.
        assert_eq!(bins.len(), 64);
        // Screen right is +y, up is +z: tile (1, 0) shows y in [8, 16] and
        // z in [24, 32], brick y = 1, z = 3.
        let xs: Vec<usize> = bins
            .list(1, 0)
            .iter()
            .map(|&n| bricks.brick(n as usize))
            .inspect(|b| assert_eq!((b[1], b[2]), (1, 3)))
            .map(|b| b[0])
            .collect();
        assert_eq!(xs, vec![3, 2, 1, 0]);

        // Cropped to x ≤ 10, the bricks from x = 16 on hold no sample (with
        // a step of margin, the brick [8, 16] still may): they are left out.
        let cropped = Sampling {
            clipping: Clipping {
                crop: Some((DVec3::splat(-1.0), DVec3::new(10.0, 40.0, 40.0))),
                planes: vec![],
            },
            ..sampling
        };
        let bins = TileBins::new(&bricks, &cropped, &view);
        assert_eq!(bins.len(), 32);
        let xs: Vec<usize> = (bins.list(2, 3).iter())
            .map(|&n| bricks.brick(n as usize)[0])
            .collect();
        assert_eq!(xs, vec![1, 0]);
    }

    /// Where the world ray `o + t·d`, `t ≥ t_min`, is inside the world box
    /// `(lo, hi)`: `(t_enter, t_exit)`, or `None` if it is inside for less
    /// than `1e-6` (a graze, which either list may hold or not).
    fn crossing(o: DVec3, d: DVec3, (lo, hi): (DVec3, DVec3), t_min: f64) -> Option<(f64, f64)> {
        let (mut enter, mut exit) = (t_min, f64::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < lo[a] || o[a] > hi[a] {
                    return None;
                }
            } else {
                let (s, t) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
                enter = enter.max(s.min(t));
                exit = exit.min(s.max(t));
            }
        }
        (exit - enter > 1e-6).then_some((enter, exit))
    }

    #[test]
    fn every_ray_finds_the_bricks_it_crosses_in_its_list_in_the_order_it_meets_them() {
        // Scattered voxels with a threshold: about half the bricks occupied,
        // their boxes of occupied cells of every size. For every pixel ray
        // of several views (perspective with the eye outside, near, inside
        // and on a brick corner; orthographic), the bricks whose box the
        // ray passes through (ahead of the eye, in perspective) must all be
        // in its tile's list, and the list must hold them in the order the
        // ray enters them.
        let dims = [41, 35, 27];
        let spacing = DVec3::new(0.7, 1.0, 1.3);
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let data: Vec<f32> = (0..dims.iter().product())
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                if seed.is_multiple_of(97) { 1.0 } else { 0.0 }
            })
            .collect();
        let v = Volume::new(dims, data)
            .unwrap()
            .with_spacing(spacing)
            .unwrap()
            .with_origin(DVec3::new(-3.0, 2.0, 1.0))
            .unwrap();
        let c = Classifier::new((0.0, 1.0), OpacityMap::Ramp { p: 0.0, q: 0.5 }, None, 1.0);
        let source = Source {
            volume: &v,
            classifier: &c,
            masked: &|_| false,
        };
        let bricks = ClassifiedBricks::new(&source, &Macrocells::new(&v), usize::MAX);
        let all = bricks.grid.len();
        assert!(
            bricks.len() > all / 4 && bricks.len() < all,
            "{} of {all}",
            bricks.len()
        );
        let grid = GridFrame {
            dims,
            origin: v.origin(),
            spacing,
        };
        let world = |i: [usize; 3]| {
            grid.origin + DVec3::new(i[0] as f64, i[1] as f64, i[2] as f64) * spacing
        };
        let (lo, hi) = v.bounds();
        let centre = 0.5 * (lo + hi);
        let perspective = |eye: DVec3, at: DVec3, fov_degrees: f64| Camera {
            view_point: Some(eye),
            look_at: Some(at),
            projection: crate::camera::Projection::Perspective { fov_degrees },
            ..Camera::default()
        };
        let cameras = [
            perspective(centre + DVec3::new(60.0, -35.0, 25.0), centre, 40.0),
            perspective(hi + DVec3::splat(0.5), centre, 100.0),
            perspective(centre, centre + DVec3::new(-1.0, 0.3, 0.2), 90.0),
            perspective(world([8, 16, 8]), world([40, 0, 26]), 120.0),
            perspective(world([16, 5, 13]), world([0, 30, 13]), 60.0),
            Camera {
                view_point: Some(centre + DVec3::new(-20.0, 30.0, 45.0)),
                ..Camera::default()
            },
        ];
        for camera in cameras {
            let view = View::frame(&camera, v.bounds(), 45, 38).unwrap();
            let sampling = Sampling {
                grid,
                step: 0.5,
                clipping: Clipping::default(),
                jitter: false,
                from_eye: matches!(view, View::Perspective(_)),
                ownership: None,
            };
            let bins = TileBins::new(&bricks, &sampling, &view);
            let t_min = if sampling.from_eye {
                0.0
            } else {
                f64::NEG_INFINITY
            };
            let mut crossed = 0;
            for row in 0..view.height() {
                for col in 0..view.width() {
                    let (o, d) = view.pixel_ray(col, row);
                    let list = bins.list(col / TILE, row / TILE);
                    let mut last_entry = f64::NEG_INFINITY;
                    let mut listed = 0;
                    for &n in list {
                        let (a, b) = bricks.occupied_box(n as usize);
                        if let Some((enter, _)) = crossing(o, d, (world(a), world(b)), t_min) {
                            assert!(
                                enter >= last_entry - 1e-9,
                                "{camera:?} ({col}, {row}): brick {:?} entered at {enter} after one at {last_entry}",
                                bricks.brick(n as usize)
                            );
                            last_entry = enter;
                            listed += 1;
                        }
                    }
                    let crosses = (0..bricks.len())
                        .filter(|&n| {
                            let (a, b) = bricks.occupied_box(n);
                            crossing(o, d, (world(a), world(b)), t_min).is_some()
                        })
                        .count();
                    assert_eq!(listed, crosses, "{camera:?} ({col}, {row})");
                    crossed += crosses;
                }
            }
            assert!(crossed > 45 * 38, "{camera:?}: {crossed} crossings");
        }
    }
}
