//! Pre- or post-classification: whether voxels or samples are classified.
//!
//! The paper (after Levoy 1988) classifies and shades every voxel, then
//! interpolates the colours and opacities along the rays
//! (pre-classification, [`crate::reference::stage1`]). Post-classification
//! interpolates the scalar and the gradient at each sample instead, then
//! classifies and shades the sample (Engel et al., *Real-Time Volume
//! Graphics*, 2006, §4.4): a transfer function with sharp features is then
//! resolved at the sampling rate rather than blurred over a cell, at the
//! cost of classifying and shading every sample. The gradient at a sample
//! is the trilinear interpolation of the voxels' central-difference
//! gradients ([`crate::kernels::gradient`]), as GPU ray casters sample a gradient
//! volume.
//!
//! A sample's colour and opacity follow the very formulas of a voxel's in
//! [`crate::reference::stage1`]: the lit colour ([`crate::kernels::phong`]) times the
//! material colour, clamped to [0, 1], and the classifier's
//! [`Classifier::opacity_at`], step-corrected. So on data where
//! interpolation commutes with classification (a uniform medium) both give
//! the same picture.

use crate::kernels::gradient::gradients;
use crate::kernels::phong::{LightGeometry, Phong, Reaching, lit_colour_reached};
use crate::kernels::trilinear;
use crate::shadows::ShadowRay;
use crate::transfer::classifier::Classifier;
use crate::volume::Volume;
use crate::volume::non_finite::NonFiniteMask;
use glam::{DVec3, DVec4, Vec3};
use std::borrow::Cow;

/// Classifies and shades samples of one volume for one frame.
pub struct PostClassifier<'a> {
    volume: &'a Volume,
    /// The volume's values as `f32` (the reference path is dense).
    values: Cow<'a, [f32]>,
    gradients: Vec<[f32; 3]>,
    classifier: &'a Classifier,
    lighting: Option<(&'a Phong, LightGeometry)>,
    /// Samples this skips are empty ([`NonFinite`](crate::NonFinite)).
    mask: Option<&'a NonFiniteMask>,
    /// With shadows: the voxels' step-corrected opacities (stage 1's) and
    /// the shadow rays marched through them ([`crate::shadows`]).
    shadows: Option<(&'a [f32], ShadowRay)>,
    /// With ambient occlusion: the ambient light reaching each voxel, the
    /// reference's march ([`crate::shadows::ambient`]).
    ambient: Option<&'a [f32]>,
}

impl<'a> PostClassifier<'a> {
    /// Samples of `volume` classified by `classifier` and lit by `lighting`
    /// (`None`: unlit, the material colour).
    pub fn new(
        volume: &'a Volume,
        classifier: &'a Classifier,
        lighting: Option<(&'a Phong, LightGeometry)>,
    ) -> Self {
        Self::with_gradients(volume, gradients(volume), classifier, lighting)
    }

    /// [`Self::new`] with the volume's `gradients` already computed
    /// ([`crate::kernels::gradient::gradients`]).
    pub fn with_gradients(
        volume: &'a Volume,
        gradients: Vec<[f32; 3]>,
        classifier: &'a Classifier,
        lighting: Option<(&'a Phong, LightGeometry)>,
    ) -> Self {
        PostClassifier {
            volume,
            values: volume.values(),
            gradients,
            classifier,
            lighting,
            mask: None,
            shadows: None,
            ambient: None,
        }
    }

    /// The same, each sample lit by the light reaching it through the
    /// voxels' opacities `alpha`, along `ray` ([`crate::shadows`]).
    pub fn with_shadows(self, alpha: &'a [f32], ray: ShadowRay) -> Self {
        PostClassifier {
            shadows: Some((alpha, ray)),
            ..self
        }
    }

    /// The same, each sample lit by the ambient light reaching the voxels,
    /// `ambient`, interpolated trilinearly as their gradients are
    /// ([`crate::shadows::ambient`]).
    pub fn with_ambient_occlusion(self, ambient: &'a [f32]) -> Self {
        PostClassifier {
            ambient: Some(ambient),
            ..self
        }
    }

    /// The same, for a cleaned volume: a sample `mask` skips (a non-finite
    /// voxel of the original weighs in it) is empty, zero colour and
    /// opacity.
    pub fn with_mask(self, mask: Option<&'a NonFiniteMask>) -> Self {
        PostClassifier { mask, ..self }
    }

    /// Colour and opacity `(r, g, b, α)` of the sample at index-space point `p`.
    pub fn sample(&self, p: [f64; 3]) -> DVec4 {
        if self.mask.is_some_and(|m| m.skips(p.into())) {
            return DVec4::ZERO;
        }
        let dims = self.volume.dims();
        let f = trilinear::reference(p, dims, 0.0, |i| self.values[i] as f64) as f32;
        let g = trilinear::reference(p, dims, DVec3::ZERO, |i| {
            Vec3::from(self.gradients[i]).as_dvec3()
        })
        .as_vec3();
        let lighting = self.lighting.as_ref().map(|(phong, light)| (*phong, light));
        let opacity = self.classifier.opacity_at(f, g.to_array());
        // A transparent sample's colour counts for nothing: no march.
        let light = match &self.shadows {
            Some((alpha, ray)) if opacity > 0.0 => {
                let alpha = |q| trilinear::reference(q, dims, 0.0, |i| alpha[i] as f64);
                ray.transmittance(DVec3::from_array(p), alpha) as f32
            }
            _ => 1.0,
        };
        let ambient = match self.ambient {
            Some(a) if opacity > 0.0 => trilinear::reference(p, dims, 0.0, |i| a[i] as f64) as f32,
            _ => 1.0,
        };
        let reaching = Reaching { light, ambient };
        let color = lit_colour_reached(lighting, g, self.classifier.material(f), reaching);
        Vec3::from(color).extend(opacity).as_dvec4()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::classifier::OpacityMap;
    use crate::transfer::function::PiecewiseLinear;
    use glam::DVec3;

    #[test]
    fn samples_between_voxels_classify_the_interpolated_value() {
        // f = x on [0, 4]; a colour ramp red → blue and the ramp opacity
        // 0.1 + 0.4t, at a sample a quarter of the way along the second cell
        // (x = 1.25, t = 0.3125): the colour and opacity of the value there.
        let v = Volume::from_fn([5, 3, 3], DVec3::ONE, DVec3::ZERO, |p| p.x as f32).unwrap();
        let color = PiecewiseLinear::new(
            "color",
            vec![(0.0, [1.0, 0.0, 0.0]), (1.0, [0.0, 0.0, 1.0])],
        )
        .unwrap();
        let c = Classifier::new(
            (0.0, 4.0),
            OpacityMap::Ramp { p: 0.1, q: 0.5 },
            Some(color),
            1.0,
        );
        let post = PostClassifier::new(&v, &c, None);
        let s = post.sample([1.25, 0.5, 1.0]);
        let want = DVec4::new(0.6875, 0.0, 0.3125, 0.1 + 0.4 * 0.3125);
        assert!((s - want).abs().max_element() < 1e-6, "{s:?}");
    }

    #[test]
    fn lit_samples_use_the_interpolated_gradient() {
        // f = x·y: at (1.5, 2, ·) the central-difference gradients of the
        // four surrounding voxels interpolate to (2, 1.5, 0). A light along
        // that gradient lights the sample fully; one along z leaves ambient.
        let v =
            Volume::from_fn([4, 5, 3], DVec3::ONE, DVec3::ZERO, |p| (p.x * p.y) as f32).unwrap();
        let c = Classifier::new((0.0, 12.0), OpacityMap::Ramp { p: 0.0, q: 1.0 }, None, 1.0);
        let phong = Phong::default();
        let n = Vec3::new(2.0, 1.5, 0.0).normalize();
        let facing = PostClassifier::new(&v, &c, Some((&phong, LightGeometry::headlight(n))));
        let s = facing.sample([1.5, 2.0, 1.0]);
        assert!(
            (s.truncate() - DVec3::ONE).abs().max_element() < 1e-5,
            "{s:?}"
        );
        assert!((s.w - 3.0 / 12.0).abs() < 1e-6);
        let edge_on =
            PostClassifier::new(&v, &c, Some((&phong, LightGeometry::headlight(Vec3::Z))));
        let s = edge_on.sample([1.5, 2.0, 1.0]);
        assert!(
            (s.truncate() - DVec3::splat(0.1)).abs().max_element() < 1e-5,
            "{s:?}"
        );
    }
}
