//! A volume's renderer within the memory budget, as the command line
//! builds one for the frames it writes (`volray render`, its animations,
//! `bench`, `view`): the input's non-finite values refused or rendered as
//! empty space, the frame refused if it may take more than the memory
//! limit even with no brick cache, and the brick caches given what is left
//! ([`crate::memory::cache_budget`]: the volume counted unless mapped, and
//! the 16-bit PNG's pixels). The Python module budgets its own renderers
//! (no PNG is written there).

use crate::AppError;
use crate::input::Input;
use crate::memory::{Budget, png_bytes};
use volray_core::{NonFinite, RenderSettings, Renderer};

/// The brick caches' budget for rendering `input` with `settings`, its
/// non-finite values as `non_finite` says.
pub fn cache_budget(
    input: &Input,
    settings: &RenderSettings,
    non_finite: NonFinite,
) -> Result<usize, AppError> {
    let mode = input.non_finite(non_finite);
    let budget = Budget {
        limit: input.max_memory,
        extra: png_bytes(settings),
        samples_count: true,
    };
    crate::memory::cache_budget(&input.volume, &input.name, settings, mode, budget)
}

/// The renderer of `input`'s volume for frames of `settings`, refused
/// ([`AppError::OverBudget`]) if rendering it may need more than the
/// memory limit, or ([`AppError::Render`]) for its non-finite values
/// unless `non_finite` renders them as empty space.
pub fn renderer_for<'v>(
    input: &'v Input,
    settings: &RenderSettings,
    non_finite: NonFinite,
) -> Result<Renderer<'v>, AppError> {
    let budget = cache_budget(input, settings, non_finite)?;
    let mode = input.non_finite(non_finite);
    let renderer =
        Renderer::with_non_finite(&input.volume, mode).map_err(|error| AppError::Render {
            name: input.name.clone(),
            error,
        })?;
    Ok(renderer.with_cache_budget(budget))
}

/// The renderers of volumes rendered together (a scene: `layers`, each
/// an input and its settings, the renderers built by [`renderer_for`]),
/// their brick caches sharing what the limit leaves after every volume's
/// frame and the one 16-bit PNG ([`crate::memory::shared_cache_budget`]):
/// each volume's own budget counts only its own frame, and their caches
/// live at once.
pub fn share_caches<'v>(
    renderers: Vec<Renderer<'v>>,
    layers: &[(&Input, &RenderSettings)],
    non_finite: NonFinite,
) -> Vec<Renderer<'v>> {
    let Some(&(first, first_settings)) = layers.first() else {
        return renderers;
    };
    let budget = Budget {
        limit: first.max_memory,
        extra: 0,
        samples_count: true,
    };
    let frames: u128 = (layers.iter())
        .map(|(input, settings)| {
            let mode = input.non_finite(non_finite);
            crate::memory::frame_bytes(&input.volume, settings, mode, &budget)
        })
        .sum::<u128>()
        + png_bytes(first_settings);
    let share = crate::memory::shared_cache_budget(frames, layers.len(), first.max_memory);
    (renderers.into_iter())
        .map(|r| {
            let budget = r.cache_budget().min(share);
            r.with_cache_budget(budget)
        })
        .collect()
}
