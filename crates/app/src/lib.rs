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
//!
//! ## Modules
//!
//! - [`input`]: an input by spec ([`input::Spec`]: a built-in source or a
//!   file) with its reading options ([`input::Request`]), read whole or
//!   mapped, with `log`;
//! - [`plan`]: how it is rendered: whole, or a chunked file's level
//!   (`level auto`) in pieces ([`plan::Plan`]);
//! - [`memory`]: the memory budget ([`memory::cache_budget`]: the
//!   refusal of a frame over the limit, and what the caches may take);
//! - `distributed` (feature `mpi`): `mpirun -np N` renders: the input
//!   split among the ranks, each rank's budget, the frame composited on
//!   rank 0, the times;
//! - [`scene`]: several volumes in one picture: channels (each in its
//!   colour), overlays (each with its own look), the mix, time points;
//! - [`reproduce`]: the view's state (camera, transfer function, look) and
//!   its two spellings: `volray render` words ([`reproduce::command`]) and
//!   Python keywords ([`reproduce::keywords`]);
//! - [`animation`]: an animation's views ([`animation::Views`]: a
//!   turntable's, or any per-frame camera path), and the window and
//!   framing the frames of a series share (its first pass);
//! - [`movie`]: movies: a keyframes file read into the flags' options,
//!   the values between keyframes (orbits, quaternions, OKLab colours,
//!   mixed transfer functions), the frame plan (frame `k` at `k / fps`,
//!   time points held or blended, parts `A:B`);
//! - [`bench`](mod@bench): `volray bench`'s timed frames, their medians and `--json`
//!   rows, and the peer benchmark's workloads (with VTK timed beside them);
//! - [`convert`]: a volume written back as a file (NRRD, `.npy`, raw,
//!   OME-Zarr), and what was written, in words;
//! - [`describe`]: what a volume file holds and how volray reads it, as
//!   `volray info` says it (lines of text, or JSON);
//! - [`look`]: what the look options leave to an input's volume (its
//!   file's window, labels, `tf auto`);
//! - [`renderer`]: a volume's renderer within the memory budget, as the
//!   command line renders its frames;
//! - [`reads`]: the files an input reads (a DICOM directory's, a
//!   header's detached data), and the refusal of an output that is one;
//! - [`words`]: the number words both spellings and the flags parse;
//! - [`error`]: [`AppError`], typed, one line naming the file, which each
//!   front end words in its own syntax.
//!
//! ```no_run
//! use volray_app::input::{self, Request};
//! use volray_app::memory::{self, Budget};
//! use volray_app::plan::{self, Frames, Plan};
//! use volray_core::{NonFinite, RenderSettings};
//!
//! let request = Request::of("blobs:64");
//! let settings = RenderSettings::default();
//! let frames = Frames {
//!     settings: &settings,
//!     non_finite: NonFinite::Refuse,
//!     log: false,
//!     labels: false,
//!     extra: 0,
//! };
//! if let Plan::Whole { level } = plan::plan(&request, &frames, &mut |_| {})? {
//!     let input = input::load(&request.at_level(level))?;
//!     let budget = Budget { limit: input.max_memory, extra: 0, samples_count: true };
//!     let bytes = memory::cache_budget(&input.volume, &input.name, &settings, NonFinite::Refuse, budget)?;
//!     println!("{}: {bytes} bytes of brick caches", input.name);
//! }
//! # Ok::<(), volray_app::AppError>(())
//! ```

pub mod animation;
pub mod bench;
pub mod convert;
pub mod describe;
pub mod display;
#[cfg(feature = "mpi")]
pub mod distributed;
pub mod error;
pub mod input;
pub mod look;
pub mod memory;
pub mod movie;
pub mod plan;
pub mod reads;
pub mod renderer;
pub mod reproduce;
pub mod scene;
pub mod words;

pub use error::AppError;
