//! A tab's drafts: a quick draft before a still slow to render
//! ([`SLOW_STILL_MS`]), and a large volume's drafts drawn from a coarse
//! copy of it (`coarse.rs`), made after the tab's first still is sent (or
//! on its first draft) and kept with the tab's renderer, its bytes
//! reserved from the ledger.

use super::render::Context;
use super::{Source, Tab};
use crate::coarse;
use crate::ledger::Reservation;
use crate::protocol::{DRAFT_SCALE_RANGE, Quality, Request};
use std::sync::atomic::AtomicBool;
use volray_core::{MemoryBound, RenderSettings, Renderer, Volume};

/// A tab's coarse copy of its volume for the drafts (`coarse.rs`), made
/// after the first still or on the first draft that takes it, and kept
/// with the tab's renderer.
// One per tab: the sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub(super) enum DraftCopy {
    NotYet,
    /// The copy's renderer, its smallest spacing over the volume's, and
    /// the bytes reserved for it (its samples and its renderer's
    /// structures, its brick caches at an eighth of the tab's budget).
    Made {
        renderer: Renderer<'static>,
        ratio: f64,
        _reserved: Reservation,
    },
    /// It did not fit what the memory limit has left: the drafts come
    /// from the volume, as for a small one.
    Refused,
}

impl DraftCopy {
    /// The copy's renderer and spacing ratio for a draft of `settings`
    /// of `renderer`'s volume, made now if it is the first; `None` where
    /// the drafts come from the volume itself.
    pub(super) fn renderer(
        &mut self,
        cx: &Context,
        renderer: &Renderer,
        settings: &RenderSettings,
        above: usize,
    ) -> Option<(&Renderer<'static>, f64)> {
        let volume = renderer.volume();
        if volume.len() <= above || !coarse::drafts_from_copy(volume, settings) {
            return None;
        }
        if let DraftCopy::NotYet = self {
            *self = Self::make(cx, volume, settings).unwrap_or(DraftCopy::Refused);
        }
        match self {
            DraftCopy::Made {
                renderer, ratio, ..
            } => Some((renderer, *ratio)),
            _ => None,
        }
    }

    fn make(cx: &Context, volume: &Volume, settings: &RenderSettings) -> Option<DraftCopy> {
        let copy = cx.pool.install(|| coarse::halved(volume));
        let ratio = coarse::spacing_ratio(volume, &copy);
        let budget = cx.costs.cache_budget() / 8;
        let non_finite = cx.costs.non_finite();
        let bound = MemoryBound::for_volume(&copy, settings, non_finite, budget);
        let reserved = (cx.ledger)
            .reserve(
                "the drafts' coarse copy of the volume",
                bound.volume + bound.cleaned + bound.path,
            )
            .ok()?;
        let renderer = Renderer::owning(copy, non_finite).ok()?;
        Some(DraftCopy::Made {
            renderer: renderer.with_cache_budget(budget),
            ratio,
            _reserved: reserved,
        })
    }
}

/// A still that took longer than this to render is preceded by a quick
/// frame ([`Tab::quick`]) the next time.
pub const SLOW_STILL_MS: f64 = 300.0;

/// What a quick frame aims to take.
const QUICK_MS: f64 = 80.0;

impl Tab<'_> {
    /// After the still `request` was sent: the drafts' coarse copy made
    /// now, while the page shows the still, rather than on the first
    /// draft of a drag, which would wait for it (0.08 s for 257³ voxels,
    /// 0.7 s for 512³ on two busy cores). A request that comes meanwhile
    /// waits as long.
    pub(super) fn prepare_drafts(&mut self, request: &Request) {
        let Source::Whole { renderer, copy, .. } = &mut self.source else {
            return;
        };
        let small = renderer.volume().len() <= self.copy_above;
        if self.time.is_some() || small || !matches!(copy, DraftCopy::NotYet) {
            return;
        }
        let Ok(reproduction) = self.reproduce.reproduce(&request.state) else {
            return;
        };
        let never = AtomicBool::new(false);
        let cx = Context {
            pool: self.pool,
            stats: self.stats,
            ledger: self.ledger,
            costs: self.costs,
            stop: &never,
            what: "the drafts' copy",
        };
        copy.renderer(&cx, renderer, &reproduction.settings, self.copy_above);
    }

    /// A quick draft of the still `request` asks for, where the last still
    /// took longer than [`SLOW_STILL_MS`]: its scale aims at [`QUICK_MS`]
    /// (the time goes with the pixels, the square of the scale).
    pub(super) fn quick(&self, request: &Request) -> Option<Request> {
        quick_request(self.last_still_ms, request)
    }
}

/// [`Tab::quick`], for a tab whose last still took `last_still_ms`.
pub(super) fn quick_request(last_still_ms: Option<f64>, request: &Request) -> Option<Request> {
    let last = last_still_ms?;
    if request.quality != Quality::Full || last <= SLOW_STILL_MS {
        return None;
    }
    let (lo, hi) = DRAFT_SCALE_RANGE;
    Some(Request {
        quality: Quality::Draft,
        draft_scale: (QUICK_MS / last).sqrt().clamp(lo, hi),
        ..request.clone()
    })
    .filter(|_| request.probe.is_none())
}

/// A side of `full` pixels at `scale`, at least one pixel.
pub(super) fn scaled(full: usize, scale: f64) -> usize {
    ((full as f64 * scale).round() as usize).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::encode;
    use crate::mailbox::{Mailbox, Slot};
    use crate::reproduce::Reproduce;
    use crate::session::tests::{Plain, one_frame, pixels, request, shared};
    use crate::session::{Outgoing, spawn};
    use std::sync::Arc;
    use tokio::sync::mpsc;
    use volray_core::{FrameRequest, Render};

    #[test]
    fn a_large_volumes_drafts_come_from_its_coarse_copy_and_its_still_from_the_volume() {
        for large in [false, true] {
            let mut shared = shared();
            // The 17³ volume counts as large, or not.
            shared.copy_above = if large { 0 } else { usize::MAX };
            let mailbox = Arc::new(Mailbox::default());
            let (tx, mut rx) = mpsc::channel(1);
            spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
            let tab = shared.ledger.held();
            let (h, _) = one_frame(&mailbox, &mut rx, request(1, Quality::Draft, 64, 30.0));
            assert_eq!(
                (h["quality"].as_str(), h["width"].as_u64()),
                (Some("draft"), Some(32))
            );
            // The copy (9³ voxels and its renderer) is held with the tab.
            let copy = shared.ledger.held() - tab;
            assert_eq!(
                copy > 9 * 9 * 9 * 4,
                large,
                "{copy} bytes held beside the tab"
            );
            // The still after it is the volume's own frame, pixel for
            // pixel, as the Command box reproduces it.
            let still = request(2, Quality::Full, 64, 30.0);
            let settings = Plain::default().reproduce(&still.state).unwrap().settings;
            let want = Renderer::new(&shared.volume)
                .unwrap()
                .render(FrameRequest::new(&settings))
                .unwrap()
                .image();
            let (h, png) = one_frame(&mailbox, &mut rx, still);
            assert_eq!(h["quality"], "full");
            let want = encode::png(&want, &mut Vec::new()).unwrap();
            assert!(pixels(&png) == pixels(&want), "large: {large}");
            // A second draft uses the copy made for the first.
            one_frame(&mailbox, &mut rx, request(3, Quality::Draft, 64, 40.0));
            assert_eq!(shared.ledger.held(), tab + copy);
            mailbox.close();
            assert!(rx.blocking_recv().is_none());
            assert_eq!(shared.ledger.held(), 0, "given back with the tab");

            // A tab whose first frame is a still makes the copy after
            // sending it, before any draft: once a probe that follows is
            // answered, it is held.
            let mailbox = Arc::new(Mailbox::default());
            let (tx, mut rx) = mpsc::channel(1);
            spawn(&shared, Arc::clone(&mailbox), tx).unwrap();
            one_frame(&mailbox, &mut rx, request(4, Quality::Full, 64, 30.0));
            let mut probe = request(5, Quality::Full, 64, 30.0);
            probe.probe = Some([32, 32]);
            mailbox.put(Slot::Probe, probe);
            assert!(matches!(rx.blocking_recv(), Some(Outgoing::Text(_))));
            // (Its renderer's bound is the still's here, the draft's above.)
            let held = shared.ledger.held() - tab;
            assert_eq!(
                held > 9 * 9 * 9 * 4,
                large,
                "{held} bytes held beside the tab"
            );
            mailbox.close();
            assert!(rx.blocking_recv().is_none());
            assert_eq!(shared.ledger.held(), 0);
        }
    }

    #[test]
    fn a_slow_still_is_preceded_by_a_quick_draft_scaled_to_its_time() {
        let full = request(7, Quality::Full, 480, 0.0);
        assert_eq!(quick_request(None, &full), None, "no still yet");
        assert_eq!(quick_request(Some(SLOW_STILL_MS), &full), None, "not slow");
        let draft = request(7, Quality::Draft, 480, 0.0);
        assert_eq!(
            quick_request(Some(2000.0), &draft),
            None,
            "drafts are quick"
        );
        // 4x QUICK_MS: half the side, a quarter of the pixels and time.
        let quick = quick_request(Some(4.0 * QUICK_MS), &full).unwrap();
        assert_eq!((quick.seq, quick.quality), (7, Quality::Draft));
        assert!((quick.draft_scale - 0.5).abs() < 1e-12);
        assert_eq!(quick.state, full.state);
        // Never below 1/16 a side.
        let slowest = quick_request(Some(1e9), &full).unwrap();
        assert_eq!(slowest.draft_scale, DRAFT_SCALE_RANGE.0);
        assert_eq!((scaled(480, 1.0 / 16.0), scaled(1, 1.0 / 16.0)), (30, 1));
    }
}
