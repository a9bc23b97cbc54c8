use super::light_volume::{Isa, LightVolume};
use super::opacities::VoxelOpacities;
use super::*;

/// A uniform medium of step-corrected opacity `alpha` on `dims` voxels.
fn uniform(dims: [usize; 3], alpha: f32) -> Vec<f32> {
    vec![alpha; dims.iter().product()]
}

#[test]
fn a_shadow_ray_through_a_uniform_medium_keeps_one_minus_alpha_per_sample() {
    // Along +z from voxel z = 3 of 10: samples at z = 4..=9, six of them.
    let dims = [6, 5, 10];
    let alpha = uniform(dims, 0.2);
    let sample = |p: [f64; 3]| trilinear::reference(p, dims, 0.0, |v| alpha[v] as f64);
    let ray = ShadowRay::new(DVec3::Z, dims, DVec3::ONE, 1.0);
    let t = ray.transmittance(DVec3::new(2.0, 2.0, 3.0), sample);
    assert!((t - 0.8f64.powi(6)).abs() < 1e-7, "{t}");
    // Half the step: twice the samples (of the same corrected opacity).
    let ray = ShadowRay::new(DVec3::Z, dims, DVec3::ONE, 0.5);
    let t = ray.transmittance(DVec3::new(2.0, 2.0, 3.0), sample);
    assert!((t - 0.8f64.powi(12)).abs() < 1e-7, "{t}");
    // On the face towards the light: nothing in the way.
    let t = ray.transmittance(DVec3::new(2.0, 2.0, 9.0), sample);
    assert_eq!(t, 1.0);
    // Spacing 2 along z, the step in world units 1: samples every half
    // voxel, z = 3.5..=9, twelve of them.
    let ray = ShadowRay::new(DVec3::Z, dims, DVec3::new(1.0, 1.0, 2.0), 1.0);
    let t = ray.transmittance(DVec3::new(2.0, 2.0, 3.0), sample);
    assert!((t - 0.8f64.powi(12)).abs() < 1e-7, "{t}");
}

#[test]
fn the_sweep_along_an_axis_takes_the_marchs_very_samples() {
    // A lumpy medium, the light along each axis both ways, spacing 1 and
    // step 1: the sweep's crossings are voxels, as the march's samples
    // are, so it equals the reference (to its 1/65535 units) on the same
    // (quantised) opacities.
    let dims = [9, 7, 8];
    let mut opacities = VoxelOpacities::from_fn(dims, 1.0, |i, j, k| {
        ((i + 9 * (j + 7 * k)) * 7919 % 13) as f32 / 20.0
    });
    let alpha = voxels(&opacities);
    let [nx, ny, _] = dims;
    for to_light in [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ] {
        let ray = ShadowRay::new(to_light, dims, DVec3::ONE, 1.0);
        let reference = reference_light(&alpha, dims, &ray);
        let swept = LightVolume::sweep(DVec3::ONE, to_light, &mut opacities);
        for k in 0..dims[2] {
            for j in 0..ny {
                for i in 0..nx {
                    let want = reference[i + nx * (j + ny * k)];
                    let got = swept.at([i, j, k]);
                    assert!(
                        (got - want).abs() <= 0.6 / 65535.0,
                        "towards {to_light} at {i},{j},{k}: swept {got}, marched {want}"
                    );
                }
            }
        }
    }
}

/// Every voxel's opacity, x fastest.
fn voxels(opacities: &VoxelOpacities) -> Vec<f32> {
    let [nx, ny, nz] = opacities.dims();
    (0..nz)
        .flat_map(|k| (0..ny).flat_map(move |j| (0..nx).map(move |i| [i, j, k])))
        .map(|v| opacities.at(v))
        .collect()
}

#[test]
fn the_sweep_corrects_each_segment_for_its_length() {
    // The light along the diagonal of a uniform medium: each slice's
    // segment is √3 voxels long, so a voxel k slices from the lit face
    // keeps (1 − α)^(k√3).
    let dims = [12, 12, 12];
    let mut opacities = VoxelOpacities::from_fn(dims, 1.0, |_, _, _| 0.1);
    let light = LightVolume::sweep(DVec3::ONE, DVec3::ONE, &mut opacities);
    let alpha = opacities.at([0, 0, 0]);
    for k in 0..4 {
        let v = 11 - k;
        let want = (1.0 - alpha).powf(k as f32 * 3f32.sqrt());
        let got = light.at([v, v, v]);
        assert!((got - want).abs() < 1e-4, "{k} slices in: {got} vs {want}");
    }
    // A grid of spacing 2 whose medium keeps 0.9 of the light a voxel,
    // its opacities for a step of half a voxel: the same.
    let half = 1.0 - 0.9f32.powf(0.5);
    let mut opacities = VoxelOpacities::from_fn(dims, 1.0, |_, _, _| half);
    let light = LightVolume::sweep(DVec3::splat(2.0), DVec3::ONE, &mut opacities);
    let got = light.at([8, 8, 8]);
    let want = 0.9f32.powf(3.0 * 3f32.sqrt());
    assert!((got - want).abs() < 1e-4, "{got} vs {want}");
}

#[test]
fn the_light_volume_interpolates_between_voxels() {
    let dims = [4, 4, 4];
    // Opacity 0.5 in the top slice only, the light from above: every
    // voxel below it keeps half the light.
    let mut opacities =
        VoxelOpacities::from_fn(dims, 1.0, |_, _, k| if k == 3 { 0.5 } else { 0.0 });
    let light = LightVolume::sweep(DVec3::ONE, DVec3::Z, &mut opacities);
    assert_eq!(light.at([1, 1, 3]), 1.0);
    assert!((light.at([1, 1, 2]) - 0.5).abs() < 1e-4);
    let between = light.sample(glam::Vec3::new(1.5, 2.0, 2.5));
    assert!((between - 0.75).abs() < 1e-4, "{between}");
    assert_eq!(light.bytes(), 64 * light_volume::BYTES_PER_VOXEL);
}

#[test]
fn a_step_of_many_slices_sweeps_as_the_march_takes_it() {
    // Step 10 along z: one sample every ten slices, farther than the
    // segments reach by default; the sweep reads only slices it has done
    // and still takes the march's samples.
    let dims = [5, 4, 31];
    let mut opacities = VoxelOpacities::from_fn(dims, 10.0, |i, j, k| {
        ((i + 5 * (j + 4 * k)) * 31 % 7) as f32 / 10.0
    });
    let alpha = voxels(&opacities);
    let [nx, ny, nz] = dims;
    let ray = ShadowRay::new(DVec3::Z, dims, DVec3::ONE, 10.0);
    let reference = reference_light(&alpha, dims, &ray);
    let swept = LightVolume::sweep(DVec3::ONE, DVec3::Z, &mut opacities);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let (want, got) = (reference[i + nx * (j + ny * k)], swept.at([i, j, k]));
                assert!((got - want).abs() < 1e-4, "{i},{j},{k}: {got} vs {want}");
            }
        }
    }
}

#[test]
fn the_sweep_is_the_same_whether_it_reuses_a_light_volume_or_not() {
    let dims = [11, 9, 10];
    let mut opacities = VoxelOpacities::from_fn(dims, 1.0, |i, j, k| {
        ((i * 31 + j * 17 + k * 7) % 11) as f32 / 30.0
    });
    let mut reused = LightVolume::sweep(DVec3::ONE, DVec3::new(0.2, 1.0, 0.4), &mut opacities);
    let to_light = DVec3::new(-0.7, 0.3, 0.9);
    reused.resweep(DVec3::ONE, to_light, &mut opacities);
    assert_eq!(
        reused,
        LightVolume::sweep(DVec3::ONE, to_light, &mut opacities)
    );
}

#[test]
fn the_sweep_compiled_for_avx2_finds_the_same_light_as_the_baselines() {
    // A lumpy medium with clear gaps (rows skip samples), lights that
    // leave by every side (the band at each end of the rows) and one
    // along an axis; the rows are 37 voxels, not a multiple of 8.
    let dims = [37, 21, 26];
    let mut opacities = VoxelOpacities::from_fn(dims, 1.0, |i, j, k| {
        let lumpy = ((i * 31 + j * 17 + k * 7) % 11) as f32 / 12.0;
        if (i / 5 + j / 4) % 3 == 0 { 0.0 } else { lumpy }
    });
    // Under CI the machine has AVX2, so that the AVX2 path is the one
    // tested.
    let best = Isa::best();
    if std::env::var_os("CI").is_some() && cfg!(target_arch = "x86_64") {
        assert_ne!(best, Isa::baseline(), "CI's machine has no AVX2");
    }
    for to_light in [
        DVec3::new(0.7, -0.4, 1.0),
        DVec3::new(-1.0, 0.5, 0.3),
        DVec3::new(0.2, 1.0, -0.6),
        DVec3::Z,
    ] {
        let mut swept = Vec::new();
        for isa in [best, Isa::baseline()] {
            let mut light = LightVolume::sweep(DVec3::ONE, DVec3::X, &mut opacities);
            light.resweep_for(isa, DVec3::new(1.0, 1.2, 0.8), to_light, &mut opacities);
            swept.push(light);
        }
        assert!(swept[0] == swept[1], "{to_light}: the light differs");
        let lit = (0..26).filter(|&k| swept[0].at([18, 10, k]) < 0.9).count();
        assert!(lit > 0, "{to_light}: the medium casts no shadow");
    }
}
