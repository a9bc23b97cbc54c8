//! The memory budget: how much of the limit (`--max-memory`, Python's
//! `max_memory`) the fast path's caches may take, and the refusal of a
//! volume whose frame would need more than the limit whatever the caches,
//! before the renderer is built; one function, [`cache_budget`], which
//! every front end calls with the frame's settings.
//! The bound is volray-core's ([`MemoryBound`]): the volume (in its own
//! sample type), the path's structures for a dense volume (every brick
//! occupied: a sparse one needs less), the caches of classified and lit
//! bricks up to their budget, the frame, and a cleaned copy with
//! `--nonfinite transparent`. Beside it a front end counts what it adds
//! ([`Budget::extra`]): the command line's 16-bit PNG's quantised pixels
//! ([`png_bytes`]). A volume mapped from its file (one over the limit,
//! see volray-io's `MapPolicy`) does not count: its pages are the file's,
//! read and dropped by the operating system; nor do samples the caller
//! owns (a numpy array).
use crate::error::{AppError, OverBudget};
use volray_core::glam::DVec3;
use volray_core::{
    DEFAULT_CACHE_BUDGET, MemoryBound, Method, NonFinite, RenderSettings, SampleType, Volume,
};

/// What a 16-bit PNG adds to a frame of `settings`: it quantises the
/// frame first, 8 bytes a pixel.
pub fn png_bytes(settings: &RenderSettings) -> u128 {
    8 * settings.width as u128 * settings.height as u128
}

/// An upper bound on the bytes rendering one frame of a volume of `dims`
/// voxels `spacing` apart, of samples of type `sample`, with `settings`
/// and non-finite values handled as `mode` says takes, the volume
/// included, with `cache_budget` bytes of brick caches, and the command
/// line's 16-bit PNG ([`png_bytes`]).
pub fn render_bytes(
    (dims, spacing, sample): ([usize; 3], DVec3, SampleType),
    settings: &RenderSettings,
    mode: NonFinite,
    cache_budget: usize,
) -> u128 {
    let bound = MemoryBound::new(dims, spacing, sample, settings, mode, cache_budget).total();
    bound + png_bytes(settings)
}

/// What a front end's frames are held to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// The memory limit, in bytes.
    pub limit: u64,
    /// What the front end adds to each frame (the command line's
    /// [`png_bytes`]; 0 for Python, which hands the frame over).
    pub extra: u128,
    /// Whether the volume's own samples count: not when they are mapped
    /// from their file (always so) or are the caller's (a numpy array).
    pub samples_count: bool,
}

/// What rendering a frame of `volume` with `settings` may take with no
/// brick cache, non-finite values handled as `mode` says: volray-core's
/// bound, with what the front end adds, less the volume's samples where
/// they do not count ([`Budget`]).
pub fn frame_bytes(
    volume: &Volume,
    settings: &RenderSettings,
    mode: NonFinite,
    budget: &Budget,
) -> u128 {
    let bound = MemoryBound::new(
        volume.dims(),
        volume.spacing(),
        volume.sample_type(),
        settings,
        mode,
        0,
    );
    // A volume mapped from its file is the page cache's, not ours: only
    // what the renderer adds counts.
    let samples = (volume.len() * volume.sample_type().bytes()) as u128;
    let mapped = if budget.samples_count && !volume.samples().is_external() {
        0
    } else {
        samples
    };
    bound.total() + budget.extra - mapped
}

/// The budget of the brick caches for rendering `volume` (named `name`)
/// with `settings`, non-finite values handled as `mode` says: the
/// library's default ([`DEFAULT_CACHE_BUDGET`]), or what is left under
/// the limit when that is less. Refuses a volume whose frame would not
/// fit even with no cache ([`AppError::OverBudget`], saying where the
/// default path would fit what the reference path does not).
pub fn cache_budget(
    volume: &Volume,
    name: &str,
    settings: &RenderSettings,
    mode: NonFinite,
    budget: Budget,
) -> Result<usize, AppError> {
    let limit = u128::from(budget.limit);
    let bytes = |settings: &RenderSettings| frame_bytes(volume, settings, mode, &budget);
    let need = bytes(settings);
    if need > limit {
        // The oracle is dense: say so where the default path would fit.
        let fast = RenderSettings {
            method: Method::Fast,
            ..settings.clone()
        };
        let fast_need = bytes(&fast);
        let fast_need =
            (settings.method == Method::Reference && fast_need <= limit).then_some(fast_need);
        return Err(AppError::OverBudget(Box::new(OverBudget {
            name: name.to_string(),
            dims: volume.dims(),
            size: (settings.width, settings.height),
            need,
            limit,
            fast_need,
        })));
    }
    Ok(usize::try_from(limit - need)
        .map_or(DEFAULT_CACHE_BUDGET, |room| room.min(DEFAULT_CACHE_BUDGET)))
}

/// The brick caches' budget of each of `layers` volumes rendered together
/// (a scene), whose frames take `frames` bytes together with no cache
/// (the sum of each volume's [`frame_bytes`]): what the limit leaves
/// after them, shared evenly, each share at most the library's default
/// ([`DEFAULT_CACHE_BUDGET`]). The caches of several volumes live at
/// once, so one volume's [`cache_budget`] (the limit less its own frame)
/// would let them take the limit several times over. Whether the frames
/// fit at all is each front end's check, made before.
pub fn shared_cache_budget(frames: u128, layers: usize, limit: u64) -> usize {
    let room = u128::from(limit).saturating_sub(frames) / layers.max(1) as u128;
    usize::try_from(room).map_or(DEFAULT_CACHE_BUDGET, |room| room.min(DEFAULT_CACHE_BUDGET))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_caches_of_a_scene_share_what_its_frames_leave() {
        let mib = 1u64 << 20;
        // 100 MiB less 40 MiB of frames, among 3 volumes: 20 MiB each.
        assert_eq!(
            shared_cache_budget(40 * u128::from(mib), 3, 100 * mib),
            20 * mib as usize
        );
        // Never more than one volume's default, nor less than nothing.
        assert_eq!(shared_cache_budget(0, 1, u64::MAX), DEFAULT_CACHE_BUDGET);
        assert_eq!(shared_cache_budget(200 * u128::from(mib), 2, 100 * mib), 0);
    }
    use volray_options::{BlendMode, Options};

    /// The settings of `options` changed by `change` (the command line's
    /// defaults otherwise).
    fn settings(change: impl FnOnce(&mut Options)) -> RenderSettings {
        let mut options = Options::default();
        change(&mut options);
        volray_options::settings(&options).unwrap()
    }

    /// The bound for `settings` on an `f32` volume of `dims`, all bricks
    /// cached.
    fn bytes(settings: &RenderSettings, mode: NonFinite, dims: [usize; 3]) -> u128 {
        render_bytes(
            (dims, DVec3::ONE, SampleType::F32),
            settings,
            mode,
            usize::MAX,
        )
    }

    #[test]
    fn bounds_follow_the_paths_and_count_the_png() {
        let dims = [65, 65, 65];
        let voxels = 65u128.pow(3);
        let frame = 24 * 480 * 480;
        let refuse = NonFinite::Refuse;
        // Every brick occupied and lit: about 34 bytes a voxel, beside the volume.
        let bricked = bytes(&settings(|_| {}), refuse, dims);
        assert!((4 * voxels + 30 * voxels..4 * voxels + 40 * voxels).contains(&(bricked - frame)));
        // Post-classification: 16 bytes a voxel kept, 12 more while packing.
        let post = bytes(
            &settings(|o| o.look.post_classification = true),
            refuse,
            dims,
        );
        assert!(
            (32 * voxels + frame..32 * voxels + frame + 100_000).contains(&post),
            "{post}"
        );
        // A projection needs the frame twice over (values, then colours).
        let mip_settings = settings(|o| {
            o.look.blend = BlendMode::Mip;
            o.camera.size = (10, 20);
        });
        let mip = bytes(&mip_settings, refuse, dims);
        assert!(
            (4 * voxels + 40 * 200..4 * voxels + 40 * 200 + 50_000).contains(&mip),
            "{mip}"
        );
        // Non-finite values as empty space add a cleaned copy and a bit a voxel.
        let cleaned = bytes(&mip_settings, NonFinite::Transparent, dims);
        assert_eq!(
            cleaned - mip,
            4 * voxels + voxels.div_ceil(64) * 8 + 8u128.pow(3)
        );
        // The bricks' slots hold (9/8)^3 ≈ 1.42 of each voxel: 38 bytes a
        // voxel with the volume.
        let one = settings(|o| o.camera.size = (1, 1));
        let per_voxel = bytes(&one, refuse, [1025; 3]) as f64 / 1025f64.powi(3);
        assert!((38.0..39.0).contains(&per_voxel), "{per_voxel}");
    }

    #[test]
    fn the_caches_get_what_the_limit_leaves_up_to_the_default() {
        let settings = settings(|o| o.camera.size = (64, 64));
        let dims = [33, 33, 33];
        let volume = Volume::from_samples(dims, vec![7u16; 33 * 33 * 33]).unwrap();
        let grid = (dims, volume.spacing(), SampleType::U16);
        let without = render_bytes(grid, &settings, NonFinite::Refuse, 0) as u64;
        let budget = |limit: u64| Budget {
            limit,
            extra: png_bytes(&settings),
            samples_count: true,
        };
        let of = |settings: &RenderSettings, limit| {
            cache_budget(&volume, "v", settings, NonFinite::Refuse, budget(limit))
        };
        // Plenty of memory: the default budget.
        assert_eq!(of(&settings, 1 << 40).unwrap(), DEFAULT_CACHE_BUDGET);
        // A limit 100 kB above the frame's own needs: 100 kB of caches.
        assert_eq!(of(&settings, without + 100_000).unwrap(), 100_000);
        // Below them: refused, naming the need and the limit.
        let Err(AppError::OverBudget(over)) = of(&settings, without - 1) else {
            panic!("not refused")
        };
        assert_eq!(
            (over.need, over.limit, over.fast_need),
            (u128::from(without), u128::from(without - 1), None)
        );
        assert_eq!((over.dims, over.size), (dims, (64, 64)));
        // The reference path is dense (28 bytes a voxel more): refused
        // where the default path fits, saying what that takes.
        let reference = RenderSettings {
            method: Method::Reference,
            ..settings.clone()
        };
        let Err(AppError::OverBudget(over)) = of(&reference, without + 100_000) else {
            panic!("not refused")
        };
        assert_eq!(over.fast_need, Some(u128::from(without)));
        // Samples the caller owns (a numpy array's) do not count: the
        // room grows by the volume's bytes.
        let theirs = Budget {
            samples_count: false,
            ..budget(without + 100_000)
        };
        let room = cache_budget(&volume, "v", &settings, NonFinite::Refuse, theirs).unwrap();
        assert_eq!(room, 100_000 + 2 * 33 * 33 * 33);
    }
}
