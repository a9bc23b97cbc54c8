//! Stopping a frame: a stop flag set before or during a frame makes the
//! renderer answer `Stopped` on every path, and the renderer's next frame
//! is the frame it would have drawn anyway.

mod common;

use common::{blobs, on_the_reference};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use volray_core::glam::DVec3;
use volray_core::scene::{Look, Mix, Scene, SceneSettings};
use volray_core::{Blend, Classification, RenderError, RenderSettings, Renderer};
use volray_core::{FrameRequest, Render};

fn settings_on_every_path() -> Vec<(&'static str, RenderSettings)> {
    let base = RenderSettings {
        width: 64,
        height: 64,
        ..RenderSettings::default()
    };
    vec![
        ("bricked", base.clone()),
        (
            "post-classified",
            RenderSettings {
                classification: Classification::Post,
                ..base.clone()
            },
        ),
        (
            "maximum projection",
            RenderSettings {
                blend: Blend::Maximum,
                ..base.clone()
            },
        ),
        ("reference", on_the_reference(&base)),
    ]
}

#[test]
fn a_frame_stopped_before_it_starts_is_stopped_on_every_path() {
    let volume = blobs([24, 20, 16], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let stop = AtomicBool::new(true);
    for (path, settings) in settings_on_every_path() {
        let pixels = AtomicUsize::new(0);
        let report = |n| {
            pixels.fetch_add(n, Ordering::Relaxed);
        };
        let request = FrameRequest::new(&settings).reporting(&report);
        let answer = renderer.render(request.stopped_by(&stop));
        assert!(
            matches!(answer, Err(RenderError::Stopped)),
            "{path}: {answer:?}"
        );
        assert_eq!(pixels.load(Ordering::Relaxed), 0, "{path}: work was done");
    }
}

#[test]
fn a_frame_stopped_half_way_leaves_the_next_frame_unchanged() {
    let volume = blobs([24, 20, 16], DVec3::ONE, DVec3::ZERO);
    for (path, settings) in settings_on_every_path() {
        let expected = Renderer::new(&volume)
            .unwrap()
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        let renderer = Renderer::new(&volume).unwrap();
        let stop = AtomicBool::new(false);
        // Stopped from the progress report, once some pixels are done.
        let report = |_| stop.store(true, Ordering::Relaxed);
        let request = FrameRequest::new(&settings).reporting(&report);
        let answer = renderer.render(request.stopped_by(&stop));
        assert!(
            matches!(answer, Err(RenderError::Stopped)),
            "{path}: {answer:?}"
        );
        let again = renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        assert_eq!(again, expected, "{path}: the frame after a stopped one");
    }
}

#[test]
fn a_frame_never_stopped_is_the_plain_frame() {
    let volume = blobs([24, 20, 16], DVec3::ONE, DVec3::ZERO);
    let renderer = Renderer::new(&volume).unwrap();
    let stop = AtomicBool::new(false);
    for (path, settings) in settings_on_every_path() {
        let plain = renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        let stoppable = renderer
            .render(FrameRequest::new(&settings).stopped_by(&stop))
            .unwrap()
            .image();
        assert_eq!(stoppable, plain, "{path}");
    }
}

#[test]
fn a_scene_stopped_half_way_is_stopped_in_every_mix_and_its_next_frame_unchanged() {
    // Two volumes on one grid: the composite mix marches them as one, the
    // additive mix and a projection render each apart.
    let (a, b) = (
        blobs([24, 20, 16], DVec3::ONE, DVec3::ZERO),
        blobs([24, 20, 16], DVec3::ONE, DVec3::new(0.5, 0.0, 0.0)),
    );
    let layers = || vec![Renderer::new(&a).unwrap(), Renderer::new(&b).unwrap()];
    let base = RenderSettings {
        width: 64,
        height: 64,
        ..RenderSettings::default()
    };
    let projected = RenderSettings {
        blend: Blend::Maximum,
        ..base.clone()
    };
    for (what, settings, mix) in [
        ("composite", &base, Mix::Composite),
        ("additive", &base, Mix::Additive),
        ("maximum", &projected, Mix::Composite),
    ] {
        let request = SceneSettings {
            settings: settings.clone(),
            looks: vec![Look::of(settings), Look::of(settings)],
            mix,
        };
        let expected = (Scene::new(layers()).unwrap())
            .render(FrameRequest::new(&request))
            .unwrap()
            .image();
        let scene = Scene::new(layers()).unwrap();
        let (stop, pixels) = (AtomicBool::new(false), AtomicUsize::new(0));
        let report = |n| {
            pixels.fetch_add(n, Ordering::Relaxed);
            stop.store(true, Ordering::Relaxed);
        };
        let asked = FrameRequest::new(&request).reporting(&report);
        // One thread: every tile after the first sees the flag.
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build();
        let answer = one
            .unwrap()
            .install(|| scene.render(asked.stopped_by(&stop)));
        assert!(
            matches!(answer, Err(RenderError::Stopped)),
            "{what}: {:?}",
            answer.map(|rendered| rendered.times)
        );
        // Fewer pixels than one march over the image: stopped within it.
        assert!(pixels.load(Ordering::Relaxed) < 64 * 64, "{what}");
        let again = scene.render(FrameRequest::new(&request)).unwrap().image();
        assert_eq!(again, expected, "{what}: the frame after a stopped one");
    }
}
