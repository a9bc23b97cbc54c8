//! `--max-memory` for rendering: an upper bound on the memory a frame of a
//! volume needs, checked before the renderer is built.
//!
//! The readers bound what they allocate (`volray_io::check_volume_size`);
//! the renderer needs more than the volume. What `volray-core` allocates
//! per path, beside the volume's `f32` values (4 bytes a voxel):
//!
//! - pre-classified fast path (composite, iso): the occupied bricks
//!   (`classified.rs`, 8 bytes a slot: normal and opacity) and their lit
//!   colours (`shade_bricks.rs`, 16 bytes a slot), [`SLOTS`] slots per
//!   brick of [`BRICK`]³ cells, plus per-brick masks; bounded by every
//!   brick being occupied and lit, about 34 bytes a voxel. The gradients
//!   of `--gradient-opacity` (12 bytes a voxel) are freed before;
//! - post-classified fast path: the gradients (12 bytes a voxel) while the
//!   packed value-and-gradient voxels (16 bytes) are built: 28;
//! - reference path: the gradients (12) and the shaded, classified voxels
//!   (`stage1.rs`, 16): 28;
//! - projections (mip, minip, average): the min/max macro-cells only;
//! - `--nonfinite transparent` on a volume with NaN or infinite values: a
//!   cleaned copy (4) and its mask (1);
//!
//! and the frame: 16 bytes a pixel (`f32` RGBA) and 8 more for a 16-bit
//! PNG. The bound is a worst case (a dense volume): a sparse one needs less.

use crate::cli::{BlendMode, ViewArgs};
use crate::error::CliError;
use crate::input::Input;
use volray_core::bricks::{BRICK, SLOTS};
use volray_io::format_bytes;

/// Bytes of the per-brick bookkeeping beside the slots: `slot_of` (4),
/// coordinates (24), the cell mask (64), the occupied cell box (6), the
/// needed-slot mask (96), the lit brick's lock and frame (about 32).
const BRICK_OVERHEAD: u128 = 4 + 24 + 64 + 6 + 96 + 32;

/// Bytes one slot of an occupied brick takes: classified (8) and lit (16).
const SLOT_BYTES: u128 = 8 + 16;

/// An upper bound on the bytes rendering one frame of a volume of `dims`
/// with `view`'s options takes, the volume included (see the module docs).
pub fn render_bytes(dims: [usize; 3], view: &ViewArgs) -> u128 {
    let voxels: u128 = dims.iter().map(|&n| n as u128).product();
    let volume = 4 * voxels;
    let projection = matches!(
        view.blend,
        BlendMode::Mip | BlendMode::Minip | BlendMode::Average
    );
    let path = if projection {
        0
    } else if view.reference || view.post_classification {
        28 * voxels
    } else {
        let bricks: u128 = dims
            .iter()
            .map(|&n| n.saturating_sub(1).div_ceil(BRICK) as u128)
            .product();
        (bricks * (SLOTS as u128 * SLOT_BYTES + BRICK_OVERHEAD)).max(12 * voxels)
    };
    let cleaned = match view.nonfinite {
        crate::cli::NonFiniteMode::Transparent => 5 * voxels,
        crate::cli::NonFiniteMode::Refuse => 0,
    };
    let (w, h) = view.size;
    let frame = 24 * w as u128 * h as u128;
    volume + path + cleaned + frame
}

/// Refuses to render `input` if [`render_bytes`] exceeds its limit.
pub fn check_render(view: &ViewArgs, input: &Input) -> Result<(), CliError> {
    let need = render_bytes(input.volume.dims(), view);
    if need <= u128::from(input.max_memory) {
        return Ok(());
    }
    let [nx, ny, nz] = input.volume.dims();
    Err(CliError::input(format!(
        "{}: rendering {nx}x{ny}x{nz} voxels at {}x{} pixels may take up to {}, more than --max-memory {} (raise it, or use a smaller grid)",
        input.name,
        view.size.0,
        view.size.1,
        format_bytes(need),
        format_bytes(u128::from(input.max_memory))
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::Cli;
    use clap::Parser;

    fn view(args: &[&str]) -> ViewArgs {
        let argv = [&["volray", "render", "-o", "x.png"], args].concat();
        match Cli::parse_from(argv).command {
            crate::cli::Command::Render(r) => r.view,
            _ => unreachable!(),
        }
    }

    #[test]
    fn bounds_follow_the_paths() {
        let dims = [65, 65, 65];
        let voxels = 65u128.pow(3);
        let frame = 24 * 480 * 480;
        // 8 bricks per axis, every one occupied and lit.
        let bricks = 8u128.pow(3) * (729 * 24 + BRICK_OVERHEAD);
        assert_eq!(render_bytes(dims, &view(&[])), 4 * voxels + bricks + frame);
        assert_eq!(
            render_bytes(dims, &view(&["--post-classification"])),
            32 * voxels + frame
        );
        assert_eq!(
            render_bytes(dims, &view(&["--reference"])),
            32 * voxels + frame
        );
        assert_eq!(
            render_bytes(dims, &view(&["--blend", "mip", "--size", "10x20"])),
            4 * voxels + 24 * 200
        );
        assert_eq!(
            render_bytes(
                dims,
                &view(&["--blend", "mip", "--nonfinite", "transparent"])
            ),
            9 * voxels + frame
        );
        // The bricks' slots hold (9/8)^3 ≈ 1.42 of each voxel: 34 bytes a voxel.
        let per_voxel = render_bytes([1025; 3], &view(&["--size", "1"])) as f64 / 1025f64.powi(3);
        assert!((38.0..39.0).contains(&per_voxel), "{per_voxel}");
    }
}
