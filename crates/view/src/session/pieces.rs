//! A pyramid level rendered piece by piece (volray-distributed's
//! `Streamed`), in pieces that fit what the memory limit has left; kept
//! between stills, so that what it learnt of its pieces (their value
//! ranges) serves the next.

use super::FrameError;
use super::render::Context;
use crate::ledger::Reservation;
use crate::levels::LevelError;
use crate::protocol::LevelShown;
use crate::pyramid::Pyramid;
use std::sync::Arc;
use volray_core::{FrameRequest, Image, Render, RenderSettings};
use volray_distributed::streamed::{StreamError, Streamed};
/// A level rendered piece by piece, with its budget: kept so that what
/// it learnt of its pieces (their value ranges) serves the next still.
#[derive(Default)]
pub(super) struct Pieces {
    streamed: Option<(usize, u64, Streamed)>,
}

impl Pieces {
    /// A frame of level `level` rendered piece by piece, in pieces that
    /// fit what the memory limit has left (at most
    /// [`volray_lazy::PIECE_BUDGET`]).
    pub(super) fn render(
        &mut self,
        cx: &Context,
        pyramid: &Pyramid,
        level: usize,
        settings: &RenderSettings,
    ) -> Result<(Image, LevelShown, Reservation, u128), FrameError> {
        let non_finite = cx.costs.non_finite();
        let (extra, message_bytes) = cx.costs.pieces_frame(settings);
        let free = (cx.ledger.limit())
            .saturating_sub(cx.ledger.held())
            .saturating_sub(extra);
        let budget = u64::try_from(free)
            .unwrap_or(u64::MAX)
            .min(volray_lazy::PIECE_BUDGET);
        let keep = matches!(&self.streamed, Some((l, b, _)) if *l == level && *b <= budget);
        if !keep {
            let source = Arc::clone(pyramid.source(level));
            let streamed = Streamed::new(source, non_finite, budget).with_labels(pyramid.labels());
            self.streamed = Some((level, budget, streamed));
        }
        let (_, budget, streamed) = self.streamed.as_mut().expect("set above");
        let reserved = cx.ledger.reserve(cx.what, extra + u128::from(*budget))?;
        let rendered = {
            let _rendering = cx.stats.rendering();
            cx.pool
                .install(|| streamed.render(FrameRequest::new(settings).stopped_by(cx.stop)))
                .map(volray_core::Rendered::image_and_times)
        };
        let [x, y, z] = pyramid.grid(level).dims;
        let (image, times) = rendered.map_err(|e| match e {
            StreamError::Render(e) => FrameError::Render(e),
            StreamError::Read(m) => FrameError::Level(LevelError::Read(m)),
            StreamError::TooLarge(m) => FrameError::Pieces(format!(
                "level {level} ({x}x{y}x{z}) in pieces: {m}: wait for the other tabs' frames, or raise --max-memory"
            )),
        })?;
        let shown = LevelShown {
            index: level,
            count: pyramid.len(),
            dims: [x, y, z],
            pieces: times.pieces,
            read: times.read_pieces,
        };
        Ok((image, shown, reserved, message_bytes))
    }
}
