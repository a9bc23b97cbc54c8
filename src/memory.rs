//! `--max-memory` for rendering: refuse a volume whose frame may need
//! more memory than the limit, before the renderer is built. The bound is
//! volray-core's ([`MemoryBound`]): the volume, the path's caches and
//! buffers for a dense volume (every brick occupied: a sparse one needs
//! less), the frame, and a cleaned copy with `--nonfinite transparent`.
//! Beside it the CLI counts what it adds: a 16-bit PNG's quantised pixels.

use crate::error::CliError;
use crate::flags::ViewArgs;
use crate::input::Input;
use volray_core::{MemoryBound, NonFinite, RenderSettings};
use volray_io::format_bytes;

/// An upper bound on the bytes rendering one frame of a volume of `dims`
/// voxels `spacing` apart with `settings` and non-finite values handled
/// as `mode` says takes, the volume included.
pub fn render_bytes(
    dims: [usize; 3],
    spacing: volray_core::glam::DVec3,
    settings: &RenderSettings,
    mode: NonFinite,
) -> u128 {
    let bound = MemoryBound::new(dims, spacing, settings, mode).total();
    // A 16-bit PNG quantises the frame first: 8 bytes a pixel.
    bound + 8 * settings.width as u128 * settings.height as u128
}

/// Refuses to render `input` with `settings` if [`render_bytes`] exceeds
/// its limit.
pub fn check_render(
    view: &ViewArgs,
    settings: &RenderSettings,
    input: &Input,
) -> Result<(), CliError> {
    let volume = &input.volume;
    let mode = input.non_finite(view.sampling.nonfinite.into());
    let need = render_bytes(volume.dims(), volume.spacing(), settings, mode);
    if need <= u128::from(input.max_memory) {
        return Ok(());
    }
    let [nx, ny, nz] = input.volume.dims();
    Err(CliError::input(format!(
        "{}: rendering {nx}x{ny}x{nz} voxels at {}x{} pixels may take up to {}, more than --max-memory {} (raise it, or use a smaller grid)",
        input.name,
        view.camera.size.0,
        view.camera.size.1,
        format_bytes(need),
        format_bytes(u128::from(input.max_memory))
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flags::{Cli, Command};
    use clap::Parser;
    use volray_core::glam::DVec3;

    fn bytes(args: &[&str], dims: [usize; 3]) -> u128 {
        let argv = [&["volray", "render", "-o", "x.png"], args].concat();
        let view = match Cli::parse_from(argv).command {
            Command::Render(r) => r.view,
            _ => unreachable!(),
        };
        let settings = crate::settings::settings(&view).unwrap();
        render_bytes(dims, DVec3::ONE, &settings, view.sampling.nonfinite.into())
    }

    #[test]
    fn bounds_follow_the_paths_and_count_the_png() {
        let dims = [65, 65, 65];
        let voxels = 65u128.pow(3);
        let frame = 24 * 480 * 480;
        // Every brick occupied and lit: about 34 bytes a voxel, beside the volume.
        let bricked = bytes(&[], dims);
        assert!((4 * voxels + 30 * voxels..4 * voxels + 40 * voxels).contains(&(bricked - frame)));
        // Post-classification: 16 bytes a voxel kept, 12 more while packing.
        let post = bytes(&["--post-classification"], dims);
        assert!(
            (32 * voxels + frame..32 * voxels + frame + 100_000).contains(&post),
            "{post}"
        );
        // A projection needs the frame twice over (values, then colours).
        let mip = bytes(&["--blend", "mip", "--size", "10x20"], dims);
        assert!(
            (4 * voxels + 40 * 200..4 * voxels + 40 * 200 + 50_000).contains(&mip),
            "{mip}"
        );
        // --nonfinite transparent adds a cleaned copy and a bit a voxel.
        let cleaned = bytes(
            &[
                "--blend",
                "mip",
                "--size",
                "10x20",
                "--nonfinite",
                "transparent",
            ],
            dims,
        );
        assert_eq!(
            cleaned - mip,
            4 * voxels + voxels.div_ceil(64) * 8 + 8u128.pow(3)
        );
        // The bricks' slots hold (9/8)^3 ≈ 1.42 of each voxel: 38 bytes a
        // voxel with the volume.
        let per_voxel = bytes(&["--size", "1"], [1025; 3]) as f64 / 1025f64.powi(3);
        assert!((38.0..39.0).contains(&per_voxel), "{per_voxel}");
    }
}
