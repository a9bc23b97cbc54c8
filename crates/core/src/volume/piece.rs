//! A piece of a larger volume: what one rank of a sort-last distributed
//! render holds, and the rule that makes the pieces' frames add up to the
//! whole volume's frame.
//!
//! A rank holds a box of the whole grid plus ghost layers ([`Piece::GHOST_BELOW`],
//! [`Piece::GHOST_ABOVE`]) as its own [`Volume`](crate::Volume), and renders it
//! with [`RenderSettings::piece`](crate::RenderSettings) set. Then:
//!
//! - the camera frames the *whole* volume's box, so every rank has the
//!   same view, pixel for pixel;
//! - every ray takes the whole volume's samples, `t = (k + u)·step` from
//!   the same image plane or eye, cut by the same crop box and clip planes
//!   (the sample planes are global, never the piece's own);
//! - of those, the piece takes the samples whose positions it owns, the
//!   half-open box `lo ≤ p < hi` of whole-grid positions
//!   ([`Piece::owned`]). The pieces of a k-d split own disjoint boxes that
//!   tile the grid, so each sample is taken by exactly one piece;
//! - classification uses the whole volume's value range and largest
//!   gradient ([`Piece::value_range`], [`Piece::max_gradient`]), not the
//!   piece's.
//!
//! Whether a sample on a face between two pieces is on one side or the
//! other is decided on its ray index `k` alone: the face's crossing,
//! `K = ⌈t_face/step − u⌉`, computed from the same world ray and the same
//! face coordinate by both pieces, bit for bit, splits the ray's samples
//! into `k < K` (before the face) and `k ≥ K` (after it). No tolerance is
//! involved, so no sample is taken twice or lost, however close to the
//! face it lies (the whole volume's own faces keep their tolerance, as in
//! one process). Composited in visibility order, the pieces' partial
//! images give the whole frame, within early ray termination's 1/1024 per
//! piece boundary and rounding.
//!
//! Ghost layers: a sample at whole position `p` (with `lo ≤ p < hi`, or a
//! rounding error outside) reads the eight voxels of its cell, `⌊p⌋` and
//! `⌊p⌋ + 1` on each axis, so voxels `lo − 1 ..= hi`; their gradients
//! (central differences) read one voxel further, `lo − 2 ..= hi + 1`; a
//! sample a rounding error past `hi` may touch `hi + 1`'s gradient, so
//! `hi + 2`. A piece therefore holds voxels `lo − 2 .. hi + 3` (clamped to
//! the grid).

pub use crate::error::Misfit;
use crate::error::SettingError;
use crate::sampling::grid::GridFrame;
use glam::DVec3;

/// A rank's piece of a larger volume (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// The whole volume's grid.
    pub whole: GridFrame,
    /// The whole-grid index of the renderer's volume's first voxel.
    pub offset: [usize; 3],
    /// The whole-grid positions whose samples this piece takes:
    /// `lo[a] ≤ p[a] < hi[a]`, in voxel indices, a k-d box of the whole
    /// grid's voxels. On the whole grid's far faces (`hi[a] = dims[a]`),
    /// and its near ones (`lo[a] = 0`), the grid's own bounds apply.
    pub owned: ([usize; 3], [usize; 3]),
    /// The whole volume's value range: the transfer function's domain
    /// when it names none, and projections' colour map.
    pub value_range: (f32, f32),
    /// The whole volume's largest gradient magnitude (world units), which
    /// gradient opacity and iso-surfaces are scaled by.
    pub max_gradient: f32,
}

impl Piece {
    /// Ghost voxels a piece holds below its owned box on each axis.
    pub const GHOST_BELOW: usize = 2;
    /// Ghost voxels a piece holds above its owned box on each axis
    /// (past `hi − 1`, its last owned voxel).
    pub const GHOST_ABOVE: usize = 3;

    /// The voxels a piece owning `owned` of a grid of `dims` must hold:
    /// the owned box with its ghost layers, clamped to the grid,
    /// half-open.
    pub fn held(owned: ([usize; 3], [usize; 3]), dims: [usize; 3]) -> ([usize; 3], [usize; 3]) {
        let (lo, hi) = owned;
        (
            std::array::from_fn(|a| lo[a].saturating_sub(Self::GHOST_BELOW)),
            std::array::from_fn(|a| (hi[a] + Self::GHOST_ABOVE).min(dims[a])),
        )
    }

    /// Checks that a volume of `dims`, `spacing` and `origin` is this
    /// piece of the whole: the same spacing, its voxels inside the whole
    /// grid where the offset puts them, and the owned box with the cells
    /// its samples read inside it.
    pub fn validate(&self, dims: [usize; 3], spacing: DVec3) -> Result<(), SettingError> {
        let whole = self.whole.dims;
        let (lo, hi) = self.owned;
        let fits = (0..3).all(|a| {
            let end = self.offset[a] + dims[a];
            end <= whole[a]
                && lo[a] < hi[a]
                && hi[a] <= whole[a]
                // The cells of the owned positions are held.
                && (lo[a] == 0 || self.offset[a] < lo[a])
                && self.offset[a] <= lo[a]
                && (hi[a] >= whole[a] - 1 || end > hi[a] + 1)
        });
        if !fits || spacing != self.whole.spacing {
            return Err(SettingError::Piece(Box::new(Misfit {
                whole,
                offset: self.offset,
                dims,
                owned: self.owned,
            })));
        }
        Ok(())
    }

    /// The owned box's faces inside the whole grid: the ones where this
    /// piece meets another.
    pub fn ownership(&self) -> Ownership {
        let (lo, hi) = self.owned;
        let g = &self.whole;
        let plane = |a: usize, i: usize| g.origin[a] + i as f64 * g.spacing[a];
        let mut faces = Vec::new();
        for a in 0..3 {
            if lo[a] > 0 {
                faces.push(Face {
                    axis: a,
                    at: plane(a, lo[a]),
                    keep: Keep::Above,
                });
            }
            if hi[a] < g.dims[a] {
                faces.push(Face {
                    axis: a,
                    at: plane(a, hi[a]),
                    keep: Keep::Below,
                });
            }
        }
        Ownership {
            whole: self.whole,
            faces,
        }
    }
}

/// Which side of a face a piece keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Keep {
    /// `p ≥ at`: the face is the owned box's low face.
    Above,
    /// `p < at`: the owned box's high face.
    Below,
}

/// One face of an owned box, a plane `p[axis] = at` in world units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Face {
    pub axis: usize,
    pub at: f64,
    pub keep: Keep,
}

/// Which of a ray's samples a piece takes: the whole grid (whose span
/// bounds the ray, as in one process) and the owned box's inner faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Ownership {
    pub whole: GridFrame,
    pub faces: Vec<Face>,
}

impl Ownership {
    /// Cuts the samples `first..=last` (sample `k` at `t = (k + offset)·step`
    /// along `origin + t·direction`) to those this piece owns, or `None`.
    pub fn restrict(
        &self,
        origin: DVec3,
        direction: DVec3,
        step: f64,
        offset: f64,
        (mut first, mut last): (i64, i64),
    ) -> Option<(i64, i64)> {
        for face in &self.faces {
            let (o, d) = (origin[face.axis], direction[face.axis]);
            if d == 0.0 {
                // Parallel to the face: all of the ray or none of it.
                let above = o >= face.at;
                if above != (face.keep == Keep::Above) {
                    return None;
                }
                continue;
            }
            // Samples k < crossing are before the face, k ≥ crossing after.
            let crossing = ((face.at - o) / d / step - offset).ceil();
            // Far outside the ray's samples: the comparison decides alone.
            let crossing = crossing.clamp(i64::MIN as f64 / 2.0, i64::MAX as f64 / 2.0) as i64;
            // Before the face the ray is below it when it moves up the axis.
            let keep_after = (d > 0.0) == (face.keep == Keep::Above);
            if keep_after {
                first = first.max(crossing);
            } else {
                last = last.min(crossing - 1);
            }
        }
        (first <= last).then_some((first, last))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whole() -> GridFrame {
        GridFrame {
            dims: [20, 10, 10],
            origin: DVec3::new(-1.0, 0.0, 2.0),
            spacing: DVec3::new(0.5, 1.0, 1.0),
        }
    }

    fn piece(lo: [usize; 3], hi: [usize; 3]) -> Piece {
        let (offset, _) = Piece::held((lo, hi), whole().dims);
        Piece {
            whole: whole(),
            offset,
            owned: (lo, hi),
            value_range: (0.0, 1.0),
            max_gradient: 1.0,
        }
    }

    #[test]
    fn pieces_on_either_side_of_a_face_split_every_ray_once() {
        // Two pieces meeting at x = 7 (world −1 + 3.5 = 2.5); rays along
        // ±x and obliquely, with offsets that put samples exactly on the
        // face and a hair either side of it.
        let (a, b) = (piece([0; 3], [7, 10, 10]), piece([7, 0, 0], [20, 10, 10]));
        let (a, b) = (a.ownership(), b.ownership());
        let all = (-100, 100);
        for direction in [
            DVec3::X,
            -DVec3::X,
            DVec3::new(0.6, 0.8, 0.0),
            DVec3::new(-0.36, 0.48, 0.8),
        ] {
            for offset in [0.0, 1e-12, -1e-12, 0.25, 0.5] {
                let origin = DVec3::new(2.5, 3.0, 4.0) - 10.0 * direction;
                let step = 0.5;
                let ra = a.restrict(origin, direction, step, offset, all).unwrap();
                let rb = b.restrict(origin, direction, step, offset, all).unwrap();
                // Complementary halves of −100..=100 in the ray's order.
                let (front, back) = if direction.x > 0.0 {
                    (ra, rb)
                } else {
                    (rb, ra)
                };
                assert_eq!(front.0, -100);
                assert_eq!(back.1, 100);
                assert_eq!(front.1 + 1, back.0, "{direction} {offset}");
                // And each piece's samples are on its side (a sample on
                // the face itself goes to the side after it).
                let t = |k: i64| (k as f64 + offset) * step;
                let x = |k: i64| origin.x + t(k) * direction.x;
                assert!(x(ra.1) <= 2.5 + 1e-9 && x(rb.0).max(x(rb.1)) >= 2.5 - 1e-9);
            }
        }
    }

    #[test]
    fn a_ray_parallel_to_a_face_belongs_to_the_side_it_runs_in() {
        let (a, b) = (piece([0; 3], [7, 10, 10]), piece([7, 0, 0], [20, 10, 10]));
        let (a, b) = (a.ownership(), b.ownership());
        for (x, in_a) in [(2.4, true), (2.5, false), (2.6, false)] {
            let o = DVec3::new(x, 0.0, 0.0);
            let ra = a.restrict(o, DVec3::Y, 1.0, 0.0, (0, 9));
            let rb = b.restrict(o, DVec3::Y, 1.0, 0.0, (0, 9));
            assert_eq!((ra.is_some(), rb.is_some()), (in_a, !in_a), "x = {x}");
        }
    }

    #[test]
    fn the_whole_grids_own_faces_are_not_cut() {
        assert!(piece([0; 3], [20, 10, 10]).ownership().faces.is_empty());
        let faces = piece([0, 3, 0], [20, 10, 6]).ownership().faces;
        assert_eq!(faces.len(), 2);
        assert_eq!(
            (faces[0].axis, faces[0].at, faces[0].keep),
            (1, 3.0, Keep::Above)
        );
        assert_eq!(
            (faces[1].axis, faces[1].at, faces[1].keep),
            (2, 8.0, Keep::Below)
        );
    }

    #[test]
    fn a_piece_must_hold_the_cells_of_what_it_owns() {
        let p = piece([7, 0, 0], [20, 10, 10]);
        // Held: x from 5 to 20 (two ghost voxels below 7).
        assert_eq!(p.offset, [5, 0, 0]);
        assert!(p.validate([15, 10, 10], whole().spacing).is_ok());
        // Another spacing, or a volume running past the whole grid, or
        // one not reaching below the owned box, is refused.
        assert!(p.validate([15, 10, 10], DVec3::ONE).is_err());
        assert!(p.validate([16, 10, 10], whole().spacing).is_err());
        let bare = Piece {
            offset: [7, 0, 0],
            ..p.clone()
        };
        assert!(bare.validate([13, 10, 10], whole().spacing).is_err());
        // The low piece must reach past its high face.
        let low = piece([0; 3], [7, 10, 10]);
        assert_eq!(Piece::held(low.owned, whole().dims), ([0; 3], [10, 10, 10]));
        assert!(low.validate([10, 10, 10], whole().spacing).is_ok());
        assert!(low.validate([8, 10, 10], whole().spacing).is_err());
    }
}
