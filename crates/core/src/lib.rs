//! # volray-core: ray-casting volume rendering
//!
//! The renderer of N. Ramesh and G. Athithan, "Visualization of
//! three-dimensional data by 'volume rendering'", *Current Science* (1993),
//! after M. Levoy, "Display of surfaces from volume data", *IEEE CG&A* 8(3),
//! 1988.
//!
//! Where things are (one concept per file):
//!
//! | folder | what |
//! |---|---|
//! | [`camera`] | the camera: pose, orthographic and perspective views, framing |
//! | [`transfer`] | values to colour and opacity: the classifier, transfer-function JSON, colour maps, presets, iso-surfaces, gradient opacity |
//! | [`sampling`] | which samples each pixel's ray takes: the sample grid, crop and clip planes, jitter |
//! | [`kernels`] | per-sample maths every path calls: trilinear interpolation, gradients, Phong, compositing, projections |
//! | `bricks` | the fast path's view-independent store: bricks, min/max macro-cells, occupied bricks |
//! | `reference` | the oracle: the paper's algorithm as written, every option, `f64` |
//! | `cpu` | the fast path: tiles, the lit-brick cache, the casters |
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

pub mod bricks;
pub mod camera;
pub mod cpu;
mod error;
mod frame;
pub mod histogram;
pub mod image;
pub mod kernels;
mod memory;
pub mod non_finite;
mod partial;
pub mod reference;
pub mod renderer;
pub mod sampling;
mod settings;
pub mod transfer;
pub mod volume;

pub use camera::{
    Camera, CameraError, CameraPoint, Fit, Orbit, OrthographicView, Projection, View,
};
pub use error::{ImageSide, Reflection, RenderError, SettingError};
pub use frame::Frame;
pub use glam;
pub use histogram::Histogram;
pub use image::Image;
pub use kernels::phong::{LightGeometry, Phong};
pub use memory::MemoryBound;
pub use non_finite::{NonFinite, NonFiniteMask};
pub use partial::{PartialImage, PartialPixels};
pub use renderer::{FrameTimes, Renderer};
pub use sampling::clipping::ClipPlane;
pub use settings::{
    Blend, Classification, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, MAX_SAMPLES_PER_RAY, Method,
    RenderSettings,
};
pub use transfer::function::{PiecewiseLinear, TransferFunction};
pub use transfer::iso::IsoSurface;
pub use volume::{Volume, VolumeError, checked_point_count};
