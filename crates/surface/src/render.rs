//! Rendering a [`PolarSurface`]: framing, projection, z-buffer, Phong shading.
//!
//! The view is orthographic, with volray-core's conventions
//! ([`OrthographicView`]): rays along `d = reference − view point`, screen
//! right `d × up`, screen up `right × d`, the view reference (default: the
//! origin, the surface's centre) at the image centre. The window is square
//! pixels fitting the surface's bounding sphere (radius
//! [`PolarSurface::max_radius`] about the origin) or the given half-size.
//!
//! Every triangle is projected and drawn into a z-buffer ([`ZBuffer`]), so
//! each sample shows the nearest surface. The visible sample is then lit with
//! the paper's Phong model `C = C_s·k_a + C_s·(k_d (N·L) + k_s (N·H)^n)`
//! ([`Phong::shade`], two-sided as in the volume path) using the normal
//! interpolated across its triangle and renormalised — Phong shading, so a
//! highlight inside a large triangle is not lost as it would be by
//! interpolating colours (Gouraud). The lit colour is multiplied by the
//! material colour and clamped to [0, 1], as for voxels.
//!
//! With `supersampling = s` every pixel is the mean of `s × s` samples on a
//! regular grid (a box filter), which smooths the silhouettes; the alpha
//! channel is the fraction of samples the surface covers.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use volray_core::LightGeometry;
use volray_core::camera::OrthographicView;
use volray_core::{Camera, Image, Phong};

use crate::SurfaceError;
use crate::polar_mesh::PolarSurface;
use crate::raster::{ScreenTriangle, ZBuffer};

/// The most samples per pixel side.
pub const MAX_SUPERSAMPLING: usize = 8;
/// The most samples in one frame (width × height × supersampling²): the
/// z-buffer takes 20 bytes per sample.
pub const MAX_SAMPLES: usize = 1 << 26;

/// How to render a polar surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceSettings {
    /// Image size in pixels.
    pub width: usize,
    pub height: usize,
    /// View point, view reference (`None`: the origin) and up vector.
    pub camera: Camera,
    /// Phong coefficients and the light's colour.
    pub phong: Phong,
    /// Direction towards the light (at infinity); `None`: a headlight
    /// (`L = V`).
    pub light_direction: Option<DVec3>,
    /// The material colour, multiplying the lit colour.
    pub color: [f32; 3],
    /// The colour where the surface is absent.
    pub background: [f32; 3],
    /// World half-size of the window's shorter side, about the view
    /// reference; `None`: the smallest window that holds the surface's
    /// bounding sphere ([`fitted_half_window`] gives the tightest window,
    /// which suits elongated surfaces better).
    pub half_window: Option<f64>,
    /// `s`: each pixel averages `s × s` samples (1: one sample at the pixel
    /// centre).
    pub supersampling: usize,
}

impl Default for SurfaceSettings {
    /// 120 × 120 pixels (the paper's window), the default camera (view
    /// point on +x, z up), the default Phong model with a headlight, a white
    /// surface on black, fitted to its bounding sphere, one sample per pixel.
    fn default() -> Self {
        SurfaceSettings {
            width: 120,
            height: 120,
            camera: Camera::default(),
            phong: Phong::default(),
            light_direction: None,
            color: [1.0; 3],
            background: [0.0; 3],
            half_window: None,
            supersampling: 1,
        }
    }
}

/// Renders `surface`: RGBA, alpha the covered fraction of each pixel.
pub fn render(surface: &PolarSurface, settings: &SurfaceSettings) -> Result<Image, SurfaceError> {
    render_with_depth(surface, settings).map(|(image, _)| image)
}

/// Renders `surface`, and gives each pixel's nearest depth along the rays,
/// `(p − reference)·d` (negative in front of the plane through the view
/// reference), `+∞` where the surface misses every sample of the pixel.
/// Row-major, row 0 at the top, like the image.
pub fn render_with_depth(
    surface: &PolarSurface,
    settings: &SurfaceSettings,
) -> Result<(Image, Vec<f64>), SurfaceError> {
    let s = settings.supersampling;
    if !(1..=MAX_SUPERSAMPLING).contains(&s) {
        return Err(SurfaceError::Supersampling(s));
    }
    let (width, height) = (settings.width, settings.height);
    let samples = width.checked_mul(height).and_then(|n| n.checked_mul(s * s));
    if width == 0 || height == 0 || samples.is_none_or(|n| n > MAX_SAMPLES) {
        return Err(SurfaceError::ImageSize {
            width,
            height,
            supersampling: s,
            limit: MAX_SAMPLES,
        });
    }
    if let Some(h) = settings.half_window
        && !(h.is_finite() && h > 0.0)
    {
        return Err(SurfaceError::HalfWindow(h));
    }
    if let Some(l) = settings.light_direction
        && !(l.is_finite() && l.length() > 0.0)
    {
        return Err(SurfaceError::LightDirection(l));
    }

    let view = frame(surface, settings)?;
    let light = {
        let to_viewer = (-view.direction).as_vec3();
        let to_light = settings
            .light_direction
            .map_or(to_viewer, |l| l.normalize().as_vec3());
        LightGeometry::new(to_light, to_viewer)
    };

    let projected: Vec<(DVec2, f64)> = surface
        .vertices()
        .par_iter()
        .map(|&p| {
            let (col, row) = view.project(p);
            (DVec2::new(col, row), (p - view.centre).dot(view.direction))
        })
        .collect();
    let normals = surface.normals();
    let triangles: Vec<ScreenTriangle> = surface
        .triangles()
        .par_iter()
        .map(|t| ScreenTriangle {
            corners: t.vertices.map(|v| projected[v as usize].0),
            depth: t.vertices.map(|v| projected[v as usize].1),
            normals: t.normals.map(|n| normals[n as usize]),
        })
        .collect();
    let zbuffer = ZBuffer::draw(&triangles, view.width, view.height);

    let shade = |normal: Vec3| -> [f32; 3] {
        let lit = settings.phong.shade(normal, &light);
        std::array::from_fn(|c| (lit[c] * settings.color[c]).clamp(0.0, 1.0))
    };
    let count = (s * s) as f32;
    let pixels: Vec<([f32; 4], f64)> = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let mut sum = [0.0f32; 3];
            let mut covered = 0usize;
            let mut nearest = f64::INFINITY;
            for sy in 0..s {
                for sx in 0..s {
                    let (col, row) = (x * s + sx, y * s + sy);
                    let depth = zbuffer.depth(col, row);
                    let color = if depth.is_finite() {
                        nearest = nearest.min(depth);
                        covered += 1;
                        shade(zbuffer.normal(col, row))
                    } else {
                        settings.background
                    };
                    for c in 0..3 {
                        sum[c] += color[c];
                    }
                }
            }
            let rgba = [
                sum[0] / count,
                sum[1] / count,
                sum[2] / count,
                covered as f32 / count,
            ];
            (rgba, nearest)
        })
        .collect();
    let (rgba, depth): (Vec<[f32; 4]>, Vec<f64>) = pixels.into_iter().unzip();
    let image = Image::from_pixels(width, height, rgba).expect("width × height pixels");
    Ok((image, depth))
}

/// The smallest [`SurfaceSettings::half_window`] that shows all of
/// `surface` with `settings`' camera and image size: the window about the
/// view reference that just holds the projection of every mesh vertex
/// (tighter than the bounding sphere for elongated surfaces, such as
/// `|Y_l0|²` seen along its axis). Errors as [`render`] for the camera.
pub fn fitted_half_window(
    surface: &PolarSurface,
    settings: &SurfaceSettings,
) -> Result<f64, SurfaceError> {
    let view = frame(
        surface,
        &SurfaceSettings {
            width: settings.width.max(1),
            height: settings.height.max(1),
            supersampling: 1,
            ..*settings
        },
    )?;
    let (half_x, half_y) = surface
        .vertices()
        .par_iter()
        .map(|&p| {
            let d = p - view.centre;
            (d.dot(view.right).abs(), d.dot(view.up).abs())
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    let (width, height) = (view.width as f64, view.height as f64);
    let pixel_size = (2.0 * half_x / width).max(2.0 * half_y / height);
    Ok(0.5 * pixel_size * width.min(height))
}

/// The sample grid's view: directions from volray-core's framing, the pixel
/// size from the bounding sphere (or `half_window`), `supersampling` times
/// finer.
fn frame(
    surface: &PolarSurface,
    settings: &SurfaceSettings,
) -> Result<OrthographicView, SurfaceError> {
    let s = settings.supersampling;
    let radius = surface.max_radius();
    let camera = Camera {
        look_at: Some(settings.camera.look_at.unwrap_or(DVec3::ZERO)),
        ..settings.camera
    };
    let bounds = (DVec3::splat(-radius), DVec3::splat(radius));
    let view = OrthographicView::frame(&camera, bounds, settings.width * s, settings.height * s)?;
    let (width, height) = (settings.width as f64, settings.height as f64);
    let pixel_size = match settings.half_window {
        Some(half) => 2.0 * half / width.min(height),
        None => {
            // The sphere about the origin, seen off-centre when the view
            // reference is not the origin.
            let offset = -view.centre;
            let half_x = offset.dot(view.right).abs() + radius;
            let half_y = offset.dot(view.up).abs() + radius;
            (2.0 * half_x / width).max(2.0 * half_y / height)
        }
    };
    Ok(OrthographicView {
        pixel_size: pixel_size / s as f64,
        ..view
    })
}
