//! The reference path: the paper's algorithm as written, generalised to
//! every rendering option, and the oracle every faster path is tested
//! against.
//!
//! For each pixel: take every sample of its ray ([`crate::sampling`]:
//! orthographic or perspective, cropped and clipped, jittered or not), in
//! `f64`, and make the pixel from them by the frame's [`Shader`]:
//!
//! - pre-classified (the paper's): interpolate the voxels' colours and
//!   opacities ([`crate::reference::stage1`]) trilinearly, drape the opaque background
//!   behind them as the last sample, and composite back to front with the
//!   paper's formula;
//! - post-classified: interpolate the scalar and the gradient, classify and
//!   shade each sample ([`crate::reference::post`]), composite alike;
//! - a projection (maximum, minimum, average; [`crate::kernels::projection`]): project the
//!   interpolated scalar and show it through the colour map.
//!
//! Non-finite voxels rendered as empty space ([`crate::non_finite`]) have
//! zero opacity in stage 1; post-classified and projected samples that a
//! non-finite voxel weighs in are skipped.
//!
//! No shortcuts: no early termination, no empty-space skipping.

pub mod post;
pub mod stage1;

use crate::camera::View;
use crate::image::Image;
use crate::kernels::composite::back_to_front;
use crate::kernels::projection::{ScalarProjection, projection_color};
use crate::kernels::trilinear::{sample_reference, scalar_reference};
use crate::non_finite::NonFiniteMask;
use crate::reference::post::PostClassifier;
use crate::reference::stage1::ShadedVolume;
use crate::sampling::Sampling;
use crate::settings::Blend;
use crate::transfer::classifier::Classifier;
use crate::volume::Volume;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// What a ray's samples are made of, and how they make the pixel.
pub enum Shader<'a> {
    /// The voxels' colours and opacities (stage 1), interpolated and
    /// composited: the paper's.
    Pre(&'a ShadedVolume),
    /// Samples classified and shaded after interpolation, composited.
    Post(&'a PostClassifier<'a>),
    /// The interpolated scalar, projected by `blend` (not
    /// [`Blend::Composite`]) and coloured by `classifier`.
    Projection {
        volume: &'a Volume,
        blend: Blend,
        classifier: &'a Classifier,
        /// Samples this skips are not counted ([`crate::non_finite`]).
        mask: Option<&'a NonFiniteMask>,
    },
}

/// Renders `view` with `shader`, sampling as `sampling` says, over the
/// opaque `background`. `progress` is called with the number of pixels
/// finished, a row at a time.
pub fn render(
    shader: &Shader,
    view: &View,
    sampling: &Sampling,
    background: [f32; 3],
    progress: &(dyn Fn(usize) + Sync),
) -> Image {
    let (width, height) = (view.width(), view.height());
    let bg = DVec3::from(background.map(f64::from));
    let dims = sampling.grid.dims;
    let mut image = Image::new(width, height, [0.0; 4]);
    image
        .pixels_mut()
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, pixels)| {
            let mut samples = Vec::new();
            for (col, pixel) in pixels.iter_mut().enumerate() {
                // Index-space positions of the ray's samples, nearest first.
                let positions = (sampling.pixel(view, col, row).into_iter())
                    .flat_map(|r| (r.first..=r.last).map(move |k| r.position(k, dims).to_array()));
                let rgba = match shader {
                    Shader::Pre(shaded) => {
                        samples.clear();
                        samples
                            .extend(positions.map(|p| sample_reference(&shaded.voxels, dims, p)));
                        back_to_front(&samples, bg)
                    }
                    Shader::Post(post) => {
                        samples.clear();
                        samples.extend(positions.map(|p| post.sample(p)));
                        back_to_front(&samples, bg)
                    }
                    Shader::Projection {
                        volume,
                        blend,
                        classifier,
                        mask,
                    } => {
                        let mut projection = ScalarProjection::new(*blend);
                        for p in positions {
                            if mask.is_some_and(|m| m.skips(p.into())) {
                                continue;
                            }
                            projection.add(scalar_reference(volume.data(), dims, p));
                        }
                        match projection.value() {
                            Some(f) => Vec3::from(projection_color(classifier, f as f32))
                                .as_dvec3()
                                .extend(1.0),
                            None => bg.extend(0.0),
                        }
                    }
                };
                *pixel = rgba.as_vec4().to_array();
            }
            progress(pixels.len());
        });
    image
}
