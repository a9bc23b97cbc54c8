//! Brick geometry for the fast path: the volume's cells grouped into
//! bricks of [`BRICK`]³ cells.
//!
//! A brick is the unit of empty-space skipping (a macro-cell) and of
//! storage. Brick `(bx, by, bz)` covers the cells whose lower corner is in
//! `[8bx, 8bx + 8) × …`, and stores the `9³` voxels at their corners: the
//! voxels on a face between two bricks are stored in both. The duplication
//! (`(9/8)³ ≈ 1.42` slots per voxel of an occupied brick) buys a simple
//! inner loop: the eight corners of any cell in a brick are in that brick,
//! at fixed offsets, so trilinear interpolation never looks across a brick
//! boundary. The last brick along an axis may hold fewer cells; its slots
//! beyond the volume repeat the last voxel, which no clamped sample can tell
//! apart from the voxel itself.

pub mod cache;
pub mod macrocells;
pub mod occupied;

/// Cells along each edge of a brick.
pub const BRICK: usize = 8;
/// Voxels along each edge of a brick (the cells' corners).
pub const SIDE: usize = BRICK + 1;
/// Voxel slots in a brick.
pub const SLOTS: usize = SIDE * SIDE * SIDE;
/// Cells in a brick.
pub const CELLS: usize = BRICK * BRICK * BRICK;

/// How a volume of `dims` voxels divides into bricks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BrickGrid {
    /// Voxels along x, y and z (each at least 2).
    pub dims: [usize; 3],
    /// Bricks along x, y and z.
    pub bricks: [usize; 3],
}

impl BrickGrid {
    pub fn new(dims: [usize; 3]) -> Self {
        BrickGrid {
            dims,
            bricks: dims.map(|n| (n - 1).div_ceil(BRICK)),
        }
    }

    /// Number of bricks.
    pub fn len(&self) -> usize {
        self.bricks.iter().product()
    }

    /// Linear index of brick `b`, x fastest.
    #[inline]
    pub fn index(&self, b: [usize; 3]) -> usize {
        b[0] + self.bricks[0] * (b[1] + self.bricks[1] * b[2])
    }

    /// Brick coordinates of linear index `i`.
    #[inline]
    pub fn coords(&self, i: usize) -> [usize; 3] {
        let [bx, by, _] = self.bricks;
        [i % bx, (i / bx) % by, i / (bx * by)]
    }

    /// Index-space position of the brick's first voxel.
    #[inline]
    pub fn origin(&self, b: [usize; 3]) -> [usize; 3] {
        b.map(|c| c * BRICK)
    }

    /// The brick's box in index space, clipped to the volume `[0, n − 1]³`.
    pub fn bounds(&self, b: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let lo = self.origin(b);
        let hi = std::array::from_fn(|a| (lo[a] + BRICK).min(self.dims[a] - 1));
        (lo, hi)
    }

    /// Whether the brick has a face on the volume's boundary.
    pub fn touches_boundary(&self, b: [usize; 3]) -> bool {
        (0..3).any(|a| b[a] == 0 || b[a] + 1 == self.bricks[a])
    }

    /// Coordinates of the voxel of linear index `v` (into the volume).
    #[inline]
    pub fn voxel_coords(&self, v: usize) -> [usize; 3] {
        let [nx, ny, _] = self.dims;
        [v % nx, (v / nx) % ny, v / (nx * ny)]
    }

    /// Linear index (into the volume) of the voxel in slot `s` of brick `b`:
    /// slots beyond the volume repeat its last voxel.
    #[inline]
    pub fn voxel_of_slot(&self, b: [usize; 3], s: [usize; 3]) -> usize {
        let [nx, ny, nz] = self.dims;
        let o = self.origin(b);
        let x = (o[0] + s[0]).min(nx - 1);
        let y = (o[1] + s[1]).min(ny - 1);
        let z = (o[2] + s[2]).min(nz - 1);
        x + nx * (y + ny * z)
    }
}

/// Slot index of local voxel `(i, j, k)` in a brick.
#[inline]
pub fn slot(i: usize, j: usize, k: usize) -> usize {
    i + SIDE * (j + SIDE * k)
}

/// Local coordinates of every slot, in slot order.
pub fn slot_coords() -> impl Iterator<Item = [usize; 3]> {
    (0..SIDE).flat_map(|k| (0..SIDE).flat_map(move |j| (0..SIDE).map(move |i| [i, j, k])))
}

/// Cell index of local cell `(i, j, k)` in a brick (the bit in its mask).
#[inline]
pub fn cell(i: usize, j: usize, k: usize) -> usize {
    i + BRICK * (j + BRICK * k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bricks_cover_every_cell_once() {
        // 50 voxels = 49 cells: 7 bricks, the last with one cell.
        let g = BrickGrid::new([50, 9, 17]);
        assert_eq!(g.bricks, [7, 1, 2]);
        assert_eq!(g.bounds([6, 0, 1]), ([48, 0, 8], [49, 8, 16]));
        let mut covered = [0usize; 49];
        for bx in 0..7 {
            let (lo, hi) = g.bounds([bx, 0, 0]);
            for c in &mut covered[lo[0]..hi[0]] {
                *c += 1;
            }
        }
        assert!(covered.iter().all(|&n| n == 1));
        for i in 0..g.len() {
            assert_eq!(g.index(g.coords(i)), i);
        }
    }

    #[test]
    fn slots_share_faces_and_repeat_the_last_voxel() {
        let g = BrickGrid::new([20, 10, 10]);
        // The face x = 8 is slot 8 of brick 0 and slot 0 of brick 1.
        assert_eq!(
            g.voxel_of_slot([0, 0, 0], [8, 3, 4]),
            g.voxel_of_slot([1, 0, 0], [0, 3, 4])
        );
        // Brick 2 along x starts at voxel 16; slots past voxel 19 repeat it.
        assert_eq!(g.voxel_of_slot([2, 0, 0], [3, 0, 0]), 19);
        assert_eq!(g.voxel_of_slot([2, 0, 0], [8, 0, 0]), 19);
        assert_eq!(slot_coords().count(), SLOTS);
        assert_eq!(slot_coords().nth(slot(2, 3, 4)), Some([2, 3, 4]));
        assert!(g.touches_boundary([1, 0, 0]) && g.touches_boundary([2, 1, 1]));
        let inner = BrickGrid::new([40, 40, 40]);
        assert!(!inner.touches_boundary([2, 1, 3]));
    }
}
