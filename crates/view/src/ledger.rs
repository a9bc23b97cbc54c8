//! The server's memory ledger: one budget, the memory limit the viewer
//! was started with (`volray view --max-memory`), from which everything
//! that grows with the number of tabs or the size of their frames is
//! reserved before it is allocated and given back when it is dropped.
//!
//! | what | reserved | given back |
//! |---|---|---|
//! | the volume, unless mapped from its file | when the server binds | never |
//! | a tab's renderer: its brick caches up to their budget, the path's structures, a cleaned copy | when the tab opens | when its thread ends |
//! | a frame: its pixels, the 8-bit copy, the encoded file and the message | before it is rendered | the pixels once encoded, the message once sent |
//!
//! The bytes are volray-core's bounds ([`MemoryBound`]), the same the CLI
//! checks `render` against, so that eight tabs each saving a 4096² PNG
//! are held together within the limit: a frame that would exceed it is
//! refused with the reason, in the page, not queued.

use std::sync::{Arc, Mutex};
use volray_core::{MemoryBound, NonFinite, RenderSettings, Volume};
use volray_io::format_bytes;

/// Bytes a pixel beyond the rendered frame, until its message is sent:
/// the 8-bit RGB copy (3), the encoded file (PNG with fast compression
/// stores at worst the 3 bytes plus a filter byte a row and 5 bytes per
/// 64 KiB deflate block, under 4 a pixel; JPEG less) and the message that
/// copies the file behind its header (4 more).
pub const ENCODE_BYTES_PER_PIXEL: u128 = 3 + 4 + 4;

/// The frame's message beyond its pixels: the header's JSON (the command
/// and the transfer-function file are a few kilobytes) and the image
/// file's own headers.
const MESSAGE_OVERHEAD: u128 = 64 << 10;

/// A budget of bytes, shared by every tab.
#[derive(Debug)]
pub struct Ledger {
    limit: u128,
    held: Mutex<u128>,
}

/// Bytes taken from a [`Ledger`], given back when dropped.
#[derive(Debug)]
pub struct Reservation {
    ledger: Arc<Ledger>,
    bytes: u128,
}

/// A reservation refused: it and what is held exceed the limit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} needs up to {}, but the open tabs hold {} of the memory limit {}: wait for their frames, close a tab, or ask for a smaller frame",
    format_bytes(*.need),
    format_bytes(*.held),
    format_bytes(*.limit)
)]
pub struct Overdrawn {
    /// What was to be reserved ("a 4096x4096 frame").
    pub what: String,
    pub need: u128,
    pub held: u128,
    pub limit: u128,
}

impl Ledger {
    /// A ledger of `limit` bytes, none held.
    pub fn new(limit: u128) -> Arc<Ledger> {
        Arc::new(Ledger {
            limit,
            held: Mutex::new(0),
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, u128> {
        // A plain number: a panic elsewhere cannot leave it half written.
        self.held.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Reserves `bytes` for `what`, if they fit beside what is held.
    pub fn reserve(self: &Arc<Self>, what: &str, bytes: u128) -> Result<Reservation, Overdrawn> {
        let mut held = self.lock();
        if bytes > self.limit.saturating_sub(*held) {
            return Err(Overdrawn {
                what: what.to_string(),
                need: bytes,
                held: *held,
                limit: self.limit,
            });
        }
        *held += bytes;
        Ok(Reservation {
            ledger: Arc::clone(self),
            bytes,
        })
    }

    /// The bytes held now.
    pub fn held(&self) -> u128 {
        *self.lock()
    }

    /// The limit.
    pub fn limit(&self) -> u128 {
        self.limit
    }
}

impl Reservation {
    /// The bytes reserved.
    pub fn bytes(&self) -> u128 {
        self.bytes
    }

    /// Moves up to `bytes` of this reservation into a new one (to be
    /// given back separately).
    pub fn split_off(&mut self, bytes: u128) -> Reservation {
        let bytes = bytes.min(self.bytes);
        self.bytes -= bytes;
        Reservation {
            ledger: Arc::clone(&self.ledger),
            bytes,
        }
    }
}

impl Drop for Reservation {
    fn drop(&mut self) {
        *self.ledger.lock() -= self.bytes;
    }
}

/// What the viewer's memory is made of, from volray-core's bounds.
#[derive(Debug, Clone, Copy)]
pub struct Costs {
    /// The volume's samples held in memory (0 when mapped from its file:
    /// its pages are the operating system's to drop).
    pub volume: u128,
    /// A tab's renderer with the starting view's settings: the path's
    /// structures with the brick caches at their budget, and the cleaned
    /// copy of the volume where non-finite values are rendered as empty.
    pub tab: u128,
    non_finite: NonFinite,
    cache_budget: usize,
}

impl Costs {
    /// The costs of serving `volume`, whose tabs render with
    /// `cache_budget` bytes of brick caches and start from `start`.
    pub fn new(
        volume: &Volume,
        start: &RenderSettings,
        non_finite: NonFinite,
        cache_budget: usize,
    ) -> Costs {
        let bound = MemoryBound::for_volume(volume, start, non_finite, cache_budget);
        let volume_bytes = if volume.samples().is_external() {
            0
        } else {
            bound.volume
        };
        Costs {
            volume: volume_bytes,
            tab: bound.cleaned + bound.path,
            non_finite,
            cache_budget,
        }
    }

    /// [`Self::new`], with the brick caches' budget lowered (and returned)
    /// where the volume, one tab and the starting view's frame would not
    /// fit `limit` together: the caches give way to the frame, as in
    /// `volray render`. Where even no cache is not enough, the budget is
    /// left as given and the frame will be refused with the reason.
    pub fn fitting(
        volume: &Volume,
        start: &RenderSettings,
        non_finite: NonFinite,
        cache_budget: usize,
        limit: u128,
    ) -> (Costs, usize) {
        let costs = Costs::new(volume, start, non_finite, cache_budget);
        let need = costs.volume + costs.tab + costs.frame(volume, start).0;
        let over = need.saturating_sub(limit);
        if over == 0 {
            return (costs, cache_budget);
        }
        // What the caches can give: their bound at this budget over none.
        let uncached = Costs::new(volume, start, non_finite, 0).tab;
        let cached = costs.tab - uncached.min(costs.tab);
        if over > cached {
            return (costs, cache_budget);
        }
        let budget = usize::try_from(cached - over).unwrap_or(cache_budget);
        (Costs::new(volume, start, non_finite, budget), budget)
    }

    /// What a frame of `settings` adds to its tab's renderer until it is
    /// sent: its pixels, encoding and message, and the part of its path's
    /// structures beyond what the tab reserved (a frame on another path
    /// than the starting view's). The second number is the message's
    /// part, held until the socket has sent it.
    pub fn frame(&self, volume: &Volume, settings: &RenderSettings) -> (u128, u128) {
        let bound = MemoryBound::for_volume(volume, settings, self.non_finite, self.cache_budget);
        self.frame_of(&bound, settings, self.tab)
    }

    /// [`Self::frame`] for a frame whose volume's bound is `bound`, its
    /// renderer's structures `reserved` already.
    pub fn frame_of(
        &self,
        bound: &MemoryBound,
        settings: &RenderSettings,
        reserved: u128,
    ) -> (u128, u128) {
        let pixels = settings.width as u128 * settings.height as u128;
        let message = 4 * pixels + MESSAGE_OVERHEAD;
        let path = (bound.cleaned + bound.path).saturating_sub(reserved);
        (
            bound.frame + path + ENCODE_BYTES_PER_PIXEL * pixels + MESSAGE_OVERHEAD,
            message,
        )
    }

    /// What a frame rendered piece by piece adds beyond its pieces'
    /// budget: the finished image (32 bytes a pixel at most, a
    /// projection's), its encoding and message.
    pub fn pieces_frame(&self, settings: &RenderSettings) -> (u128, u128) {
        let pixels = settings.width as u128 * settings.height as u128;
        let message = 4 * pixels + MESSAGE_OVERHEAD;
        (
            (32 + ENCODE_BYTES_PER_PIXEL) * pixels + MESSAGE_OVERHEAD,
            message,
        )
    }

    /// How non-finite values are rendered, and each renderer's brick
    /// caches' budget.
    pub fn non_finite(&self) -> NonFinite {
        self.non_finite
    }

    pub fn cache_budget(&self) -> usize {
        self.cache_budget
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reservations_fit_under_the_limit_and_are_given_back_when_dropped() {
        let ledger = Ledger::new(100);
        let a = ledger.reserve("a", 60).unwrap();
        let refused = ledger.reserve("a 10x10 frame", 41).unwrap_err();
        assert_eq!((refused.need, refused.held, refused.limit), (41, 60, 100));
        assert!(
            refused.to_string().starts_with(
                "a 10x10 frame needs up to 41 bytes, but the open tabs hold 60 bytes of the memory limit 100 bytes"
            ),
            "{refused}"
        );
        let mut b = ledger.reserve("b", 40).unwrap();
        assert_eq!(ledger.held(), 100);
        let part = b.split_off(30);
        assert_eq!((b.bytes(), part.bytes()), (10, 30));
        drop(b);
        assert_eq!(ledger.held(), 90);
        drop(part);
        drop(a);
        assert_eq!(ledger.held(), 0);
        assert!(ledger.reserve("all", 100).is_ok());
        assert_eq!(ledger.held(), 0);
    }

    #[test]
    fn a_frame_costs_its_pixels_encoding_and_message() {
        use volray_core::glam::DVec3;
        let volume = Volume::from_fn([9, 9, 9], DVec3::ONE, DVec3::ZERO, |_| 0.0).unwrap();
        let start = RenderSettings::default();
        let costs = Costs::new(&volume, &start, NonFinite::Refuse, 1 << 20);
        assert_eq!(costs.volume, 9 * 9 * 9 * 4);
        assert!(costs.tab > 0);
        let big = RenderSettings {
            width: 4096,
            height: 4096,
            ..start
        };
        let (frame, message) = costs.frame(&volume, &big);
        let pixels = 4096u128 * 4096;
        // 16 bytes a pixel rendered, 11 to encode and send, and the
        // path's per-frame lists of a frame larger than the start's.
        assert!(frame >= 27 * pixels && frame < 30 * pixels, "{frame}");
        assert!(message >= 4 * pixels && message < frame);
    }
}
