//! A frame's progress, told and asked: the casters report the pixels they
//! finish after each tile or row ([`Progress::done`]), and ask before
//! each whether the frame was stopped ([`Progress::stopped`]), the
//! bricked caster also between the bricks of a tile: a caller that sets
//! the stop flag (Ctrl-C in Python, a newer frame in the viewer) gets its
//! thread back within one tile's work (one brick's on the bricked path),
//! about a millisecond at the usual steps, and the renderer answers
//! [`RenderError::Stopped`](crate::RenderError::Stopped). A stopped frame
//! leaves the renderer's caches as they were: each brick is lit or not,
//! never half.

use std::sync::atomic::{AtomicBool, Ordering};

/// What a frame reports to and asks of its caller.
#[derive(Clone, Copy)]
pub struct Progress<'a> {
    report: &'a (dyn Fn(usize) + Sync),
    stop: Option<&'a AtomicBool>,
}

impl<'a> Progress<'a> {
    /// Reports finished pixels to `report`; never stopped.
    pub fn new(report: &'a (dyn Fn(usize) + Sync)) -> Self {
        Progress { report, stop: None }
    }

    /// The same, stopped once `stop` is set.
    pub fn stopping(self, stop: &'a AtomicBool) -> Self {
        Progress {
            stop: Some(stop),
            ..self
        }
    }

    /// `pixels` more are finished.
    #[inline]
    pub fn done(&self, pixels: usize) {
        (self.report)(pixels)
    }

    /// Whether the frame was stopped: the casters skip the work left.
    #[inline]
    pub fn stopped(&self) -> bool {
        // Relaxed: the flag carries no data; a tile that misses the store
        // by a moment only finishes its own work.
        self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }
}
