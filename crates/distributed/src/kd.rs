//! The k-d decomposition of a grid of voxels among any number of ranks (not only powers of two).
//!
//! Each split cuts the longest axis of the current box, giving each side a share of the
//! voxels proportional to its share of the ranks (`floor(n / 2)` ranks on the low side), so
//! that every rank receives about `voxels / N` voxels. The boxes are half-open voxel ranges
//! that tile the grid exactly once.

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
}

/// Splits `dims` among `ranks` ranks; box `r` belongs to rank `r`.
///
/// An axis is never cut below one voxel per side: with more ranks than voxels along the
/// longest axis, some boxes are empty (zero voxels), which the caller renders as nothing.
/// `ranks` must be at least 1.
pub fn split(dims: [usize; 3], ranks: usize) -> Vec<VoxelBox> {
    assert!(ranks >= 1, "a decomposition needs at least one rank");
    let mut out = Vec::with_capacity(ranks);
    split_into(
        VoxelBox {
            lo: [0; 3],
            hi: dims,
        },
        ranks,
        &mut out,
    );
    out
}

fn split_into(b: VoxelBox, ranks: usize, out: &mut Vec<VoxelBox>) {
    if ranks == 1 {
        out.push(b);
        return;
    }
    let ext = |a: usize| b.hi[a] - b.lo[a];
    let axis = (0..3)
        .max_by_key(|&a| (ext(a), std::cmp::Reverse(a)))
        .unwrap_or(0);
    let low_ranks = ranks / 2;
    // Proportional cut, rounded to the nearest voxel.
    let cut = b.lo[axis] + (ext(axis) * low_ranks + ranks / 2) / ranks;
    let (mut low, mut high) = (b, b);
    low.hi[axis] = cut;
    high.lo[axis] = cut;
    split_into(low, low_ranks, out);
    split_into(high, ranks - low_ranks, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_tiles(dims: [usize; 3], ranks: usize) {
        let boxes = split(dims, ranks);
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
        }
    }

    #[test]
    fn three_ranks_split_the_longest_axis_one_third_to_two_thirds() {
        let boxes = split([30, 10, 10], 3);
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
}
