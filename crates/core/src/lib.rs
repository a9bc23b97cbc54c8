//! # volray-core: ray-casting volume rendering
//!
//! The renderer of N. Ramesh and G. Athithan, "Visualization of
//! three-dimensional data by 'volume rendering'", *Current Science* (1993),
//! after M. Levoy, "Display of surfaces from volume data", *IEEE CG&A* 8(3),
//! 1988.
//!
//! ## The pipeline, as the default (fast) path runs
//!
//! ```text
//!  Volume ──► Renderer::new ─ value range; NaN/∞ refused or masked ─────── renderer.rs, volume/non_finite.rs
//!    │
//!    │ once per volume and transfer function (kept across frames)
//!    ├─► min/max of each 8³-cell brick ──────────────────────────────────── bricks/macrocells.rs
//!    └─► occupied bricks: per voxel slot, unit normal and opacity ───────── bricks/occupied.rs
//!          (transfer function: transfer/classifier.rs; gradient: kernels/gradient.rs)
//!
//!  per frame
//!    RenderSettings checked, camera framed, each ray's samples ─────────── frame/, settings.rs
//!          (camera/ ─ the view; sampling/ ─ t = (k + u)·step, crop, clip planes, jitter)
//!    occupied bricks binned into 16² tiles, front to back ──────────────── cpu/tiles.rs
//!    per tile, in parallel, brick by brick front to back ───────────────── cpu/bricked.rs
//!      ├─ light the brick's voxels (once per frame) ────────────────────── cpu/lit_bricks.rs
//!      │    (kernels/phong.rs: two-sided Phong × material colour)
//!      └─ each ray: trilinear sample, composite front to back, stop ───── kernels/trilinear.rs,
//!           when T < 1/1024                                               kernels/composite.rs
//!    ──► PartialImage: premultiplied colour and transmittance per pixel ─ frame/partial.rs
//!    ──► finish: over the background ──► Image ─────────────────── frame/image.rs
//! ```
//!
//! The other paths share every step they can: post-classified frames
//! (`cpu/post/`: interpolate the scalar and the gradient, then classify
//! and shade each sample, walking the bricks each ray crosses) and the
//! projections (`cpu/projection.rs`: maximum, minimum, average of the
//! scalar, skipping bricks that cannot change the result) take the same
//! samples and call the same kernels; the **reference path**
//! (`reference/`, [`Method::Reference`]) is the paper's algorithm as
//! written, every voxel classified and shaded, every sample composited
//! back to front in `f64`, and is the oracle every fast path is tested
//! against (within 1/255 per channel). Partial images of pieces of a
//! volume combine front to back ([`PartialImage::combine`]) before the
//! background is applied, which is how tiles, ranks of a cluster or GPU
//! passes can share one frame. [`MemoryBound`] says, before anything is
//! allocated, how much memory a frame will take.
//!
//! ## Where things are
//!
//! | folder or file | what |
//! |---|---|
//! | [`camera`] | the camera: pose and orbits, orthographic and perspective views, framing |
//! | [`transfer`] | values to colour and opacity: the classifier, transfer-function JSON, colour maps, presets, iso-surfaces, gradient opacity |
//! | [`sampling`] | which samples each pixel's ray takes: the grid in the world, crop box and clip planes, jitter |
//! | [`kernels`] | per-sample maths, the one copy every path calls (and a GPU port mirrors): trilinear interpolation, gradients, Phong, compositing, projections |
//! | `bricks/` | the fast path's view-independent store: the brick grid, min/max macro-cells, occupied bricks |
//! | `cpu/` | the fast path on the CPU: tiles, the lit-brick cache, the three casters |
//! | `reference/` | the oracle: the paper's stage 1 and back-to-front compositing, every option |
//! | `frame/` | one frame: asked for ([`FrameRequest`], answered through the one entry [`Render::render`] with [`Rendered`]: the image or [`PartialImage`], and [`FrameTimes`]), made ready ([`Frame`]: settings checked, camera framed), its [`Progress`] and stop flag, the [`PartialImage`] and the finished [`Image`] |
//! | `renderer.rs`, `renderer/` | the [`Renderer`] of one volume: its caches, routing to a path, timing; its depth cues |
//! | [`scene`] | several volumes in one picture: a [`Scene`](scene::Scene) renders through the same entry |
//! | `volume/` | the [`Volume`] and its samples, stores and sources ([`VolumeSource`]); [`NonFinite`] values, [`Histogram`]s, a [`Piece`] of a larger volume |
//! | `settings.rs`, `error.rs`, `memory.rs` | [`RenderSettings`], typed errors, [`MemoryBound`] |
//! | `shadows/`, [`probe`] | depth cues (shadows, ambient occlusion); what a pixel shows |
//!
//! ```
//! use volray_core::{FrameRequest, Render, Renderer, RenderSettings, Volume, glam::DVec3};
//!
//! // A ball of density 1 − r on a 32³ grid over [−1, 1]³.
//! let n = 32;
//! let h = 2.0 / (n - 1) as f64;
//! let volume = Volume::from_fn([n, n, n], DVec3::splat(h), DVec3::splat(-1.0), |p| {
//!     (1.0 - p.length()).max(0.0) as f32
//! })
//! .unwrap();
//! let settings = RenderSettings { width: 64, height: 64, ..Default::default() };
//! let renderer = Renderer::new(&volume).unwrap();
//! let image = renderer.render(FrameRequest::new(&settings)).unwrap().image();
//! let centre = image.get(32, 32);
//! let corner = image.get(0, 0);
//! assert!(centre[0] > 0.5 && corner == [0.0, 0.0, 0.0, 0.0]);
//! ```

mod bricks;
pub mod camera;
mod cpu;
mod error;
mod frame;
pub mod kernels;
mod memory;
pub mod probe;
mod reference;
mod renderer;
pub mod sampling;
pub mod scene;
mod settings;
pub mod shadows;
pub mod transfer;
mod volume;

pub use camera::{
    Camera, CameraError, CameraPoint, Fit, Orbit, OrthographicView, Projection, View,
};
pub use error::{ImageSide, Reflection, RenderError, SceneError, SettingError};
pub use frame::Frame;
pub use frame::image::Image;
pub use frame::partial::{PartialImage, PartialPixels};
pub use frame::progress::Progress;
pub use frame::request::{FrameRequest, FrameTimes, Picture, Render, Rendered};
pub use glam;
pub use kernels::phong::{LightGeometry, Phong};
pub use memory::MemoryBound;
pub use renderer::{DEFAULT_CACHE_BUDGET, Renderer};
pub use sampling::clipping::ClipPlane;
pub use settings::{
    Blend, Classification, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, MAX_SAMPLES_PER_RAY, Method,
    RenderSettings, key_light,
};
pub use transfer::function::{PiecewiseLinear, TransferFunction};
pub use transfer::iso::IsoSurface;
pub use volume::histogram::Histogram;
pub use volume::non_finite::{NonFinite, NonFiniteMask};
pub use volume::piece;
pub use volume::piece::Piece;
pub use volume::{
    External, ExternalBytes, ExternalError, Sample, SampleType, Samples, SourceError,
    SourceErrorKind, Store, Volume, VolumeError, VolumeSource, check_box, checked_point_count,
};
