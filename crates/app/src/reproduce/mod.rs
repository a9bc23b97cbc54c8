//! The view's state and its reproduction: one model, two spellings.
//!
//! The model is the viewer page's state (volray-view's `ViewState`: the
//! camera, the window, opacity points and colours, the look, the
//! figure) read against the options a viewer was started with
//! (volray-options' `Options`, which the command line's flags and the
//! Python module's keywords both become). It is spelled twice, each
//! spelling once:
//!
//! - [`command`]: as `volray render` words (`volray view`'s Command box);
//!   the command line parses them back with its own flags' parser, so
//!   that the frame the page shows is the command's;
//! - [`keywords`]: as the keywords of `volray.render` and the call as
//!   Python code (the notebook viewer's), from the options volray-view's
//!   `state_options` reads from the state.

pub mod command;
pub mod keywords;
