//! From a [`ViewState`] to the frame's [`RenderSettings`] and the command
//! that renders the same frame without the viewer.
//!
//! The viewer does not build settings itself: whoever starts it (the
//! `volray` binary) supplies a [`Reproduce`], which writes the state as a
//! command line and builds the settings from that command line, so that
//! the frame the page shows and the command it prints are the same frame
//! by construction. This crate knows nothing of flags.

use super::state::ViewState;
use volray_core::RenderSettings;
use volray_core::scene::{Look, Mix};

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
    /// A scene's other volumes (`ViewState::layers`): their looks, the
    /// files their options name, and the mix; `None` for one volume.
    pub scene: Option<SceneLooks>,
}

/// The looks of a scene's volumes after the first (whose look is
/// [`Reproduction::settings`]'), as the command sets them.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneLooks {
    pub looks: Vec<Look>,
    pub mix: Mix,
    /// The transfer-function files the command's `--overlay` options
    /// name: name and JSON.
    pub tf_files: Vec<(String, String)>,
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
