//! The k-d decomposition of a grid of voxels among any number of ranks
//! (not only powers of two), and the visibility order of its boxes.
//!
//! Each split cuts the longest axis of the current box, giving each side a
//! share of the voxels proportional to its share of the ranks (`⌊n/2⌋`
//! ranks on the low side), so that every rank receives about `voxels / N`
//! voxels. The boxes are half-open voxel ranges that tile the grid exactly
//! once, numbered in the tree's order (low before high). Halving the rank
//! count at every split puts every leaf at depth `⌊log₂ N⌋` or
//! `⌈log₂ N⌉`, which the compositor's fold relies on
//! ([`crate::schedule`]).

use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;

/// A half-open box of voxel indices, `lo[a] <= i < hi[a]` on each axis `a`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VoxelBox {
    /// The first voxel on each axis.
    pub lo: [usize; 3],
    /// One past the last voxel on each axis.
    pub hi: [usize; 3],
}

impl VoxelBox {
    /// The number of voxels in the box.
    pub fn voxels(&self) -> usize {
        (0..3).map(|a| self.hi[a] - self.lo[a]).product()
    }

    /// Whether the box holds no voxel (more ranks than voxels to share).
    pub fn is_empty(&self) -> bool {
        self.voxels() == 0
    }
}

/// A node of the k-d tree.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    /// Rank `rank`'s box.
    Leaf { rank: usize },
    /// The box cut at voxel `cut` on `axis`: `low` holds `i < cut`, `high`
    /// holds `i ≥ cut`.
    Split {
        axis: usize,
        cut: usize,
        low: Box<Node>,
        high: Box<Node>,
    },
}

/// Where the rays come from: what decides which side of a cut is in front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Viewpoint {
    /// Parallel rays travelling along this world direction (orthographic).
    Direction(DVec3),
    /// Rays from this world point (perspective).
    Eye(DVec3),
}

impl Viewpoint {
    /// Where the rays of a framed view come from.
    pub fn of(view: &volray_core::camera::View) -> Self {
        match view {
            volray_core::camera::View::Orthographic(v) => Viewpoint::Direction(v.direction),
            volray_core::camera::View::Perspective(v) => Viewpoint::Eye(v.eye),
        }
    }

    /// Whether the low side of the world plane `p[axis] = at` is in front.
    /// Where it does not matter (rays parallel to the plane, or an eye on
    /// it, whose rays each stay on one side), the low side.
    pub fn low_in_front(&self, axis: usize, at: f64) -> bool {
        match *self {
            Viewpoint::Direction(d) => d[axis] >= 0.0,
            Viewpoint::Eye(e) => e[axis] <= at,
        }
    }
}

/// A grid split among ranks: the tree and each rank's box.
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition {
    pub dims: [usize; 3],
    pub root: Node,
    /// Box `r` belongs to rank `r`.
    pub boxes: Vec<VoxelBox>,
}

impl Decomposition {
    /// Splits `dims` among `ranks` ranks (at least 1).
    ///
    /// An axis is never cut below one voxel per side while it has two: with
    /// more ranks than voxels along the longest axis some boxes are empty,
    /// which their ranks render as nothing.
    pub fn new(dims: [usize; 3], ranks: usize) -> Self {
        assert!(ranks >= 1, "a decomposition needs at least one rank");
        let mut boxes = Vec::with_capacity(ranks);
        let whole = VoxelBox {
            lo: [0; 3],
            hi: dims,
        };
        let root = split_into(whole, ranks, &mut boxes);
        Decomposition { dims, root, boxes }
    }

    /// The ranks in visibility order for `view` (front first), each cut's
    /// world plane placed by `grid`.
    pub fn front_to_back(&self, view: &Viewpoint, grid: &GridFrame) -> Vec<usize> {
        let mut order = Vec::with_capacity(self.boxes.len());
        visit(&self.root, view, grid, &mut order);
        order
    }
}

/// The world coordinate of voxel plane `i` on `axis`.
pub fn plane(grid: &GridFrame, axis: usize, i: usize) -> f64 {
    grid.origin[axis] + i as f64 * grid.spacing[axis]
}

fn visit(node: &Node, view: &Viewpoint, grid: &GridFrame, order: &mut Vec<usize>) {
    match node {
        Node::Leaf { rank } => order.push(*rank),
        Node::Split {
            axis,
            cut,
            low,
            high,
        } => {
            let (first, second) = if view.low_in_front(*axis, plane(grid, *axis, *cut)) {
                (low, high)
            } else {
                (high, low)
            };
            visit(first, view, grid, order);
            visit(second, view, grid, order);
        }
    }
}

fn split_into(b: VoxelBox, ranks: usize, out: &mut Vec<VoxelBox>) -> Node {
    if ranks == 1 {
        out.push(b);
        return Node::Leaf {
            rank: out.len() - 1,
        };
    }
    let ext = |a: usize| b.hi[a] - b.lo[a];
    // Ties go to the slowest axis (z, then y): a cut across z leaves each
    // side a contiguous run of the file (x fastest), so that a rank
    // mapping it touches only its own pages. A cut across x touches every
    // page of rows shorter than a page (1024 f32): at 4 ranks of a 257³
    // f32 file (68 MB), each rank's resident file pages (the binary's
    // own included) fell from 62 to 39 MB.
    let axis = (0..3).max_by_key(|&a| (ext(a), a)).unwrap_or(0);
    let low_ranks = ranks / 2;
    // Proportional cut, rounded to the nearest voxel.
    let cut = b.lo[axis] + (ext(axis) * low_ranks + ranks / 2) / ranks;
    let (mut low, mut high) = (b, b);
    low.hi[axis] = cut;
    high.lo[axis] = cut;
    let low = Box::new(split_into(low, low_ranks, out));
    let high = Box::new(split_into(high, ranks - low_ranks, out));
    Node::Split {
        axis,
        cut,
        low,
        high,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_tiles(dims: [usize; 3], ranks: usize) {
        let boxes = Decomposition::new(dims, ranks).boxes;
        assert_eq!(boxes.len(), ranks);
        let mut count = vec![0u8; dims.iter().product()];
        for b in &boxes {
            for z in b.lo[2]..b.hi[2] {
                for y in b.lo[1]..b.hi[1] {
                    for x in b.lo[0]..b.hi[0] {
                        count[(z * dims[1] + y) * dims[0] + x] += 1;
                    }
                }
            }
        }
        assert!(
            count.iter().all(|&c| c == 1),
            "{dims:?} among {ranks} must tile once"
        );
    }

    #[test]
    fn boxes_tile_the_grid_exactly_once_for_any_rank_count() {
        for ranks in 1..=9 {
            check_tiles([17, 12, 9], ranks);
            check_tiles([3, 40, 5], ranks);
            check_tiles([2, 2, 2], ranks);
        }
    }

    #[test]
    fn three_ranks_split_the_longest_axis_one_third_to_two_thirds() {
        let boxes = Decomposition::new([30, 10, 10], 3).boxes;
        assert_eq!(
            boxes[0],
            VoxelBox {
                lo: [0; 3],
                hi: [10, 10, 10]
            }
        );
        assert_eq!(boxes[1].voxels(), 1000);
        assert_eq!(boxes[2].voxels(), 1000);
    }

    #[test]
    fn the_visibility_order_follows_the_view_through_every_cut() {
        let grid = GridFrame {
            dims: [40, 30, 10],
            origin: DVec3::ZERO,
            spacing: DVec3::ONE,
        };
        let d = Decomposition::new(grid.dims, 4);
        // Cut at x = 20, then each half at y = 15.
        assert_eq!(d.boxes[1].lo, [0, 15, 0]);
        assert_eq!(d.boxes[2].lo, [20, 0, 0]);
        let along = |v: DVec3| d.front_to_back(&Viewpoint::Direction(v), &grid);
        assert_eq!(along(DVec3::new(1.0, 0.5, 0.0)), vec![0, 1, 2, 3]);
        assert_eq!(along(DVec3::new(-1.0, 0.5, 0.0)), vec![2, 3, 0, 1]);
        assert_eq!(along(DVec3::new(-1.0, -0.5, 0.0)), vec![3, 2, 1, 0]);
        // An eye in box 3 (x ≥ 20, y ≥ 15): its own box first, then its
        // neighbour across y, then the far half, nearer y first.
        let eye = Viewpoint::Eye(DVec3::new(30.0, 20.0, 5.0));
        assert_eq!(d.front_to_back(&eye, &grid), vec![3, 2, 1, 0]);
        let eye = Viewpoint::Eye(DVec3::new(10.0, 2.0, 5.0));
        assert_eq!(d.front_to_back(&eye, &grid), vec![0, 1, 2, 3]);
    }
}
