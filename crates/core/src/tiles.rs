//! Per frame: which occupied bricks each image tile's rays may cross, in
//! front-to-back order.
//!
//! Rays are parallel (orthographic), so a brick can only be crossed by the
//! rays whose pixel centres lie inside its projection; each occupied brick
//! (the box of its occupied cells, see
//! [`ClassifiedBricks::occupied_box`]) is projected once and listed in
//! every tile its screen bounding box touches. The ray caster then walks only its tile's list instead of
//! stepping through every brick along the ray, so empty space costs nothing
//! at all, and neighbouring rays share one list.
//!
//! **Order.** Bricks are listed by the depth of their centre along the
//! index-space ray direction `D`. Along any one ray this is the order in
//! which the ray meets its bricks: a ray passes from a brick to a face
//! neighbour one brick further along some axis `a` in the direction of
//! `D_a`, and that neighbour's centre is deeper by `8·|D_a| > 0`. Bricks in
//! a list that a ray misses are rejected by the ray's own box test.
//!
//! Bricks wholly outside the crop box or wholly behind a clip plane are
//! left out: no sample of theirs is taken.

use crate::bricks::BRICK;
use crate::camera::OrthographicView;
use crate::classified::ClassifiedBricks;
use crate::ray::GridFrame;
use crate::sampling::Sampling;
use glam::DVec3;

/// Tile edge in pixels.
pub const TILE: usize = 16;

/// Slack, in pixels, around each brick's projected box: pixel centres on
/// its edge are listed whatever the rounding.
const SLACK: f64 = 1e-3;

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
    pub fn new(bricks: &ClassifiedBricks, sampling: &Sampling, view: &OrthographicView) -> Self {
        let grid = &sampling.grid;
        let tiles_x = view.width.div_ceil(TILE);
        let tiles_y = view.height.div_ceil(TILE);
        let direction = view.direction / grid.spacing;
        let centre = |b: [usize; 3]| {
            DVec3::new(b[0] as f64, b[1] as f64, b[2] as f64) * BRICK as f64
                + DVec3::splat(BRICK as f64 / 2.0)
        };
        let mut order: Vec<(f64, u32)> = bricks
            .occupied
            .iter()
            .enumerate()
            .map(|(n, &b)| (centre(b).dot(direction), n as u32))
            .collect();
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));

        // Each brick's tile rectangle, then a counting sort into the tiles.
        let clipping = &sampling.clipping;
        let kept = |(lo, hi): ([usize; 3], [usize; 3])| {
            // The box in world space, a step larger all round: a sample a
            // rounding error outside the kept part still counts as inside.
            let world = |i: [usize; 3]| {
                grid.origin + DVec3::new(i[0] as f64, i[1] as f64, i[2] as f64) * grid.spacing
            };
            let margin = DVec3::splat(sampling.step);
            clipping.may_keep_box((world(lo) - margin, world(hi) + margin))
        };
        let rects: Vec<Option<[usize; 4]>> = order
            .iter()
            .map(|&(_, n)| {
                let cells = bricks.occupied_box(n as usize);
                if clipping.is_active() && !kept(cells) {
                    return None;
                }
                tile_rect(cells, grid, view)
            })
            .collect();
        let mut count = vec![0u32; tiles_x * tiles_y + 1];
        for &[x0, x1, y0, y1] in rects.iter().flatten() {
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
            if let Some([x0, x1, y0, y1]) = *rect {
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

    /// Entries in all lists.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

/// The tiles `[x0, x1] × [y0, y1]` holding a pixel centre inside the
/// projection of the index-space box `(lo, hi)`, or `None` if it is off
/// screen.
fn tile_rect(
    (lo, hi): ([usize; 3], [usize; 3]),
    grid: &GridFrame,
    view: &OrthographicView,
) -> Option<[usize; 4]> {
    let (mut c0, mut c1, mut r0, mut r1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for corner in 0..8 {
        let pick = |a: usize| if corner >> a & 1 == 0 { lo[a] } else { hi[a] } as f64;
        let world = grid.origin + DVec3::new(pick(0), pick(1), pick(2)) * grid.spacing;
        let (c, r) = view.project(world);
        (c0, c1, r0, r1) = (c0.min(c), c1.max(c), r0.min(r), r1.max(r));
    }
    // Pixel (c, r) has its centre at (c + 0.5, r + 0.5).
    let first = |x: f64| (x - 0.5 - SLACK).ceil().max(0.0);
    let last = |x: f64, n: usize| (x - 0.5 + SLACK).floor().min(n as f64 - 1.0);
    let (x0, x1) = (first(c0), last(c1, view.width));
    let (y0, y1) = (first(r0), last(r1, view.height));
    (x0 <= x1 && y0 <= y1).then_some({
        [
            x0 as usize / TILE,
            x1 as usize / TILE,
            y0 as usize / TILE,
            y1 as usize / TILE,
        ]
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::classified::ClassifiedBricks;
    use crate::classify::{Classifier, OpacityMap};
    use crate::clipping::Clipping;
    use crate::macrocells::Macrocells;
    use crate::volume::Volume;

    #[test]
    fn bricks_land_in_the_tiles_they_cover_front_to_back() {
        // Everything visible on a 33³ grid: 4³ bricks. Viewed along −x (the
        // default) onto 64 × 64 pixels, each brick covers 16 × 16 pixels, one
        // tile; the four bricks along x share it, nearest (largest x) first.
        let v = Volume::new([33, 33, 33], vec![1.0; 33 * 33 * 33]).unwrap();
        let c = Classifier::new((0.0, 1.0), OpacityMap::Ramp { p: 0.1, q: 0.5 }, None, 1.0);
        let bricks = ClassifiedBricks::new(&v, &Macrocells::new(&v), &c);
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
        };
        let view = OrthographicView::frame(&Camera::default(), v.bounds(), 64, 64).unwrap();
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
            .map(|&n| bricks.occupied[n as usize])
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
            .map(|&n| bricks.occupied[n as usize][0])
            .collect();
        assert_eq!(xs, vec![1, 0]);
    }
}
