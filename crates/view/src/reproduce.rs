//! From a [`ViewState`] to the frame's [`RenderSettings`] and the command
//! that renders the same frame without the viewer.
//!
//! The viewer does not build settings itself: whoever starts it (the
//! `volray` binary) supplies a [`Reproduce`], which writes the state as a
//! command line and builds the settings from that command line, so that
//! the frame the page shows and the command it prints are the same frame
//! by construction. This crate knows nothing of flags.

use crate::state::ViewState;
use volray_core::RenderSettings;

/// A state made ready to render, and how to render it again.
#[derive(Debug, Clone, PartialEq)]
pub struct Reproduction {
    /// What the frame is rendered with.
    pub settings: RenderSettings,
    /// The command that renders the same frame, as one line.
    pub command: String,
    /// The transfer-function file the command names, if it names one:
    /// its name and its JSON text.
    pub tf_file: Option<(String, String)>,
}

/// A state that cannot be rendered, in one line the page shows.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct Refusal(pub String);

/// Turns page states into settings and commands.
pub trait Reproduce: Send + Sync {
    /// The settings and the command of a checked `state`.
    fn reproduce(&self, state: &ViewState) -> Result<Reproduction, Refusal>;
}
