//! The reference path: the paper's algorithm as written, generalised to
//! every rendering option, and the oracle every faster path is tested
//! against.
//!
//! For each pixel: take every sample of its ray ([`crate::sampling`]:
//! orthographic or perspective, cropped and clipped, jittered or not), in
//! `f64`, and make the pixel from them by the frame's [`Shader`]:
//!
//! - pre-classified (the paper's): interpolate the voxels' colours and
//!   opacities ([`crate::reference::stage1`]) trilinearly and composite
//!   back to front with the paper's formula
//!   ([`crate::kernels::composite::back_to_front`]);
//! - post-classified: interpolate the scalar and the gradient, classify and
//!   shade each sample ([`crate::reference::post`]), composite alike;
//! - a projection (maximum, minimum, average;
//!   [`crate::kernels::projection`]): project the interpolated scalar.
//!
//! The result is a partial image ([`PartialImage`]): the paper drapes the
//! opaque background behind the samples as the last one, which is applied
//! when the image is finished, as on every path (and projected values go
//! through the colour map there).
//!
//! Non-finite voxels rendered as empty space ([`NonFinite`](crate::NonFinite)) have
//! zero opacity in stage 1; post-classified and projected samples that a
//! non-finite voxel weighs in are skipped.
//!
//! No shortcuts: no early termination, no empty-space skipping.

pub mod post;
pub mod stage1;

use crate::camera::View;
use crate::frame::partial::{PartialImage, PartialPixels};
use crate::frame::progress::Progress;
use crate::kernels::composite::back_to_front;
use crate::kernels::projection::Projected;
use crate::kernels::trilinear;
use crate::reference::post::PostClassifier;
use crate::reference::stage1::ShadedVolume;
use crate::sampling::Sampling;
use crate::settings::Blend;
use crate::volume::Volume;
use crate::volume::non_finite::NonFiniteMask;
use glam::DVec4;
use rayon::prelude::*;

/// Bytes of one sample of a ray being composited.
pub(crate) const BYTES_PER_SAMPLE: usize = size_of::<DVec4>();

/// What a ray's samples are made of, and how they make the pixel.
pub enum Shader<'a> {
    /// The voxels' colours and opacities (stage 1), interpolated and
    /// composited: the paper's.
    Pre(&'a ShadedVolume),
    /// Samples classified and shaded after interpolation, composited.
    Post(&'a PostClassifier<'a>),
    /// The interpolated scalar, projected by `blend` (not
    /// [`Blend::Composite`]).
    Projection {
        volume: &'a Volume,
        blend: Blend,
        /// Samples this skips are not counted ([`NonFinite`](crate::NonFinite)).
        mask: Option<&'a NonFiniteMask>,
    },
}

/// Renders `view` with `shader`, sampling as `sampling` says, into a
/// partial image (the background is applied when it is finished).
/// `progress` is called with the number of pixels finished, a row at a
/// time.
pub fn render(
    shader: &Shader,
    view: &View,
    sampling: &Sampling,
    progress: &Progress,
) -> PartialImage {
    let (width, height) = (view.width(), view.height());
    let dims = sampling.grid.dims;
    // Index-space positions of the samples of pixel (col, row), nearest first.
    let positions = |col: usize, row: usize| {
        (sampling.pixel(view, col, row).into_iter())
            .flat_map(move |r| (r.first..=r.last).map(move |k| r.position(k, dims).to_array()))
    };
    // Each row of pixels from its own rays, rows in parallel.
    fn rows<P: Send>(
        pixels: &mut [P],
        width: usize,
        progress: &Progress,
        pixel: impl Fn(usize, usize) -> P + Sync,
    ) {
        pixels
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(row, out)| {
                if progress.stopped() {
                    return;
                }
                for (col, p) in out.iter_mut().enumerate() {
                    *p = pixel(col, row);
                }
                progress.done(out.len());
            });
    }
    match shader {
        Shader::Pre(_) | Shader::Post(_) => {
            let mut image = PartialImage::composite(width, height);
            let PartialPixels::Composite(pixels) = image.pixels_mut() else {
                unreachable!("a composite image")
            };
            rows(pixels, width, progress, |col, row| {
                let samples: Vec<DVec4> = match shader {
                    Shader::Pre(shaded) => positions(col, row)
                        .map(|p| {
                            trilinear::reference(p, dims, DVec4::ZERO, |i| {
                                shaded.voxels[i].as_dvec4()
                            })
                        })
                        .collect(),
                    Shader::Post(post) => positions(col, row).map(|p| post.sample(p)).collect(),
                    Shader::Projection { .. } => unreachable!("a composite shader"),
                };
                back_to_front(&samples).as_vec4().to_array()
            });
            image
        }
        &Shader::Projection {
            volume,
            blend,
            mask,
        } => {
            let mut image = PartialImage::projection(width, height, blend);
            let PartialPixels::Projection { pixels, .. } = image.pixels_mut() else {
                unreachable!("a projection image")
            };
            // The reference path reads every value as f32, from a dense copy
            // where the samples are of another type.
            let values = volume.values();
            rows(pixels, width, progress, |col, row| {
                let mut projection = Projected::empty(blend);
                for p in positions(col, row) {
                    if mask.is_some_and(|m| m.skips(p.into())) {
                        continue;
                    }
                    let f = trilinear::reference(p, dims, 0.0, |i| values[i] as f64);
                    projection.add(blend, f);
                }
                projection
            });
            image
        }
    }
}
