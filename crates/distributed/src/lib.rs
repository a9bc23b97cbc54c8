//! Sort-last distributed rendering: a volume split among N ranks (any N),
//! each rendering its piece into a partial image, composited into the
//! frame on rank 0. The paper's "parallel computers", as ParaView (IceT),
//! VisIt and OSPRay's `mpi_distributed` do it.
//!
//! The steps, in the order a frame runs:
//!
//! 1. [`kd`]: the k-d split of the grid into one box per rank, and the
//!    visibility order of the boxes for a view.
//! 2. [`frame`]: each rank reads its box plus the ghost layers that
//!    trilinear cells and gradients need (`volray_core::piece`), the ranks
//!    agree on the value range, and each renders its piece on the fast
//!    path with the whole volume's camera, sample planes and statistics.
//! 3. [`schedule`] and [`compose`]: binary swap over the k-d tree (ranks
//!    beyond a power of two folded in first), exchanging only the
//!    non-empty rectangle of each piece of image ([`wire`]); rank 0
//!    gathers the parts.
//! 4. [`transport`]: the messages, over MPI (feature `mpi`, module `mpi`) or
//!    between threads of one process ([`transport::Local`]).
//!
//! Several volumes of one grid (channels) go through the same steps
//! together: [`scene`] reads each rank's box of each and renders them as
//! one scene of pieces.
//!
//! ```
//! use volray_core::glam::DVec3;
//! use volray_core::{RenderSettings, Volume};
//! use volray_distributed::frame::Distributed;
//! use volray_distributed::transport::Local;
//!
//! // A 16³ ramp rendered by 3 ranks (threads here; MPI processes in a run).
//! let volume = Volume::from_fn([16; 3], DVec3::ONE, DVec3::ZERO, |p| p.x as f32).unwrap();
//! let settings = RenderSettings { width: 32, height: 32, ..RenderSettings::default() };
//! let frames: Vec<_> = std::thread::scope(|s| {
//!     let ranks: Vec<_> = Local::group(3).into_iter().map(|t| {
//!         let (volume, settings) = (&volume, &settings);
//!         s.spawn(move || {
//!             let mut d = Distributed::read(&t, volume, Default::default()).unwrap();
//!             d.render(settings).unwrap().0
//!         })
//!     }).collect();
//!     ranks.into_iter().map(|h| h.join().unwrap()).collect()
//! });
//! assert!(frames[0].is_some() && frames[1].is_none());
//! ```

pub mod compose;
pub mod frame;
pub mod kd;
#[cfg(feature = "mpi")]
pub mod mpi;
pub mod scene;
pub mod schedule;
pub mod streamed;
pub mod transport;
pub mod wire;
