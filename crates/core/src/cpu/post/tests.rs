//! Unit tests of the post-classification caster: the packed voxels, and
//! the images and the work skipped against the reference's.

use super::scene::PostWork;
use super::*;
use crate::bricks::macrocells::Macrocells;
use crate::frame::progress::Progress;
use crate::kernels::composite::Finish;
use crate::kernels::phong::LightGeometry;
use crate::kernels::trilinear::{cell_of, corners, interpolate};
use crate::transfer::iso::IsoSurface;
use crate::volume::Volume;
use crate::{FrameRequest, Render};
use glam::Vec3;

#[test]
fn packed_voxels_interpolate_to_the_scalar_and_the_gradient_of_the_reference() {
    use crate::kernels::gradient::gradients;
    use crate::kernels::trilinear::{reference, sample_scalar};
    use glam::DVec3;
    // Values from a hash of the index: nothing a layout bug could hide behind.
    let volume = Volume::from_fn([7, 5, 6], DVec3::new(1.0, 0.5, 2.0), DVec3::ZERO, |p| {
        let (i, j, k) = (p.x as u32, (p.y / 0.5) as u32, (p.z / 2.0) as u32);
        let h =
            (i.wrapping_mul(73_856_093) ^ j.wrapping_mul(19_349_663)) ^ k.wrapping_mul(83_492_791);
        (h % 1000) as f32 / 37.0 - 9.0
    })
    .unwrap();
    let dims = volume.dims();
    let grads = gradients(&volume);
    let voxels = packed_voxels(&volume, &grads);
    let [x, y, z, f] = voxels[3 + 7 * (2 + 5 * 4)].to_array();
    assert_eq!(
        ([x, y, z], f),
        (grads[3 + 7 * (2 + 5 * 4)], volume.get(3, 2, 4))
    );
    // The interpolation of `march`, on the packed lanes.
    let mut s = 0.618_034_f64;
    for _ in 0..500 {
        let p = Vec3::from(std::array::from_fn(|a| {
            s = (s * 9301.0 + 0.49297).fract();
            (s * (dims[a] - 1) as f64) as f32
        }));
        let (c, offsets) = cell_of(p, dims.map(|n| n - 2));
        let (sy, sz) = (dims[0], dims[0] * dims[1]);
        let base = c[0] + sy * c[1] + sz * c[2];
        let [x, y, z, f] = interpolate(corners(|i| voxels[i], base, sy, sz), offsets).to_array();
        // The value lane is the scalar lerps' value to the last bit.
        let scalar = sample_scalar(&volume.values(), dims, p);
        assert_eq!(f.to_bits(), scalar.to_bits(), "{p}");
        let want = reference([p.x, p.y, p.z].map(f64::from), dims, DVec3::ZERO, |i| {
            Vec3::from(grads[i]).as_dvec3()
        });
        let got = DVec3::new(x as f64, y as f64, z as f64);
        assert!(
            (got - want).abs().max_element() < 1e-4,
            "{p}: {got} vs {want}"
        );
    }
}

use crate::camera::View;
use crate::camera::{Camera, Projection};
use crate::frame::image::Image;
use crate::frame::partial::{PartialImage, PartialPixels};
use crate::kernels::gradient::gradients;
use crate::renderer::Renderer;
use crate::settings::{Classification, Method, RenderSettings};
use glam::DVec3;

fn on_the_reference(settings: &RenderSettings) -> RenderSettings {
    RenderSettings {
        method: Method::Reference,
        ..settings.clone()
    }
}

/// 48³ of nothing but three small dense features: a 3³ block deep behind
/// empty bricks (seen along −x, the eye is on +x), a single voxel on a
/// brick corner, and a 2-voxel rod lying in a brick face.
fn sparse() -> Volume {
    let n = 48;
    Volume::from_fn([n, n, n], DVec3::ONE, DVec3::ZERO, |p| {
        let (x, y, z) = (p.x as usize, p.y as usize, p.z as usize);
        let block = (3..6).contains(&x) && (30..33).contains(&y) && (10..13).contains(&z);
        let corner = (x, y, z) == (16, 16, 24);
        let rod = x == 8 && y == 40 && (20..22).contains(&z);
        if block || corner || rod { 1.0 } else { 0.0 }
    })
    .unwrap()
}

/// Renders `settings` with [`render`] directly, to see its work.
fn post_cast_work(renderer: &Renderer, settings: &RenderSettings) -> (Image, PostWork, usize) {
    let volume = renderer.volume();
    let frame = renderer.prepare(settings).unwrap();
    let classifier = renderer.classifier(settings);
    let voxels = packed_voxels(volume, &gradients(volume));
    let macrocells = Macrocells::new(volume);
    let light = LightGeometry::headlight((-frame.view.direction()).as_vec3());
    let scene = Scene {
        voxels: &voxels,
        macrocells: &macrocells,
        classifier: &classifier,
        lighting: Some((&settings.phong, light)),
        mask: None,
        light: None,
        ambient: None,
    };
    let mut partial = PartialImage::composite(settings.width, settings.height);
    let PartialPixels::Composite(pixels) = partial.pixels_mut() else {
        unreachable!()
    };
    let work = render(
        &scene,
        &frame.view,
        &frame.sampling,
        pixels,
        Finish::Partial,
        &Progress::new(&|_| {}),
    );
    let image = renderer.finish(settings, partial);
    (image, work, frame.nominal_samples())
}

#[test]
fn empty_bricks_are_skipped_and_small_features_behind_them_are_found() {
    let volume = sparse();
    let renderer = Renderer::new(&volume).unwrap();
    let cameras = [
        Camera::default(),
        Camera {
            view_point: Some(DVec3::new(100.0, 30.0, 45.0)),
            ..Camera::default()
        },
        Camera {
            projection: Projection::Perspective { fov_degrees: 50.0 },
            azimuth: 20.0,
            elevation: -15.0,
            ..Camera::default()
        },
    ];
    for camera in cameras {
        // The paper's ramp from 0: the empty bricks (all 0, the minimum)
        // are transparent; a dense voxel's opacity is 0.9.
        let s = RenderSettings {
            width: 96,
            height: 96,
            camera,
            step: 0.5,
            opacity_ramp: (0.0, 0.9),
            classification: Classification::Post,
            ..RenderSettings::default()
        };
        let (image, work, nominal) = post_cast_work(&renderer, &s);
        // The renderer's fast path is this very function.
        assert!(
            image == renderer.render(FrameRequest::new(&s)).unwrap().image(),
            "{camera:?}"
        );
        let slow = renderer
            .render(FrameRequest::new(&on_the_reference(&s)))
            .unwrap()
            .image();
        assert!(
            image.max_abs_diff(&slow).unwrap() <= 1.0 / 255.0,
            "{camera:?}"
        );
        // Most samples lie in empty bricks and are never interpolated.
        println!("{camera:?}: {work:?} of {nominal} nominal samples");
        assert!(work.bricks_skipped > 10_000, "{work:?}");
        assert!(work.samples * 10 < nominal as u64, "{work:?} of {nominal}");
        // Each feature shows where its centre projects.
        let view = View::frame(&camera, volume.bounds(), 96, 96).unwrap();
        for centre in [
            DVec3::new(4.0, 31.0, 11.0),
            DVec3::new(16.0, 16.0, 24.0),
            DVec3::new(8.0, 40.0, 20.5),
        ] {
            let (c, r) = view.project(centre).unwrap();
            let alpha = image.get(c as usize, r as usize)[3];
            assert!(
                alpha > 0.3,
                "{camera:?}: feature at {centre} has alpha {alpha}"
            );
        }
    }
}

#[test]
fn bricks_near_an_isovalue_are_visited_and_far_ones_skipped() {
    // With an iso-surface, a brick is skipped only if its values lie
    // farther from the isovalue than the contour can reach at the
    // volume's steepest gradient. The steepest is at the block's corners,
    // |∇f| = |(½, ½, ½)| = √3/2 per voxel, so a contour 0.5 voxels thick
    // reaches 0.43 from the isovalue 0.5: the empty bricks (all 0) are
    // skipped, and the features' bricks are not.
    let volume = sparse();
    let renderer = Renderer::new(&volume).unwrap();
    assert!((renderer.max_gradient() - 0.75f32.sqrt()).abs() < 1e-6);
    let s = RenderSettings {
        width: 64,
        height: 64,
        step: 0.5,
        classification: Classification::Post,
        iso: Some(IsoSurface {
            value: 0.5,
            thickness: 0.5,
        }),
        ..RenderSettings::default()
    };
    let (fast, work, nominal) = post_cast_work(&renderer, &s);
    assert!(fast == renderer.render(FrameRequest::new(&s)).unwrap().image());
    let slow = renderer
        .render(FrameRequest::new(&on_the_reference(&s)))
        .unwrap()
        .image();
    assert!(fast.max_abs_diff(&slow).unwrap() <= 1.0 / 255.0);
    assert!(slow.pixels().iter().filter(|p| p[3] > 0.3).count() >= 4);
    println!("iso: {work:?} of {nominal} nominal samples");
    assert!(work.bricks_skipped > 1000, "{work:?}");
    assert!(work.samples * 10 < nominal as u64, "{work:?} of {nominal}");
    // A contour reaching every value (a thickness of 100 voxels) rules
    // out no brick.
    let thick = RenderSettings {
        iso: Some(IsoSurface {
            value: 0.5,
            thickness: 100.0,
        }),
        ..s
    };
    let (fast, work, _) = post_cast_work(&renderer, &thick);
    assert_eq!(work.bricks_skipped, 0);
    let slow = renderer
        .render(FrameRequest::new(&on_the_reference(&thick)))
        .unwrap()
        .image();
    assert!(fast.max_abs_diff(&slow).unwrap() <= 1.0 / 255.0);
}
