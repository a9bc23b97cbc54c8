//! Stage 1 of the paper: every voxel gets a colour (shading) and an
//! opacity (classification) before any ray is cast.
//!
//! The colour is the lit colour of [`crate::kernels::phong`] times the material
//! colour of [`crate::transfer::classifier`], clamped to [0, 1]; the opacity is the
//! classified opacity of the voxel's value and gradient
//! ([`Classifier::opacity_at`]) corrected for the sampling step. Stage 2
//! interpolates these per-voxel values along the rays (pre-classification,
//! as in the paper and Levoy 1988). This is the reference path's stage 1, over every
//! voxel, dense; the fast path's is [`crate::bricks::occupied`] (view-independent,
//! kept across frames) and [`crate::cpu::lit_bricks`] (the light, per frame).

use crate::kernels::phong::{LightGeometry, Phong, Reaching, lit_colour_reached};
use crate::transfer::classifier::Classifier;
use crate::transfer::labels::colour_value;
use crate::volume::Volume;
use glam::{Vec3, Vec4};
use rayon::prelude::*;

/// Bytes per voxel of a [`ShadedVolume`].
pub(crate) const BYTES_PER_VOXEL: usize = size_of::<Vec4>();

/// Per-voxel colour and opacity: `(r, g, b, α)` with α per sample, x fastest.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadedVolume {
    pub dims: [usize; 3],
    pub voxels: Vec<Vec4>,
}

/// How much of the light and of the ambient light reaches each voxel (x
/// fastest), where the frame has shadows ([`crate::shadows`]) or ambient
/// occlusion ([`crate::shadows::ambient`]); `None`: all of it.
#[derive(Debug, Clone, Copy, Default)]
pub struct Reached<'a> {
    pub light: Option<&'a [f32]>,
    pub ambient: Option<&'a [f32]>,
}

/// Shades and classifies every voxel of `volume`. `gradients` are the
/// volume's (see [`crate::kernels::gradient`]); `lighting` is `None` for unlit
/// rendering (the colour is the material colour); `reached` is the light
/// and ambient light reaching each voxel.
pub fn shade_and_classify(
    volume: &Volume,
    gradients: &[[f32; 3]],
    classifier: &Classifier,
    lighting: Option<(&Phong, &LightGeometry)>,
    reached: Reached,
) -> ShadedVolume {
    let mut voxels = vec![Vec4::ZERO; volume.len()];
    let dims = volume.dims();
    let slice = dims[0] * dims[1];
    let values = volume.values();
    // A label volume's hidden voxels take a shown neighbour's colour.
    let shown = |f: f32| classifier.unit_opacity(f) > 0.0;
    let colour_of = |f: f32, at: usize| {
        if volume.is_labels() && !shown(f) {
            let voxel = [at % dims[0], (at / dims[0]) % dims[1], at / slice];
            classifier.material(colour_value(&values, dims, voxel, shown))
        } else {
            classifier.material(f)
        }
    };
    voxels
        .par_chunks_mut(slice)
        .zip(values.par_chunks(slice))
        .zip(gradients.par_chunks(slice))
        .enumerate()
        .for_each(|(k, ((out, values), grads))| {
            for (n, ((o, &f), g)) in out.iter_mut().zip(values).zip(grads).enumerate() {
                let at = k * slice + n;
                let reaching = Reaching {
                    light: reached.light.map_or(1.0, |l| l[at]),
                    ambient: reached.ambient.map_or(1.0, |a| a[at]),
                };
                let color =
                    lit_colour_reached(lighting, Vec3::from(*g), colour_of(f, at), reaching);
                *o = Vec3::from(color).extend(classifier.opacity_at(f, *g));
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
    use crate::kernels::gradient::{gradients, max_magnitude};
    use crate::transfer::classifier::OpacityMap;
    use crate::transfer::classifier::correct_opacity;
    use crate::transfer::function::PiecewiseLinear;
    use crate::transfer::iso::IsoSurface;
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
        let s = shade_and_classify(&v, &gradients(&v), &c, None, Reached::default());
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
        let s = shade_and_classify(
            &v,
            &gradients(&v),
            &c,
            Some((&Phong::default(), &light)),
            Reached::default(),
        );
        let got = s.voxels[v.index(1, 1, 1)];
        assert!(
            (got - Vec4::new(0.5, 0.25, 1.0, 0.5)).abs().max_element() < 1e-6,
            "{got:?}"
        );
    }

    /// Levoy's contour of `f_v` on `volume` as the renderer sets it up:
    /// `r` in voxels of the smallest spacing, the volume's largest gradient.
    fn iso_classifier(volume: &Volume, value: f32, thickness: f32, step: f32) -> Classifier {
        let c = Classifier::new((0.0, 10.0), OpacityMap::Ramp { p: 0.2, q: 0.6 }, None, step);
        let h = volume.spacing().min_element() as f32;
        let iso = IsoSurface { value, thickness };
        c.with_iso(iso, h, max_magnitude(volume))
    }

    #[test]
    fn iso_on_a_linear_ramp_is_a_slab_r_voxels_thick_either_side() {
        // f = x (world), so |f − f_v| / |∇f| is the distance to the plane
        // x = f_v and eq. 3 is α_v (1 − |x − x_v| / (r·h)): in voxels of the
        // smallest spacing h, whatever the spacing along the ramp. Spacings
        // 0.5 along x, 0.25 along y: h = 0.25.
        let v = Volume::from_fn([17, 3, 3], DVec3::new(0.5, 0.25, 1.0), DVec3::ZERO, |p| {
            p.x as f32
        })
        .unwrap();
        let g = gradients(&v);
        for (value, thickness, step) in [(3.0, 4.0, 1.0), (3.2, 4.0, 1.0), (4.1, 7.0, 0.5)] {
            let c = iso_classifier(&v, value, thickness, step);
            // With the ramp, α_v is its top opacity q.
            let alpha_v = c.iso().unwrap().alpha();
            assert_eq!(alpha_v, 0.6);
            let s = shade_and_classify(&v, &g, &c, None, Reached::default());
            let half_width = thickness * 0.25; // world units
            let mut opaque = 0;
            for i in 0..17 {
                let x = 0.5 * i as f32;
                let want = alpha_v * (1.0 - (x - value).abs() / half_width).max(0.0);
                let want = correct_opacity(want, step);
                for (j, k) in [(0, 0), (1, 2), (2, 1)] {
                    let got = s.voxels[v.index(i, j, k)].w;
                    assert!((got - want).abs() < 1e-6, "x {x}: {got} vs {want}");
                }
                opaque += (want > 0.0) as usize;
            }
            // The slab is 2·r·h wide: 2 world units (4 voxels of 0.5) for
            // r = 4, 3.5 for r = 7; an open interval of that width holds 3
            // or 4 (r = 4 at 3.0: x = 2.5, 3, 3.5) or 7 grid points.
            let want_count = match (value, thickness) {
                (3.0, _) => 3,
                (3.2, _) => 4,
                _ => 7,
            };
            assert_eq!(opaque, want_count, "f_v {value}, r {thickness}");
        }
        // The same slab along z, where the spacing is 1 but h is still
        // 0.25: r = 4 reaches 1 world unit, so only the voxel on the plane
        // is opaque.
        let vz = Volume::from_fn([3, 3, 9], DVec3::new(0.5, 0.25, 1.0), DVec3::ZERO, |p| {
            p.z as f32
        })
        .unwrap();
        let c = iso_classifier(&vz, 3.0, 4.0, 1.0);
        let s = shade_and_classify(&vz, &gradients(&vz), &c, None, Reached::default());
        let alphas: Vec<f32> = (0..9).map(|k| s.voxels[vz.index(1, 1, k)].w).collect();
        let mut want = vec![0.0; 9];
        want[3] = c.iso().unwrap().alpha();
        assert_eq!(alphas, want);
    }
}
