//! `--max-memory` for rendering: how much of the limit the fast path's
//! caches may take, and the refusal of a volume whose frame would need
//! more than the limit whatever the caches, before the renderer is built.
//! The bound is volray-core's ([`MemoryBound`]): the volume (in its own
//! sample type), the path's structures for a dense volume (every brick
//! occupied: a sparse one needs less), the caches of classified and lit
//! bricks up to their budget, the frame, and a cleaned copy with
//! `--nonfinite transparent`. Beside it the CLI counts what it adds: a
//! 16-bit PNG's quantised pixels. A volume mapped from its file (one over
//! the limit, see volray-io's `MapPolicy`) does not count: its pages are
//! the file's, read and dropped by the operating system.

use crate::error::CliError;
use crate::flags::ViewArgs;
use crate::input::Input;
use volray_core::glam::DVec3;
use volray_core::{
    DEFAULT_CACHE_BUDGET, MemoryBound, Method, NonFinite, RenderSettings, SampleType,
};
use volray_io::format_bytes;

/// An upper bound on the bytes rendering one frame of a volume of `dims`
/// voxels `spacing` apart, of samples of type `sample`, with `settings`
/// and non-finite values handled as `mode` says takes, the volume
/// included, with `cache_budget` bytes of brick caches.
pub fn render_bytes(
    (dims, spacing, sample): ([usize; 3], DVec3, SampleType),
    settings: &RenderSettings,
    mode: NonFinite,
    cache_budget: usize,
) -> u128 {
    let bound = MemoryBound::new(dims, spacing, sample, settings, mode, cache_budget).total();
    // A 16-bit PNG quantises the frame first: 8 bytes a pixel.
    bound + 8 * settings.width as u128 * settings.height as u128
}

/// The budget of the brick caches for rendering `input` with `settings`:
/// the library's default ([`DEFAULT_CACHE_BUDGET`]), or what is left
/// under `--max-memory` when that is less. Refuses a volume whose frame
/// would not fit even with no cache.
pub fn cache_budget(
    view: &ViewArgs,
    settings: &RenderSettings,
    input: &Input,
) -> Result<usize, CliError> {
    let volume = &input.volume;
    let limit = u128::from(input.max_memory);
    let grid = (volume.dims(), volume.spacing(), volume.sample_type());
    let mode = input.non_finite(view.sampling.nonfinite.into());
    // A volume mapped from its file is the page cache's, not ours: only
    // what the renderer adds counts.
    let mapped = if volume.samples().is_external() {
        (volume.len() * volume.sample_type().bytes()) as u128
    } else {
        0
    };
    let need = render_bytes(grid, settings, mode, 0) - mapped;
    if need > limit {
        let [nx, ny, nz] = volume.dims();
        let what = format!(
            "{}: rendering {nx}x{ny}x{nz} voxels at {}x{} pixels",
            input.name,
            view.camera.size().0,
            view.camera.size().1
        );
        // The oracle is dense: say so where the default path would fit.
        let fast = RenderSettings {
            method: Method::Fast,
            ..settings.clone()
        };
        let fast_need = render_bytes(grid, &fast, mode, 0) - mapped;
        if settings.method == Method::Reference && fast_need <= limit {
            return Err(CliError::input(format!(
                "{what} on the reference path (--reference) may take up to {}, more than --max-memory {}; the default path takes at most {}: leave out --reference",
                format_bytes(need),
                format_bytes(limit),
                format_bytes(fast_need)
            )));
        }
        return Err(CliError::input(format!(
            "{what} may take up to {}, more than --max-memory {} (raise it, or use a smaller grid)",
            format_bytes(need),
            format_bytes(limit)
        )));
    }
    Ok(usize::try_from(limit - need)
        .map_or(DEFAULT_CACHE_BUDGET, |room| room.min(DEFAULT_CACHE_BUDGET)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flags::{Cli, Command};
    use clap::Parser;

    fn view(args: &[&str]) -> ViewArgs {
        let argv = [&["volray", "render", "-o", "x.png"], args].concat();
        match Cli::parse_from(argv).command {
            Command::Render(r) => r.view,
            _ => unreachable!(),
        }
    }

    /// The bound for `args` on an `f32` volume of `dims`, all bricks cached.
    fn bytes(args: &[&str], dims: [usize; 3]) -> u128 {
        let view = view(args);
        let settings = crate::settings::settings(&view).unwrap();
        let mode = NonFinite::from(view.sampling.nonfinite);
        render_bytes(
            (dims, DVec3::ONE, SampleType::F32),
            &settings,
            mode,
            usize::MAX,
        )
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

#[cfg(test)]
mod budget_tests {
    use super::*;
    use crate::flags::{Cli, Command};
    use clap::Parser;
    use volray_core::Volume;

    fn input(volume: Volume, max_memory: u64) -> Input {
        Input {
            name: "v".to_string(),
            volume,
            file: None,
            max_memory,
        }
    }

    #[test]
    fn the_caches_get_what_max_memory_leaves_up_to_the_default() {
        let argv = ["volray", "render", "-o", "x.png", "--size", "64"];
        let view = match Cli::parse_from(argv).command {
            Command::Render(r) => r.view,
            _ => unreachable!(),
        };
        let settings = crate::settings::settings(&view).unwrap();
        let dims = [33, 33, 33];
        let volume = Volume::from_samples(dims, vec![7u16; 33 * 33 * 33]).unwrap();
        let grid = (dims, volume.spacing(), SampleType::U16);
        let without = render_bytes(grid, &settings, NonFinite::Refuse, 0) as u64;
        // Plenty of memory: the default budget.
        let roomy = input(volume.clone(), 1 << 40);
        assert_eq!(
            cache_budget(&view, &settings, &roomy).unwrap(),
            DEFAULT_CACHE_BUDGET
        );
        // A limit 100 kB above the frame's own needs: 100 kB of caches.
        let tight = input(volume.clone(), without + 100_000);
        assert_eq!(cache_budget(&view, &settings, &tight).unwrap(), 100_000);
        // Below them: refused, naming the limit.
        let short = input(volume.clone(), without - 1);
        let err = cache_budget(&view, &settings, &short).unwrap_err();
        assert!(err.message.contains("more than --max-memory"), "{err}");
        // The reference path is dense (28 bytes a voxel more): refused
        // where the default path fits, saying so.
        let reference = RenderSettings {
            method: Method::Reference,
            ..settings.clone()
        };
        let err = cache_budget(&view, &reference, &tight).unwrap_err();
        assert!(
            err.message.contains("on the reference path (--reference)")
                && err.message.contains("leave out --reference"),
            "{err}"
        );
    }
}
