use super::light_volume::LightVolume;
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
    // step 1: the sweep's crossings are voxels and its segments one
    // sample long, so it equals the reference (to its 1/65535 units).
    let dims = [9, 7, 8];
    let alpha: Vec<f32> = (0..dims.iter().product::<usize>())
        .map(|v| ((v * 7919) % 13) as f32 / 20.0)
        .collect();
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
        let swept = LightVolume::sweep(dims, DVec3::ONE, to_light, 1.0, |i, j, k| {
            alpha[i + nx * (j + ny * k)]
        });
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

#[test]
fn the_sweep_corrects_each_segment_for_its_length() {
    // The light along the diagonal of a uniform medium: each slice's
    // segment is √3 voxels long, √3 samples of a step of 1, so a voxel
    // k slices from the lit face keeps (1 − α)^(k√3).
    let dims = [12, 12, 12];
    let light = LightVolume::sweep(dims, DVec3::ONE, DVec3::ONE, 1.0, |_, _, _| 0.1);
    for k in 0..4 {
        let v = 11 - k;
        let want = 0.9f32.powf(k as f32 * 3f32.sqrt());
        let got = light.at([v, v, v]);
        assert!((got - want).abs() < 1e-4, "{k} slices in: {got} vs {want}");
    }
    // A step of 0.5: the same medium corrected for it keeps as much.
    let half = 1.0 - 0.9f32.powf(0.5);
    let light = LightVolume::sweep(dims, DVec3::ONE, DVec3::ONE, 0.5, |_, _, _| half);
    let got = light.at([8, 8, 8]);
    assert!((got - 0.9f32.powf(3.0 * 3f32.sqrt())).abs() < 1e-4, "{got}");
}

#[test]
fn the_light_volume_interpolates_between_voxels() {
    let dims = [4, 4, 4];
    // Opacity 0.5 in the top slice only, the light from above: every
    // voxel below it keeps half the light.
    let light = LightVolume::sweep(dims, DVec3::ONE, DVec3::Z, 1.0, |_, _, k| {
        if k == 3 { 0.5 } else { 0.0 }
    });
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
    let alpha: Vec<f32> = (0..dims.iter().product::<usize>())
        .map(|v| ((v * 31) % 7) as f32 / 10.0)
        .collect();
    let [nx, ny, nz] = dims;
    let ray = ShadowRay::new(DVec3::Z, dims, DVec3::ONE, 10.0);
    let reference = reference_light(&alpha, dims, &ray);
    let swept = LightVolume::sweep(dims, DVec3::ONE, DVec3::Z, 10.0, |i, j, k| {
        alpha[i + nx * (j + ny * k)]
    });
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let (want, got) = (reference[i + nx * (j + ny * k)], swept.at([i, j, k]));
                assert!((got - want).abs() < 1e-4, "{i},{j},{k}: {got} vs {want}");
            }
        }
    }
}
