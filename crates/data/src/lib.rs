//! volray's built-in volumes, named by *source specs*.
//!
//! The renderer's INPUT is either a volume file or a spec such as
//! `marschner-lobb:41`, which this crate turns into a [`Volume`]: analytic
//! test signals with known closed forms, for checking reconstruction,
//! shading and orientation without any data files.
//!
//! # Spec grammar
//!
//! ```text
//! SPEC = NAME [ ":" ARG { "," ARG } ]
//! ARG  = VALUE | KEY "=" VALUE
//! ```
//!
//! Positional arguments come first, then `key=value` ones. Whitespace around
//! the pieces is ignored. Empty arguments, empty keys or values, duplicate
//! keys, a positional argument after a named one, unknown keys and surplus
//! positional arguments are all errors, so a typo is never silently ignored.
//! A source's positional parameters may also be given by name
//! (`marschner-lobb:n=41`). Use [`is_source_spec`] to tell a spec from a file
//! path, [`generate`] to make the volume, [`sources`] to list the sources.
//!
//! # Sources
//!
//! All sample a cube with `N` points per side (2 ≤ N ≤ 1025), `[−1, 1]³`
//! with point `i` at `−1 + 2i/(N − 1)` (see [`grid`]) except `hydrogen`,
//! which samples `[−R, R]³`:
//!
//! | spec | volume |
//! |------|--------|
//! | `marschner-lobb[:N][,fm=F][,alpha=A]` | the Marschner–Lobb test signal (N = 41, f_M = 6, α = 0.25), [`marschner_lobb`] |
//! | `blobs[:N]` | four Gaussian blobs without mirror symmetry (N = 64), [`blobs`] |
//! | `sphere[:N][,radius=R][,edge=W]` | a solid ball with a smoothstep edge (N = 64, R = 0.8, W = 0.1), [`sphere`] |
//! | `torus[:N][,major=R][,minor=r]` | a Gaussian tube around the z axis (N = 64, R = 0.6, r = 0.25), [`torus`] |
//! | `hydrogen[:N[,L[,M]]][,grid=G][,extent=R][,real=true\|false]` | the hydrogen density `\|ψ_nlm\|²` in `a₀⁻³` on `[−R, R]³` in Bohr radii, `R` holding 99.5% of the probability unless given (1, 0, 0, G = 50), [`hydrogen`] |
//! | `fractal[:SIZE][,seed=S][,dim=D][,sigma=X][,ramp=R][,threshold=T][,raw=true][,additions=true]` | a fractal cloud by 3-D midpoint displacement, SIZE = 2^k + 1 (129, seed 1, D = 3.7, σ = 1, ramp 0.3, threshold 0.45), [`fractal`] |
//!
//! # Example
//!
//! ```
//! use volray_core::glam::DVec3;
//!
//! assert!(volray_data::is_source_spec("marschner-lobb:9"));
//! assert!(!volray_data::is_source_spec("head.raw"));
//!
//! let volume = volray_data::generate("marschner-lobb:9")?;
//! assert_eq!(volume.dims(), [9, 9, 9]);
//! assert_eq!(volume.origin(), DVec3::splat(-1.0));
//! assert_eq!(volume.spacing(), DVec3::splat(0.25));
//! // At the centre ρ = (1 + 2α)/(2(1 + α)) = 0.6.
//! assert!((volume.get(4, 4, 4) - 0.6).abs() < 1e-6);
//!
//! let err = volray_data::generate("marschner-lobb:1").unwrap_err();
//! assert_eq!(
//!     err.to_string(),
//!     "marschner-lobb:1: grid must have at least 2 points per side, got 1"
//! );
//! # Ok::<(), volray_data::DataError>(())
//! ```
//!
//! # Adding a source
//!
//! Write a module with a `pub const INFO: SourceInfo` whose `build` reads
//! its parameters through [`Args`] and samples with [`grid::cube_volume`]
//! (or builds any other [`Volume`]), then list `INFO` in the registry in
//! `sources.rs`.

pub mod blobs;
mod error;
pub mod fractal;
pub mod grid;
pub mod hydrogen;
pub mod marschner_lobb;
mod sources;
mod spec;
pub mod sphere;
pub mod torus;

pub use error::DataError;
pub use grid::generate_box;
pub use sources::{SourceInfo, find, generate, is_source_spec, sources};
pub use spec::{Args, SourceSpec};
pub use volray_core::Volume;
