//! # volray-app: what the front ends share above the renderer
//!
//! volray has three front ends: the command line (`volray render`, `view`,
//! `bench`, ...), the Python module (`import volray`) and the browser viewer
//! (`volray view`, volray-view). Each takes its user's words in its own
//! syntax; everything they decide the same way lives here, once:
//!
//! - opening an input by spec (a file, a built-in source) and planning it:
//!   whole, mapped or chunked, which level, in how many pieces;
//! - assembling scenes: channels, overlays, time;
//! - the memory budget;
//! - the camera and transfer-function state, and its reproduction as
//!   `volray render` words and as Python keywords (one model, two spellings);
//! - MPI orchestration.
//!
//! A front end keeps only its syntax (flags, keywords, page messages), its
//! output writing and its progress display.

pub mod reproduce;
pub mod scene;
pub mod words;
