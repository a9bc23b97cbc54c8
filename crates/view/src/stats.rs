//! Counters the server keeps and `/api/status` reports: the tabs whose
//! renderers are alive, the frames rendered, and the requests dropped
//! because a newer one replaced them. Tests read them to see that a
//! closed tab frees its renderer and that a burst is not queued.

use serde::Serialize;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// The server's counters.
#[derive(Debug, Default)]
pub struct Stats {
    sessions: AtomicUsize,
    frames: AtomicU64,
    dropped: AtomicU64,
}

/// The counters at one moment, as `/api/status` writes them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Snapshot {
    /// Tabs whose renderer is alive.
    pub sessions: usize,
    /// Frames rendered and sent, by all tabs.
    pub frames: u64,
    /// Requests replaced before they were rendered, by closed tabs.
    pub dropped: u64,
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

    pub fn frame_rendered(&self) {
        self.frames.fetch_add(1, Ordering::Relaxed);
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

    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            sessions: self.sessions(),
            frames: self.frames(),
            dropped: self.dropped(),
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
        stats.frame_rendered();
        stats.add_dropped(3);
        assert_eq!(
            stats.snapshot(),
            Snapshot {
                sessions: 1,
                frames: 1,
                dropped: 3
            }
        );
        drop(b);
        assert_eq!(stats.sessions(), 0);
    }
}
