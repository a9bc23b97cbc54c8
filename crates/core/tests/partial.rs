//! Partial images: a frame before its background, and the pieces of a
//! volume composited after they are rendered apart (sort-last, as ranks of
//! a cluster or tiles would). Finishing a partial image gives exactly the
//! frame `render` gives, on every path; a volume cut in two along the
//! view, each half rendered as a partial image (cropped to its half, the
//! same samples as the whole), the front one combined over the back one,
//! gives the whole volume's frame, within rounding and early termination.

mod common;

use common::{blobs, colorful, on_the_reference};
use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::{
    Blend, Classification, Image, PartialImage, RenderSettings, Renderer, TransferFunction,
};
use volray_core::{FrameRequest, Render};

fn volume() -> volray_core::Volume {
    blobs([33, 29, 25], DVec3::new(1.0, 1.2, 0.9), DVec3::ZERO)
}

/// Every path: fast and reference, pre- and post-classified, the three
/// projections, orthographic and perspective.
fn every_path() -> Vec<(String, RenderSettings)> {
    let base = RenderSettings {
        width: 48,
        height: 40,
        transfer_function: colorful(),
        background: [0.2, 0.3, 0.4],
        ..RenderSettings::default()
    };
    let mut cases = Vec::new();
    for perspective in [false, true] {
        let camera = Camera {
            projection: if perspective {
                Projection::Perspective { fov_degrees: 40.0 }
            } else {
                Projection::Orthographic
            },
            azimuth: 25.0,
            elevation: 15.0,
            ..Camera::default()
        };
        let variants = [
            ("pre", Blend::Composite, Classification::Pre),
            ("post", Blend::Composite, Classification::Post),
            ("maximum", Blend::Maximum, Classification::Pre),
            ("minimum", Blend::Minimum, Classification::Pre),
            ("average", Blend::Average, Classification::Pre),
        ];
        for (name, blend, classification) in variants {
            let s = RenderSettings {
                camera,
                blend,
                classification,
                ..base.clone()
            };
            let view = if perspective {
                "perspective"
            } else {
                "orthographic"
            };
            cases.push((format!("{name}, {view}, reference"), on_the_reference(&s)));
            cases.push((format!("{name}, {view}, fast"), s));
        }
    }
    cases
}

#[test]
fn a_finished_partial_image_is_the_frame_render_gives_on_every_path() {
    let volume = volume();
    let renderer = Renderer::new(&volume).unwrap();
    for (what, s) in every_path() {
        let partial = renderer
            .render(FrameRequest::new(&s).partial())
            .unwrap()
            .partial();
        let finished = renderer.finish(&s, partial);
        let frame = renderer.render(FrameRequest::new(&s)).unwrap().image();
        assert!(finished == frame, "{what}");
        // And into a reused buffer of another frame.
        let reusing = FrameRequest::new(&s).reusing(Image::new(7, 3, [0.5; 4]));
        let reused = renderer.render(reusing).unwrap().image();
        assert!(reused == frame, "{what}: reusing a buffer");
        assert!(frame.pixels().iter().any(|p| p[3] > 0.5), "{what}: empty");
    }
}

#[test]
fn halves_rendered_apart_and_combined_front_to_back_give_the_whole_frame() {
    // The default view looks along −x: samples lie on planes x = c − k·step
    // through the volume's centre c = 16 (step 1), so a cut at x = 16.5
    // lies between sample planes and every sample is in exactly one half.
    // The front half (nearer the eye) is x ≥ 16.5.
    let volume = volume();
    let renderer = Renderer::new(&volume).unwrap();
    let (lo, hi) = volume.bounds();
    let cut = 16.5;
    let front = (DVec3::new(cut, lo.y, lo.z), hi);
    let back = (lo, DVec3::new(cut, hi.y, hi.z));
    let base = RenderSettings {
        width: 60,
        height: 50,
        transfer_function: colorful(),
        background: [0.1, 0.0, 0.3],
        // Fix the value window, as ranks holding pieces must.
        ..RenderSettings::default()
    };
    let window = renderer.value_range();
    let tf = TransferFunction {
        domain: Some((window.0 as f64, window.1 as f64)),
        ..base.transfer_function.clone()
    };
    for (name, blend, classification) in [
        ("pre-classified", Blend::Composite, Classification::Pre),
        ("post-classified", Blend::Composite, Classification::Post),
        ("maximum", Blend::Maximum, Classification::Pre),
        ("average", Blend::Average, Classification::Pre),
    ] {
        for reference in [false, true] {
            let whole = RenderSettings {
                blend,
                classification,
                transfer_function: tf.clone(),
                ..base.clone()
            };
            let whole = if reference {
                on_the_reference(&whole)
            } else {
                whole
            };
            let piece = |crop| {
                let s = RenderSettings {
                    crop: Some(crop),
                    ..whole.clone()
                };
                renderer
                    .render(FrameRequest::new(&s).partial())
                    .unwrap()
                    .partial()
            };
            let mut combined: PartialImage = piece(front);
            combined.combine(&piece(back));
            let combined = renderer.finish(&whole, combined);
            let frame = renderer.render(FrameRequest::new(&whole)).unwrap().image();
            let diff = combined.max_abs_diff(&frame).unwrap();
            // The fast path stops a ray once T < 1/1024, within each half
            // for the pieces: each image is within T < 1/1024 of the exact
            // one (what is dropped is T times a colour in [0, 1], the
            // background's share included), so the two are within 2/1024.
            // The reference takes every sample: rounding only.
            let bound = if reference { 1e-5 } else { 2.0 / 1024.0 };
            println!("{name}, reference {reference}: combined halves vs whole {diff:e}");
            assert!(diff <= bound, "{name}, reference {reference}: {diff}");
            assert!(frame.pixels().iter().any(|p| p[3] > 0.5), "{name}: empty");
        }
    }
}
