//! A volume its owner may change between frames: a numpy array in a
//! notebook, written in a later cell (`a[...] = ...`) while its viewer is
//! shown. The viewer cannot see such a write (numpy keeps no count of
//! writes), so before each frame a tab asks the [`Watch`] for the volume
//! as it is now: the owner digests the samples (the Python module's
//! `digest.rs`) and, where they changed, prepares the volume again, the
//! new volume checked after the frame against the digest taken before
//! it. A write between frames is then rendered, and only a write during
//! a frame refused.

use volray_core::Volume;

/// The volume as its owner has it now, asked before each frame.
pub trait Watch: Send + Sync {
    /// `None` where the volume is that of `generation` (what the tab
    /// renders; 0 is the volume the viewer started with); else the
    /// volume now and its generation. `Err` with a one-line reason where
    /// it cannot be read.
    fn current(&self, generation: u64) -> Result<Option<(u64, Volume)>, String>;
}
