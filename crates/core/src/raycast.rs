//! The fast path: the reference's samples composited front to back, with
//! early ray termination, in parallel over image tiles.
//!
//! Each pixel is computed from its own ray alone, by the same arithmetic
//! whatever thread runs it, so the image is bit-identical for any thread
//! count. A ray stops once its transmittance is below
//! [`TERMINATION_TRANSMITTANCE`]: colours are in [0, 1], so what lies behind
//! could change the pixel by at most that much, well under 1/255.

use crate::camera::OrthographicView;
use crate::composite::FrontToBack;
use crate::image::Image;
use crate::ray::GridFrame;
use crate::stage1::ShadedVolume;
use crate::trilinear::sample;
use glam::{Vec3, Vec4};
use rayon::prelude::*;

/// Rays stop when less than this fraction of light gets through.
pub const TERMINATION_TRANSMITTANCE: f32 = 1.0 / 1024.0;

/// Tile edge in pixels: a 16×16 tile's rays stay close together in the
/// volume, so neighbouring rays reuse cached voxels.
const TILE: usize = 16;

/// Renders `shaded` through `view` with samples `step` world units apart.
/// `progress` is called with the number of pixels finished, a tile at a time.
pub fn render(
    shaded: &ShadedVolume,
    grid: &GridFrame,
    view: &OrthographicView,
    step: f64,
    background: [f32; 3],
    progress: &(dyn Fn(usize) + Sync),
) -> Image {
    let (width, height) = (view.width, view.height);
    let tiles_x = width.div_ceil(TILE);
    let tiles_y = height.div_ceil(TILE);
    let bg = Vec3::from(background);
    let tiles: Vec<Vec<[f32; 4]>> = (0..tiles_x * tiles_y)
        .into_par_iter()
        .map(|tile| {
            let (x0, y0) = ((tile % tiles_x) * TILE, (tile / tiles_x) * TILE);
            let (x1, y1) = ((x0 + TILE).min(width), (y0 + TILE).min(height));
            let mut out = Vec::with_capacity((x1 - x0) * (y1 - y0));
            for row in y0..y1 {
                for col in x0..x1 {
                    out.push(cast(shaded, grid, view, col, row, step, bg).to_array());
                }
            }
            progress(out.len());
            out
        })
        .collect();

    let mut image = Image::new(width, height, [0.0; 4]);
    for (tile, pixels) in tiles.iter().enumerate() {
        let (x0, y0) = ((tile % tiles_x) * TILE, (tile / tiles_x) * TILE);
        let tile_width = (x0 + TILE).min(width) - x0;
        for (n, rgba) in pixels.iter().enumerate() {
            image.set(x0 + n % tile_width, y0 + n / tile_width, *rgba);
        }
    }
    image
}

/// The colour of one ray.
#[inline]
fn cast(
    shaded: &ShadedVolume,
    grid: &GridFrame,
    view: &OrthographicView,
    col: usize,
    row: usize,
    step: f64,
    background: Vec3,
) -> Vec4 {
    let mut acc = FrontToBack::new();
    if let Some(ray) = grid.ray(view, col, row, step) {
        let dims = grid.dims;
        let origin = ray.origin.as_vec3();
        let delta = (ray.direction * step).as_vec3();
        let upper = Vec3::new(
            (dims[0] - 1) as f32,
            (dims[1] - 1) as f32,
            (dims[2] - 1) as f32,
        );
        for k in ray.first..=ray.last {
            let p = (origin + k as f32 * delta).clamp(Vec3::ZERO, upper);
            acc.add(sample(&shaded.voxels, dims, p));
            if acc.transmittance() < TERMINATION_TRANSMITTANCE {
                break;
            }
        }
    }
    acc.finish(background)
}
