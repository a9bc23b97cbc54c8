//! The reference path of a scene's composite mix: every sample of every
//! volume, in `f64`, mixed ([`mix_reference`]) and composited back to
//! front with the paper's formula, as the single-volume reference
//! ([`crate::reference`]) does for one: the oracle of `fast.rs`.
//!
//! Each volume's samples are its own reference samples: pre-classified,
//! its voxels classified and shaded (stage 1) and interpolated; or
//! post-classified, its scalar and gradient interpolated and the sample
//! classified and shaded. A sample outside a volume's box (beyond a
//! millionth of a step) takes nothing from it.

use super::SceneFrame;
use crate::frame::partial::{PartialImage, PartialPixels};
use crate::frame::progress::Progress;
use crate::kernels::composite::back_to_front;
use crate::kernels::mix::mix_reference;
use crate::kernels::trilinear;
use crate::reference::post::PostClassifier;
use crate::reference::stage1::ShadedVolume;
use crate::renderer::Renderer;
use crate::sampling::grid::{GridFrame, clamp_to_grid};
use crate::settings::{Classification, RenderSettings};
use crate::transfer::classifier::Classifier;
use glam::{DVec3, DVec4};
use rayon::prelude::*;

/// What one volume's samples are made of.
enum Samples<'a> {
    Pre(ShadedVolume),
    Post(PostClassifier<'a>),
}

/// One volume of the frame: its grid in the world, and its samples.
struct Layer<'a> {
    grid: GridFrame,
    samples: Samples<'a>,
}

impl Layer<'_> {
    /// The sample at world point `p`, or `None` outside the volume's box
    /// (`tolerance`: world units of slack).
    fn sample(&self, p: DVec3, tolerance: f64) -> Option<DVec4> {
        let (lo, hi) = self.grid.bounds();
        if p.cmplt(lo - tolerance).any() || p.cmpgt(hi + tolerance).any() {
            return None;
        }
        let dims = self.grid.dims;
        let index = clamp_to_grid((p - self.grid.origin) / self.grid.spacing, dims).to_array();
        Some(match &self.samples {
            Samples::Pre(shaded) => {
                trilinear::reference(index, dims, DVec4::ZERO, |i| shaded.voxels[i].as_dvec4())
            }
            Samples::Post(post) => post.sample(index),
        })
    }
}

/// Renders `layers` (each volume shown, with its settings) mixed, as the
/// frame's settings `shared` say, into a partial image.
pub(super) fn render(
    layers: &[(&Renderer, &RenderSettings)],
    frame: &SceneFrame,
    shared: &RenderSettings,
    progress: &Progress,
) -> PartialImage {
    let view = &frame.view;
    let classifiers: Vec<Classifier> = layers.iter().map(|(r, s)| r.classifier(s)).collect();
    let layers: Vec<Layer> = (layers.iter().zip(&classifiers))
        .map(|(&(renderer, settings), classifier)| {
            let volume = renderer.volume();
            let samples = match shared.classification {
                Classification::Pre => Samples::Pre(renderer.stage1(settings, view)),
                Classification::Post => {
                    let light = Renderer::light(settings, view);
                    let lighting = settings.shading.then_some((&settings.phong, light));
                    Samples::Post(
                        PostClassifier::new(volume, classifier, lighting)
                            .with_mask(renderer.non_finite()),
                    )
                }
            };
            Layer {
                grid: GridFrame::of(volume),
                samples,
            }
        })
        .collect();
    let sampling = &frame.sampling;
    let tolerance = 1e-6 * sampling.step;
    let (width, height) = (view.width(), view.height());
    let mut image = PartialImage::composite(width, height);
    let PartialPixels::Composite(pixels) = image.pixels_mut() else {
        unreachable!("a composite image")
    };
    pixels
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, out)| {
            if progress.stopped() {
                return;
            }
            for (col, pixel) in out.iter_mut().enumerate() {
                let (origin, direction) = view.pixel_ray(col, row);
                let Some(ray) = sampling.ray(col, row, origin, direction) else {
                    continue;
                };
                let samples: Vec<DVec4> = (ray.first..=ray.last)
                    .map(|k| {
                        let p = origin + ray.t(k) * direction;
                        mix_reference(layers.iter().filter_map(|l| l.sample(p, tolerance)))
                    })
                    .collect();
                *pixel = back_to_front(&samples).as_vec4().to_array();
            }
            progress.done(out.len());
        });
    image
}
