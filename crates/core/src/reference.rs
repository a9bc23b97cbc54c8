//! The reference path: the paper's algorithm as written, the oracle every
//! faster path is tested against.
//!
//! For each pixel: collect every sample along the ray by trilinear
//! interpolation in `f64`, drape the opaque background behind them as the
//! last sample, and composite back to front with the paper's formula. No
//! shortcuts: no early termination, no empty-space skipping.

use crate::camera::OrthographicView;
use crate::composite::back_to_front;
use crate::image::Image;
use crate::ray::GridFrame;
use crate::stage1::ShadedVolume;
use crate::trilinear::sample_reference;
use glam::DVec3;
use rayon::prelude::*;

/// Renders `shaded` through `view` with samples `step` world units apart.
/// `progress` is called with the number of pixels finished, a row at a time.
pub fn render(
    shaded: &ShadedVolume,
    grid: &GridFrame,
    view: &OrthographicView,
    step: f64,
    background: [f32; 3],
    progress: &(dyn Fn(usize) + Sync),
) -> Image {
    let bg = DVec3::from(background.map(f64::from));
    let mut image = Image::new(view.width, view.height, [0.0; 4]);
    image
        .pixels_mut()
        .par_chunks_mut(view.width)
        .enumerate()
        .for_each(|(row, pixels)| {
            let mut samples = Vec::new();
            for (col, pixel) in pixels.iter_mut().enumerate() {
                samples.clear();
                if let Some(ray) = grid.ray(view, col, row, step) {
                    for k in ray.first..=ray.last {
                        let p = ray.position(k, grid.dims);
                        samples.push(sample_reference(&shaded.voxels, grid.dims, p.to_array()));
                    }
                }
                *pixel = back_to_front(&samples, bg).as_vec4().to_array();
            }
            progress(pixels.len());
        });
    image
}
