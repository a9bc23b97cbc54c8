//! A tab's part of a pyramid (`pyramid.rs`, `levels.rs`): the level a
//! frame shows (the drafts' coarse level, the still's level), and the
//! renderers of the levels it holds whole (at most two, the last used
//! kept); a level too large for what the memory limit has left is
//! rendered in pieces (`pieces.rs`).

use super::FrameError;
use super::pieces::Pieces;
use super::render::{Context, Drawn, basis_of};
use crate::ledger::Reservation;
use crate::levels::Levels;
use crate::protocol::{LevelShown, Quality};
use std::sync::Arc;
use volray_core::camera::View;
use volray_core::{Image, RenderError, RenderSettings, Renderer};

/// A tab's part of a pyramid: its renderers of the levels held whole and
/// the still's level rendered piece by piece.
pub(super) struct LevelTab {
    pub(super) levels: Arc<Levels>,
    /// Renderers of levels held whole, the last used last, with the
    /// bytes reserved for their structures; at most two (the drafts' and
    /// the still's level).
    pub(super) renderers: Vec<(usize, Renderer<'static>, Reservation)>,
    /// A level rendered piece by piece (`pieces.rs`).
    pub(super) streamed: Pieces,
}

impl LevelTab {
    /// A frame of `settings` (the full-size frame's `full`): a draft from
    /// a coarse level held whole, a still from the level it needs, whole
    /// if it fits what the memory limit has left, else in pieces; either
    /// framed on the still's level's box.
    pub(super) fn draw(
        &mut self,
        cx: &Context,
        quality: Quality,
        full: &RenderSettings,
        settings: &RenderSettings,
    ) -> Result<Drawn, FrameError> {
        let levels = Arc::clone(&self.levels);
        let pyramid = &levels.pyramid;
        let non_finite = cx.costs.non_finite();
        settings.validate().map_err(RenderError::from)?;
        let still = pyramid.still_level(full)?;
        let grid = pyramid.grid(still);
        let basis = basis_of(&View::frame(
            &full.camera,
            grid.bounds(),
            full.width,
            full.height,
        )?);
        let limit = cx.ledger.limit();
        let (level, whole) = match quality {
            Quality::Draft => match pyramid.draft_level(settings, still, non_finite, limit)? {
                Some(level) => (level, true),
                // Even the coarsest level is too large to hold: in pieces.
                None => (pyramid.len() - 1, false),
            },
            Quality::Full | Quality::Save => {
                let (extra, _) = cx.costs.pieces_frame(settings);
                let held = if levels.is_held(still) {
                    pyramid.volume_bytes(still)
                } else {
                    0
                };
                let need =
                    (pyramid.whole_bytes(still, settings, non_finite) + extra).saturating_sub(held);
                let free = limit.saturating_sub(cx.ledger.held());
                (still, need <= free)
            }
        };
        // Whichever level it shows, the frame is framed as the still
        // (`Pyramid::framed`): no jump when the still replaces the drafts.
        let framed = pyramid.framed(settings, still);
        let (image, shown, reserved, message_bytes) = if whole {
            self.whole(cx, level, &framed)?
        } else {
            self.streamed.render(cx, pyramid, level, &framed)?
        };
        Ok(Drawn {
            image,
            basis,
            level: Some(shown),
            reserved,
            message_bytes,
        })
    }

    /// A frame of level `level` held whole.
    fn whole(
        &mut self,
        cx: &Context,
        level: usize,
        settings: &RenderSettings,
    ) -> Result<(Image, LevelShown, Reservation, u128), FrameError> {
        let levels = &self.levels;
        let pyramid = &levels.pyramid;
        let non_finite = cx.costs.non_finite();
        let cache_budget = cx.costs.cache_budget();
        let read = usize::from(!levels.is_held(level));
        let index = match self.renderers.iter().position(|(l, ..)| *l == level) {
            Some(i) => i,
            None => {
                // This tab lets go of its renderers of other levels but
                // the last one used (the drafts' or the still's).
                let over = self.renderers.len().saturating_sub(1);
                self.renderers.drain(..over);
                let volume = levels.whole(level, cx.ledger)?;
                let bound = pyramid.bound(level, settings, non_finite, cache_budget);
                let what = format!("a renderer of level {level}");
                let structures = cx.ledger.reserve(&what, bound.cleaned + bound.path)?;
                let renderer =
                    Renderer::owning(volume, non_finite)?.with_cache_budget(cache_budget);
                self.renderers.push((level, renderer, structures));
                self.renderers.len() - 1
            }
        };
        let entry = self.renderers.remove(index);
        self.renderers.push(entry);
        let (_, renderer, structures) = self.renderers.last().expect("pushed above");
        let bound = pyramid.bound(level, settings, non_finite, cache_budget);
        let (bytes, message_bytes) = cx.costs.frame_of(&bound, settings, structures.bytes());
        let reserved = cx.ledger.reserve(cx.what, bytes)?;
        let image = cx.render(renderer, settings)?;
        let shown = LevelShown {
            index: level,
            count: pyramid.len(),
            dims: pyramid.grid(level).dims,
            pieces: 1,
            read,
        };
        Ok((image, shown, reserved, message_bytes))
    }
}
