//! # volray-core: ray-casting volume rendering
//!
//! The renderer of N. Ramesh and G. Athithan, "Visualization of
//! three-dimensional data by 'volume rendering'", *Current Science* (1993),
//! after M. Levoy, "Display of surfaces from volume data", *IEEE CG&A* 8(3),
//! 1988. The data path, one module per step:
//!
//! ```text
//! Volume ─► stage 1: gradient ─► shading (Phong) ┐
//!                    classify (opacity, colour)  ┴► ShadedVolume (r, g, b, α per voxel)
//!        ─► stage 2: camera ─► ray (sample positions) ─► trilinear ─► composite ─► Image
//! ```
//!
//! - [`volume`]: the grid of scalars (voxels are grid points, x fastest).
//! - **Stage 1**, per voxel ([`stage1`]): [`gradient`] gives the normal by
//!   central differences (errata 1), [`shading`] the paper's Phong colour
//!   `C = Cs·ka + Cs·(kd (N·L) + ks (N·H)^n)`, [`classify`] the opacity
//!   `α = p + (f − fmin)/(fmax − fmin)·(q − p)` or a
//!   [`transfer_function`], corrected for the sampling step; optionally
//!   Levoy's isovalue contours ([`iso`]) or gradient-magnitude opacity
//!   ([`gradient_opacity`]).
//! - **Stage 2**, per pixel: [`camera`] frames an orthographic or a
//!   [`perspective`] view, orbited as VTK does ([`pose`]); [`ray`]
//!   finds each ray's samples at a fixed step (default one voxel, errata 8);
//!   [`trilinear`] resamples colour and opacity there; [`composite`] applies
//!   the transparency formula `C_out = C_in (1 − α) + C α`.
//! - **Options** of stage 2: [`sampling`] gives every pixel's samples, cut
//!   by the crop box and clip planes ([`clipping`]) and offset by
//!   [`jitter`]; [`post_classification`] classifies and shades samples
//!   instead of voxels; [`blend`] projects the scalar (maximum, minimum,
//!   average) instead of compositing.
//! - Two paths: [`reference`](mod@reference), the paper's algorithm as written (stage 1
//!   on every voxel, back-to-front compositing of every sample), kept as
//!   the oracle; and the fast default, which computes the same samples but
//!   skips what contributes nothing. Its view-independent stage 1 groups
//!   the cells into [`bricks`], rules out empty ones with the [`macrocells`]
//!   min/max grid and keeps the occupied ones compact ([`classified`]); per
//!   frame, [`shade_bricks`] lights them, [`tiles`] lists them per image
//!   tile front to back, and [`raycast`] composites front to back through
//!   the occupied cells only, with early ray termination, in parallel over
//!   tiles. The paths agree within 1/255 per channel; the fast path is
//!   bit-identical for any thread count. `docs/performance.md` records the
//!   design and what each step bought. The fast path renders composited,
//!   pre-classified frames of either projection (with any crop, clip
//!   planes and jitter); [`intensity`] renders the projection blend modes
//!   fast, and [`post_cast`] post-classified compositing (walking each ray
//!   brick by brick, skipping the transparent ones, from per-voxel
//!   gradients packed with the values, 16 bytes per voxel). The reference
//!   renders every option too, as the oracle ([`Method::Reference`]).
//! - [`render`] ties it together; [`image`] is the RGBA `f32` result.
//!   Volumes with NaN or infinite values are refused, or rendered with
//!   those voxels as empty space ([`non_finite`]).
//!
//! ```
//! use volray_core::{Renderer, RenderSettings, Volume, glam::DVec3};
//!
//! // A ball of density 1 − r on a 32³ grid over [−1, 1]³.
//! let n = 32;
//! let h = 2.0 / (n - 1) as f64;
//! let volume = Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
//!     (1.0 - p.length()).max(0.0) as f32
//! })
//! .unwrap();
//! let settings = RenderSettings { width: 64, height: 64, ..Default::default() };
//! let image = Renderer::new(&volume).unwrap().render(&settings).unwrap();
//! let centre = image.get(32, 32);
//! let corner = image.get(0, 0);
//! assert!(centre[0] > 0.5 && corner == [0.0, 0.0, 0.0, 0.0]);
//! ```

pub mod blend;
pub mod bricks;
pub mod camera;
pub mod classified;
pub mod classify;
pub mod clipping;
pub mod colormap;
pub mod composite;
pub mod gradient;
pub mod gradient_opacity;
pub mod histogram;
pub mod image;
pub mod intensity;
pub mod iso;
pub mod jitter;
pub mod macrocells;
pub mod non_finite;
pub mod perspective;
pub mod pose;
pub mod post_cast;
pub mod post_classification;
pub mod presets;
pub mod ray;
pub mod raycast;
pub mod reference;
pub mod render;
pub mod sampling;
pub mod shade_bricks;
pub mod shading;
pub mod stage1;
pub mod tiles;
pub mod transfer_function;
pub mod trilinear;
pub mod volume;

pub use blend::Blend;
pub use camera::{Camera, Fit, Projection, View};
pub use clipping::ClipPlane;
pub use glam;
pub use histogram::Histogram;
pub use image::Image;
pub use iso::IsoSurface;
pub use non_finite::{NonFinite, NonFiniteMask};
pub use post_classification::Classification;
pub use render::{FrameTimes, Method, RenderError, RenderSettings, Renderer};
pub use shading::Phong;
pub use transfer_function::TransferFunction;
pub use volume::{Volume, VolumeError};
