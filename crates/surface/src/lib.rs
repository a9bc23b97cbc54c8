//! # volray-surface: surface rendering of polar surfaces `r(θ, φ)`
//!
//! The paper's Figure 1c (Ramesh & Athithan 1993, errata 6) shows "surface
//! renderings of the angular part" of the hydrogen densities: the polar
//! surface `r(θ, φ) = |Y_lm(θ, φ)|²`, seen from (150, 150, 500). This crate
//! is that surface renderer, separate from the volume path: a polar surface
//! is sampled on a (θ, φ) grid and triangulated ([`polar_mesh`]); the
//! triangles are projected orthographically with volray-core's camera
//! conventions and drawn into a z-buffer, so the nearest surface wins at
//! every pixel ([`raster`]); each visible sample is lit by the paper's Phong
//! model (volray-core's [`Phong`]) with the normal interpolated across its
//! triangle (Phong shading, not Gouraud) ([`render`](mod@render)).
//!
//! `θ` is the polar angle from +z and `φ` the azimuth from +x towards +y, as
//! in `volray_data::hydrogen::SphericalHarmonic`.
//!
//! # API
//!
//! ```text
//! PolarSurface::new(r: impl Fn(θ, φ) -> f64 + Sync, theta_steps, phi_steps)
//!     -> Result<PolarSurface, SurfaceError>      // r ≥ 0, finite; theta_steps ≥ 2, phi_steps ≥ 3
//! PolarSurface::max_radius(&self) -> f64          // largest sampled r: the mesh lies in that ball
//! PolarSurface::{vertices, normals, triangles}    // the mesh: DVec3s, unit normals, Triangle
//!                                                 //   { vertices: [u32; 3], normals: [u32; 3] }
//!
//! SurfaceSettings {                               // Default: 120 × 120, the default camera
//!     width, height,                              //   (view point on +x, z up), Phong::default(),
//!     camera: Camera,                             //   headlight, white, black background,
//!     phong: Phong,                               //   fit the bounding sphere, no supersampling
//!     light_direction: Option<DVec3>,             // towards the light; None: headlight (L = V)
//!     color: [f32; 3], background: [f32; 3],      // material colour; opaque background
//!     half_window: Option<f64>,                   // world half-size of the window's shorter side;
//!                                                 //   None: fit the bounding sphere (max_radius)
//!     supersampling: usize,                       // s × s samples per pixel, box-filtered (1)
//! }
//! render(&PolarSurface, &SurfaceSettings) -> Result<Image, SurfaceError>
//! render_with_depth(&PolarSurface, &SurfaceSettings) -> Result<(Image, Vec<f64>), SurfaceError>
//! fitted_half_window(&PolarSurface, &SurfaceSettings) -> Result<f64, SurfaceError>
//!     // the smallest half_window showing the whole projected mesh for this camera and size
//! ```
//!
//! The projection is always orthographic, as in the paper's views. The
//! camera's view reference defaults to the origin (the centre of the
//! polar surface); the window comes from `half_window` or the bounding
//! sphere, not from the volume path's box framing. Rays run along `d = reference − view point`, screen right
//! is `d × up` and screen up `right × d` (as `volray_core::camera`). The
//! image's alpha is the fraction of the pixel's samples the surface covers;
//! its colour is the lit colour times `color`, clamped to [0, 1], over the
//! background. The depth map holds, per pixel, the nearest depth along the
//! rays, `(p − reference)·d` (negative in front of the plane through the
//! reference), `+∞` where the surface misses the pixel.
//!
//! ```
//! use volray_surface::{PolarSurface, SurfaceSettings, render};
//! use volray_core::{Camera, glam::DVec3};
//!
//! // The polar surface of |Y_10|² = 3 cos²θ / 4π: two lobes along z.
//! let y10 = |theta: f64, _phi: f64| 3.0 * theta.cos().powi(2) / (4.0 * std::f64::consts::PI);
//! let surface = PolarSurface::new(y10, 48, 96).unwrap();
//! let settings = SurfaceSettings {
//!     width: 64,
//!     height: 64,
//!     camera: Camera { view_point: Some(DVec3::new(150.0, 150.0, 500.0)), ..Camera::default() },
//!     ..SurfaceSettings::default()
//! };
//! let image = render(&surface, &settings).unwrap();
//! assert_eq!(image.get(0, 0), [0.0, 0.0, 0.0, 0.0]); // a corner shows the background
//! assert!(image.get(32, 20)[3] == 1.0);              // the upper lobe covers this pixel
//! ```

pub mod polar_mesh;
pub mod raster;
pub mod render;

pub use polar_mesh::PolarSurface;
pub use render::{SurfaceSettings, fitted_half_window, render, render_with_depth};
pub use volray_core::{Camera, Image, Phong, glam};

use thiserror::Error;
use volray_core::camera::CameraError;

/// Why a surface cannot be built or rendered.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SurfaceError {
    #[error(
        "the (θ, φ) grid needs theta_steps >= 2 and phi_steps >= 3 cells, got {theta_steps} × {phi_steps}"
    )]
    TooFewSteps {
        theta_steps: usize,
        phi_steps: usize,
    },
    #[error(
        "the (θ, φ) grid of {theta_steps} × {phi_steps} cells is larger than the limit of {limit} cells"
    )]
    TooManySteps {
        theta_steps: usize,
        phi_steps: usize,
        limit: usize,
    },
    #[error("r(θ = {theta:.6}, φ = {phi:.6}) = {value}: the radius must be finite and >= 0")]
    BadRadius { theta: f64, phi: f64, value: f64 },
    #[error("r is 0 at every sample: there is no surface to render")]
    NoSurface,
    #[error(
        "image size {width} × {height} with {supersampling} × {supersampling} samples per pixel: \
         both sides must be at least 1 and the samples at most {limit}"
    )]
    ImageSize {
        width: usize,
        height: usize,
        supersampling: usize,
        limit: usize,
    },
    #[error("supersampling {0}: must be between 1 and {limit}", limit = render::MAX_SUPERSAMPLING)]
    Supersampling(usize),
    #[error("half window {0}: must be finite and > 0")]
    HalfWindow(f64),
    #[error("light direction {0}: must be finite and non-zero")]
    LightDirection(glam::DVec3),
    #[error("camera: {0}")]
    Camera(#[from] CameraError),
}
