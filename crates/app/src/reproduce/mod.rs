//! The view's state and its reproduction: one model, two spellings.
//!
//! The model is the viewer page's state ([`state::ViewState`]: the
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
//!   Python code (the notebook viewer's), from the options
//!   [`options::state_options`] reads from the state.
//!
//! Beside them: [`options`] (the state a viewer starts in, from the
//! options; the options a state says) and [`viewer`] (what the viewer asks
//! of a front end: the [`viewer::Reproduce`] hook, which the command line
//! implements with its flags' parser). volray-view serves the state and
//! re-exports these under its own names.

pub mod command;
pub mod keywords;
pub mod options;
pub mod state;
pub mod viewer;
