//! Movies: `volray render --keyframes FILE`'s camera and look paths.
//!
//! A keyframes file (JSON, its schema in `docs/movies.md`) gives, at times
//! `t` in seconds, any of `volray render`'s options under the flag's name
//! (`look_at` for `--look-at`), each holding until a later keyframe
//! changes it. Here the file is read into the very option structs the
//! flags produce (volray-options' [`Options`](volray_options::Options),
//! [`schema`]), the values between keyframes are interpolated
//! ([`interpolate`]: orbits, quaternions, values, colours in OKLab,
//! [`color`]), and the frames are planned ([`plan`]: frame `k` shows the
//! time `k / fps`, the data's time point held or blended, a part `A:B`).
//! A front end turns each frame's options into settings with
//! `volray_options::settings`, so a keyframe means exactly what the flags
//! mean, and renders and encodes the frames (volray-io's `ffmpeg` or
//! `Animation`), keeping finished ones in a work folder to resume
//! ([`work`]).

pub mod color;
pub mod interpolate;
pub mod plan;
pub mod schema;
pub mod time;
pub mod work;

pub use interpolate::{Ease, State};
pub use plan::{DataFrame, Movie};
pub use schema::{KeyframesError, TimeMode};
