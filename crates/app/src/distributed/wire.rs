//! A distributed render's bytes on the wire: a grid, a piece (rank 0
//! sends each rank its piece of a file that cannot be read by range).

use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;

/// The held piece (with ghosts) of the box `lo..hi`, or `None` if empty.
pub(super) fn held_piece(
    volume: &Volume,
    lo: [usize; 3],
    hi: [usize; 3],
    dims: [usize; 3],
) -> Option<Volume> {
    if (0..3).any(|a| lo[a] >= hi[a]) {
        return None;
    }
    let (lo, hi) = volray_core::Piece::held((lo, hi), dims);
    Some(volume.sub_box(lo, hi))
}

pub(super) fn grid_of(v: &Volume) -> GridFrame {
    GridFrame {
        dims: v.dims(),
        origin: v.origin(),
        spacing: v.spacing(),
    }
}

/// A grid on the wire: dims (3 × `u64`), origin and spacing (6 × `f64`),
/// little-endian: 72 bytes.
pub(super) fn grid_bytes(g: &GridFrame) -> Vec<u8> {
    let mut out = Vec::with_capacity(72);
    for d in g.dims {
        out.extend_from_slice(&(d as u64).to_le_bytes());
    }
    for x in g.origin.to_array().into_iter().chain(g.spacing.to_array()) {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

/// The grid of [`grid_bytes`] (`b` at least 72 bytes).
pub(super) fn parse_grid(b: &[u8]) -> GridFrame {
    let u = |i: usize| u64::from_le_bytes(b[8 * i..8 * i + 8].try_into().unwrap()) as usize;
    let f = |i: usize| f64::from_le_bytes(b[8 * i..8 * i + 8].try_into().unwrap());
    GridFrame {
        dims: [u(0), u(1), u(2)],
        origin: DVec3::new(f(3), f(4), f(5)),
        spacing: DVec3::new(f(6), f(7), f(8)),
    }
}

/// A piece on the wire: its grid ([`grid_bytes`]), the labels flag, then
/// its samples as little-endian `f32`, written straight from its own
/// type (no `f32` copy of the piece on the way).
pub(super) fn encode_piece(v: &Volume) -> Vec<u8> {
    let mut out = grid_bytes(&grid_of(v));
    out.reserve(1 + 4 * v.len());
    out.push(v.is_labels() as u8);
    volray_core::with_samples!(v.samples(), |data| {
        for x in data.iter() {
            out.extend_from_slice(&volray_core::Sample::to_f32(*x).to_le_bytes());
        }
    });
    out
}

pub(super) fn decode_piece(b: &[u8]) -> Option<Volume> {
    if b.len() < 73 {
        return None;
    }
    let (grid, labels) = (parse_grid(b), b[72] != 0);
    let data: Vec<f32> = (b[73..].chunks_exact(4))
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let mut v = Volume::new(grid.dims, data)
        .ok()?
        .with_spacing(grid.spacing)
        .ok()?
        .with_origin(grid.origin)
        .ok()?;
    v.set_labels(labels);
    Some(v)
}
