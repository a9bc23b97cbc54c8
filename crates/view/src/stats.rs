//! Counters the server keeps and `/api/status` reports: the tabs whose
//! renderers are alive, the frames being rendered, rendered, stopped (a
//! newer request superseded them) and refused (over the memory limit),
//! the requests dropped because a newer one replaced them, and the bytes
//! the memory ledger holds. Tests read them to see that a closed tab
//! frees its renderer and stops its frame, and that a burst is not
//! queued.

use crate::ledger::Ledger;
use serde::Serialize;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// The server's counters.
#[derive(Debug, Default)]
pub struct Stats {
    sessions: AtomicUsize,
    rendering: AtomicUsize,
    frames: AtomicU64,
    stopped: AtomicU64,
    refused: AtomicU64,
    dropped: AtomicU64,
}

/// The counters at one moment, as `/api/status` writes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Snapshot {
    /// Tabs whose renderer is alive.
    pub sessions: usize,
    /// Frames being rendered now.
    pub rendering: usize,
    /// Frames rendered and sent, by all tabs.
    pub frames: u64,
    /// Frames stopped before they were finished: superseded by a newer
    /// request, or their tab closed.
    pub stopped: u64,
    /// Frames refused because they did not fit the memory limit beside
    /// what the other tabs held.
    pub refused: u64,
    /// Requests replaced before they were rendered, by closed tabs.
    pub dropped: u64,
    /// Bytes the memory ledger holds (the volume, the tabs' renderers,
    /// the frames in flight), and its limit.
    pub memory_held: u64,
    pub memory_limit: u64,
}

/// Counts a frame as being rendered while it lives.
#[derive(Debug)]
pub struct Rendering<'a>(&'a Stats);

impl Drop for Rendering<'_> {
    fn drop(&mut self) {
        self.0.rendering.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Counts a tab's renderer while it lives.
#[derive(Debug)]
pub struct Open(Arc<Stats>);

impl Drop for Open {
    fn drop(&mut self) {
        self.0.sessions.fetch_sub(1, Ordering::SeqCst);
    }
}

impl Stats {
    /// Counts a renderer until the guard is dropped, if fewer than `max`
    /// are alive.
    pub fn open(self: &Arc<Self>, max: usize) -> Option<Open> {
        self.sessions
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| {
                (n < max).then_some(n + 1)
            })
            .ok()?;
        Some(Open(Arc::clone(self)))
    }

    /// Counts a frame as being rendered until the guard is dropped.
    pub fn rendering(&self) -> Rendering<'_> {
        self.rendering.fetch_add(1, Ordering::SeqCst);
        Rendering(self)
    }

    pub fn frame_rendered(&self) {
        self.frames.fetch_add(1, Ordering::Relaxed);
    }

    pub fn frame_stopped(&self) {
        self.stopped.fetch_add(1, Ordering::Relaxed);
    }

    pub fn frame_refused(&self) {
        self.refused.fetch_add(1, Ordering::Relaxed);
    }

    pub fn add_dropped(&self, n: u64) {
        self.dropped.fetch_add(n, Ordering::Relaxed);
    }

    pub fn sessions(&self) -> usize {
        self.sessions.load(Ordering::SeqCst)
    }

    pub fn frames(&self) -> u64 {
        self.frames.load(Ordering::Relaxed)
    }

    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    pub fn stopped(&self) -> u64 {
        self.stopped.load(Ordering::Relaxed)
    }

    /// The counters, and the ledger's bytes.
    pub fn snapshot(&self, ledger: &Ledger) -> Snapshot {
        let bytes = |b: u128| u64::try_from(b).unwrap_or(u64::MAX);
        Snapshot {
            sessions: self.sessions(),
            rendering: self.rendering.load(Ordering::SeqCst),
            frames: self.frames(),
            stopped: self.stopped(),
            refused: self.refused.load(Ordering::Relaxed),
            dropped: self.dropped(),
            memory_held: bytes(ledger.held()),
            memory_limit: bytes(ledger.limit()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_session_counts_while_its_guard_lives() {
        let stats = Arc::new(Stats::default());
        let a = stats.open(2).unwrap();
        let b = stats.open(2).unwrap();
        assert_eq!(stats.sessions(), 2);
        assert!(stats.open(2).is_none());
        drop(a);
        let rendering = stats.rendering();
        stats.frame_rendered();
        stats.frame_stopped();
        stats.frame_refused();
        stats.add_dropped(3);
        let ledger = Ledger::new(1000);
        let _held = ledger.reserve("x", 10).unwrap();
        assert_eq!(
            stats.snapshot(&ledger),
            Snapshot {
                sessions: 1,
                rendering: 1,
                frames: 1,
                stopped: 1,
                refused: 1,
                dropped: 3,
                memory_held: 10,
                memory_limit: 1000,
            }
        );
        drop(rendering);
        assert_eq!(stats.snapshot(&ledger).rendering, 0);
        drop(b);
        assert_eq!(stats.sessions(), 0);
    }
}
