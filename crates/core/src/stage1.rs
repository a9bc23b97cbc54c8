//! Stage 1 of the paper: every voxel gets a colour (shading) and an
//! opacity (classification) before any ray is cast.
//!
//! The colour is the lit colour of [`crate::shading`] times the material
//! colour of [`crate::classify`], clamped to [0, 1]; the opacity is the
//! classified opacity corrected for the sampling step. Stage 2 interpolates
//! these per-voxel values along the rays (pre-classification, as in the
//! paper and Levoy 1988). This is the reference path's stage 1, over every
//! voxel, dense; the fast path's is [`crate::classified`] (view-independent,
//! kept across frames) and [`crate::shade_bricks`] (the light, per frame).

use crate::classify::Classifier;
use crate::shading::{LightGeometry, Phong};
use crate::volume::Volume;
use glam::{Vec3, Vec4};
use rayon::prelude::*;

/// Per-voxel colour and opacity: `(r, g, b, α)` with α per sample, x fastest.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadedVolume {
    pub dims: [usize; 3],
    pub voxels: Vec<Vec4>,
}

/// Shades and classifies every voxel of `volume`. `gradients` are the
/// volume's (see [`crate::gradient`]); `lighting` is `None` for unlit
/// rendering (the colour is the material colour).
pub fn shade_and_classify(
    volume: &Volume,
    gradients: &[[f32; 3]],
    classifier: &Classifier,
    lighting: Option<(&Phong, &LightGeometry)>,
) -> ShadedVolume {
    let mut voxels = vec![Vec4::ZERO; volume.len()];
    let slice = volume.dims()[0] * volume.dims()[1];
    voxels
        .par_chunks_mut(slice)
        .zip(volume.data().par_chunks(slice))
        .zip(gradients.par_chunks(slice))
        .for_each(|((out, values), grads)| {
            for ((o, &f), g) in out.iter_mut().zip(values).zip(grads) {
                let material = Vec3::from(classifier.material(f));
                let lit = match lighting {
                    Some((phong, light)) => Vec3::from(phong.shade(Vec3::from(*g), light)),
                    None => Vec3::ONE,
                };
                let color = (lit * material).clamp(Vec3::ZERO, Vec3::ONE);
                *o = color.extend(classifier.sample_opacity(f));
            }
        });
    ShadedVolume {
        dims: volume.dims(),
        voxels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classify::OpacityMap;
    use crate::gradient::gradients;
    use crate::transfer_function::PiecewiseLinear;
    use glam::DVec3;

    #[test]
    fn unlit_voxels_take_the_material_colour_and_ramp_opacity() {
        let v = Volume::from_fn([3, 3, 3], DVec3::ONE, DVec3::ZERO, |p| p.x as f32).unwrap();
        let color = PiecewiseLinear::new(
            "color",
            vec![(0.0, [1.0, 0.0, 0.0]), (1.0, [0.0, 0.0, 1.0])],
        )
        .unwrap();
        let c = Classifier::new(
            (0.0, 2.0),
            OpacityMap::Ramp { p: 0.2, q: 0.6 },
            Some(color),
            1.0,
        );
        let s = shade_and_classify(&v, &gradients(&v), &c, None);
        assert_eq!(s.voxels[v.index(0, 1, 1)], Vec4::new(1.0, 0.0, 0.0, 0.2));
        assert!(
            (s.voxels[v.index(1, 2, 0)] - Vec4::new(0.5, 0.0, 0.5, 0.4))
                .abs()
                .max_element()
                < 1e-6
        );
        assert_eq!(s.voxels[v.index(2, 0, 2)], Vec4::new(0.0, 0.0, 1.0, 0.6));
    }

    #[test]
    fn lit_colour_is_multiplied_by_the_material() {
        // A ramp along x seen along the gradient by a headlight: full white
        // light times the material.
        let v = Volume::from_fn([3, 3, 3], DVec3::ONE, DVec3::ZERO, |p| p.x as f32).unwrap();
        let color = PiecewiseLinear::constant([0.5, 0.25, 1.0]);
        let c = Classifier::new(
            (0.0, 2.0),
            OpacityMap::Ramp { p: 0.0, q: 1.0 },
            Some(color),
            1.0,
        );
        let light = LightGeometry::headlight(Vec3::X);
        let s = shade_and_classify(&v, &gradients(&v), &c, Some((&Phong::default(), &light)));
        let got = s.voxels[v.index(1, 1, 1)];
        assert!(
            (got - Vec4::new(0.5, 0.25, 1.0, 0.5)).abs().max_element() < 1e-6,
            "{got:?}"
        );
    }
}
