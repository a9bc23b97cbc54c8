//! A renderer's depth cues: the light reaching each voxel through the
//! volume (shadows, [`crate::shadows`]) and the ambient light reaching it
//! (ambient occlusion, [`crate::shadows::ambient`]). The reference path
//! marches them for each frame; the fast paths compute a volume of each
//! and keep it while what it was computed for holds (the light volume per
//! light direction and transfer function, the ambient volume per transfer
//! function and radius).

use super::Renderer;
use crate::bricks::BRICK;
use crate::kernels::gradient::Differences;
use crate::kernels::phong::LightGeometry;
use crate::settings::RenderSettings;
use crate::shadows::ambient::{self, AmbientRays};
use crate::shadows::ambient_volume::AmbientVolume;
use crate::shadows::light_volume::LightVolume;
use crate::shadows::opacities::VoxelOpacities;
use crate::shadows::{self, ShadowRay};
use crate::transfer::classifier::Classifier;
use crate::volume::Sample;
use rayon::prelude::*;
use std::sync::{Mutex, MutexGuard};

/// The voxels' opacities for a classifier and the shadow rays' step, and
/// the light volume swept from them for a light direction: an orbit under
/// a light that turns with the camera sweeps again each frame, from the
/// same opacities.
pub(crate) struct KeptLight {
    classifier: Classifier,
    /// The shadow rays' step in voxels (its bits).
    step: u64,
    opacities: VoxelOpacities,
    /// The direction towards the light (its bits), and the light volume.
    swept: Option<([u32; 3], LightVolume)>,
}

/// An ambient volume and what it was computed for.
pub(crate) struct KeptAmbient {
    /// The classifier and the radius (its bits).
    key: (Classifier, u64),
    ambient: AmbientVolume,
}

/// The step-corrected opacity of each voxel, for the fast paths' sweeps:
/// the classifier's, with the gradient only where it needs one; 0 for a
/// masked non-finite voxel and in a brick whose values are all
/// transparent, without classifying it (on the peers' 257³ cloud, a tenth
/// of the light sweep's time).
struct VoxelOpacity<'a, T, M> {
    data: &'a [T],
    differences: Differences<'a, T>,
    classifier: &'a Classifier,
    masked: M,
    /// Per brick of the macro-cells' grid, whether it is transparent.
    transparent: Vec<bool>,
    grid: crate::bricks::BrickGrid,
    dims: [usize; 3],
}

impl<'a, T: Sample, M: Fn(usize) -> bool> VoxelOpacity<'a, T, M> {
    fn new(renderer: &'a Renderer, data: &'a [T], classifier: &'a Classifier, masked: M) -> Self {
        let macrocells = renderer.macrocells();
        VoxelOpacity {
            data,
            differences: Differences::new(data, &renderer.volume),
            classifier,
            masked,
            transparent: (macrocells.ranges.iter())
                .map(|&(lo, hi)| classifier.is_transparent_between(lo, hi))
                .collect(),
            grid: macrocells.grid,
            dims: renderer.volume.dims(),
        }
    }

    #[inline]
    fn at(&self, i: usize, j: usize, k: usize) -> f32 {
        let brick: [usize; 3] =
            std::array::from_fn(|a| ([i, j, k][a] / BRICK).min(self.grid.bricks[a] - 1));
        if self.transparent[self.grid.index(brick)] {
            return 0.0;
        }
        let [nx, ny, _] = self.dims;
        let v = i + nx * (j + ny * k);
        if (self.masked)(v) {
            return 0.0;
        }
        let g = if self.classifier.uses_gradient() {
            self.differences.at(i, j, k)
        } else {
            [0.0; 3]
        };
        self.classifier.opacity_at(self.data[v].to_f32(), g)
    }
}

impl Renderer<'_> {
    /// The shadow rays of a frame of `settings` lit by `light`, and the
    /// classifier of their samples: a step of the frame's, or of one voxel
    /// where the frame's is shorter (see [`crate::shadows`]).
    pub(super) fn shadow_ray(
        &self,
        settings: &RenderSettings,
        light: &LightGeometry,
        classifier: &Classifier,
    ) -> (ShadowRay, Classifier) {
        let spacing = self.volume.spacing();
        let step = shadows::shadow_step(settings.step);
        let ray = ShadowRay::new(
            light.to_light.as_dvec3(),
            self.volume.dims(),
            spacing,
            step * spacing.min_element(),
        );
        (ray, classifier.with_step(step as f32))
    }

    /// The ambient occlusion's rays for a frame of `settings` with it, and
    /// the classifier of one voxel's length their opacities are corrected
    /// from.
    pub(super) fn ambient_rays(
        &self,
        settings: &RenderSettings,
        classifier: &Classifier,
    ) -> Option<(AmbientRays, Classifier)> {
        let radius = settings.ambient_occlusion?;
        let rays = AmbientRays::new(radius, self.volume.spacing());
        Some((rays, classifier.with_step(1.0)))
    }

    /// Every voxel's step-corrected opacity for `classifier` (stage 1's),
    /// from `gradients`; masked non-finite voxels are transparent.
    pub(super) fn opacities(&self, classifier: &Classifier, gradients: &[[f32; 3]]) -> Vec<f32> {
        let values = self.volume.values();
        let masked = self.masked();
        (values.par_iter().zip(gradients).enumerate())
            .map(|(v, (&f, &g))| {
                if masked(v) {
                    0.0
                } else {
                    classifier.opacity_at(f, g)
                }
            })
            .collect()
    }

    /// The reference path's light reaching every voxel, for a frame of
    /// `settings` with shadows (see [`crate::shadows`]).
    pub(super) fn reference_light(
        &self,
        settings: &RenderSettings,
        light: &LightGeometry,
        classifier: &Classifier,
        gradients: &[[f32; 3]],
    ) -> Vec<f32> {
        let (ray, classifier) = self.shadow_ray(settings, light, classifier);
        let alpha = self.opacities(&classifier, gradients);
        shadows::reference_light(&alpha, self.volume.dims(), &ray)
    }

    /// The reference path's ambient light reaching every voxel, for a frame
    /// of `settings` with ambient occlusion (`None` without).
    pub(super) fn reference_ambient(
        &self,
        settings: &RenderSettings,
        classifier: &Classifier,
        gradients: &[[f32; 3]],
    ) -> Option<Vec<f32>> {
        let (rays, unit) = self.ambient_rays(settings, classifier)?;
        let unit = self.opacities(&unit, gradients);
        Some(ambient::reference_occlusion(
            &unit,
            self.volume.dims(),
            &rays,
        ))
    }

    /// The kept light volume, locked for a frame; a frame without
    /// shadows drops it.
    pub(super) fn kept_light(&self, shadows: bool) -> MutexGuard<'_, Option<KeptLight>> {
        kept(&self.light, shadows)
    }

    /// The kept ambient volume, locked for a frame; a frame without
    /// ambient occlusion drops it.
    pub(super) fn kept_ambient(&self, on: bool) -> MutexGuard<'_, Option<KeptAmbient>> {
        kept(&self.ambient, on)
    }

    /// The fast paths' light volume for `classifier`, `light` and frames
    /// of `step`: swept ([`LightVolume::sweep`]) unless `kept` was swept for
    /// all three, from the voxels' opacities kept for `classifier` and the
    /// shadow rays' step (classified again only for another).
    pub(super) fn light_volume<'k>(
        &self,
        step: f64,
        classifier: &Classifier,
        light: &LightGeometry,
        kept: &'k mut Option<KeptLight>,
    ) -> &'k LightVolume {
        let step = shadows::shadow_step(step);
        if kept
            .as_ref()
            .is_none_or(|k| k.classifier != *classifier || k.step != step.to_bits())
        {
            *kept = None;
            let volume = &*self.volume;
            // Opacities for the shadow rays' samples, `step` voxels of
            // the shortest spacing apart.
            let for_step = &classifier.with_step(step as f32);
            let opacities = crate::with_samples!(volume.samples(), |data| {
                let alpha = VoxelOpacity::new(self, data, for_step, self.masked());
                let step_world = step * volume.spacing().min_element();
                VoxelOpacities::from_fn(volume.dims(), step_world, |i, j, k| alpha.at(i, j, k))
            });
            *kept = Some(KeptLight {
                classifier: classifier.clone(),
                step: step.to_bits(),
                opacities,
                swept: None,
            });
        }
        let kept = kept.as_mut().expect("classified above");
        let spacing = self.volume.spacing();
        let key = light.to_light.to_array().map(f32::to_bits);
        if kept.swept.as_ref().is_none_or(|(k, _)| *k != key) {
            let to_light = light.to_light.as_dvec3();
            let opacities = &mut kept.opacities;
            // The last light volume is swept again in place.
            let swept = match kept.swept.take() {
                Some((_, mut old)) => {
                    old.resweep(spacing, to_light, opacities);
                    old
                }
                None => LightVolume::sweep(spacing, to_light, opacities),
            };
            kept.swept = Some((key, swept));
        }
        &kept.swept.as_ref().expect("swept above").1
    }

    /// The fast paths' ambient volume for `classifier` and a frame of
    /// `settings` with ambient occlusion: computed
    /// ([`AmbientVolume::compute`]) unless `kept` was for both; `None`
    /// without ambient occlusion.
    pub(super) fn ambient_volume<'k>(
        &self,
        settings: &RenderSettings,
        classifier: &Classifier,
        kept: &'k mut Option<KeptAmbient>,
    ) -> Option<&'k AmbientVolume> {
        let radius = settings.ambient_occlusion?;
        let key = (classifier.clone(), radius.to_bits());
        if kept.as_ref().is_none_or(|k| k.key != key) {
            *kept = None;
            let (rays, unit) = self.ambient_rays(settings, classifier)?;
            let volume = &*self.volume;
            let ambient = crate::with_samples!(volume.samples(), |data| {
                let alpha = VoxelOpacity::new(self, data, &unit, self.masked());
                AmbientVolume::compute(volume.dims(), &rays, |i, j, k| alpha.at(i, j, k))
            });
            *kept = Some(KeptAmbient { key, ambient });
        }
        kept.as_ref().map(|k| &k.ambient)
    }
}

/// `slot` locked for a frame, emptied first where the frame does not use
/// what it keeps (`on` false): its memory goes back.
fn kept<T>(slot: &Mutex<Option<T>>, on: bool) -> MutexGuard<'_, Option<T>> {
    let mut guard = slot.lock().unwrap_or_else(|e| e.into_inner());
    if !on {
        *guard = None;
    }
    guard
}
