//! How much a scene of two and three channels costs against one channel
//! alone: channels of one 256³ grid, rendered at 512², each frame turned a
//! further half degree. The channels are stains of one specimen: twelve
//! Gaussian "cells" at the same places in every channel, each channel
//! giving them its own size and brightness (as nuclei and membranes
//! overlap); and, for comparison, channels of blobs at different places
//! (every channel's bricks are then extra work). Prints the median frame
//! time of each case and its ratio to the one channel's, all measured in
//! one run, alternating the cases frame by frame; and the median
//! processor time of each (all threads), steadier on a shared machine.
//!
//! `cargo run --release -p volray-core --example scene_bench [-- N FRAMES]`
//! (N: grid side, default 256; FRAMES: timed frames per case, default 7).
//! `SCENE_BENCH_ONLY=TEXT` runs the cases whose names hold TEXT (the first
//! one shown is the ratios' unit), `SCENE_BENCH_CLASS=pre|post` one
//! classification.

use std::time::Instant;
use volray_core::camera::Camera;
use volray_core::glam::DVec3;
use volray_core::scene::{Look, Mix, Scene, SceneSettings};
use volray_core::{
    Classification, PiecewiseLinear, RenderSettings, Renderer, TransferFunction, Volume,
};
use volray_core::{FrameRequest, Render};

/// A generator of numbers in [0, 1) from `seed`.
fn random(seed: u64) -> impl FnMut() -> f64 {
    let step = |s: u64| {
        s.wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407)
    };
    let mut s = step(seed);
    move || {
        s = step(s);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Gaussian blobs on an `n`³ grid over the unit cube: their centres from
/// `places`, their widths from `seed`.
fn channel(n: usize, places: u64, seed: u64) -> Volume {
    let (mut place, mut size) = (random(places), random(seed));
    let blobs: Vec<(DVec3, f64)> = (0..12)
        .map(|_| {
            let centre = DVec3::new(place(), place(), place()) * 0.8 + 0.1;
            (centre, 0.04 + 0.06 * size())
        })
        .collect();
    let h = 1.0 / (n - 1) as f64;
    Volume::from_fn([n; 3], DVec3::splat(h), DVec3::ZERO, move |p| {
        blobs
            .iter()
            .map(|(c, w)| (-(p - *c).length_squared() / (w * w)).exp())
            .sum::<f64>() as f32
    })
    .unwrap()
}

/// One case: renders frame `n`.
type Frame<'a> = Box<dyn Fn(usize) + 'a>;

/// The processor time of every thread of this process so far, in seconds
/// (Linux: `/proc/self/task/*/schedstat`; elsewhere 0). On a machine
/// shared with other work, a frame's processor time is steadier than its
/// wall time.
fn cpu_seconds() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0.0;
    };
    let ns: u64 = tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum();
    ns as f64 * 1e-9
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let n = args.first().copied().unwrap_or(256);
    let frames = args.get(1).copied().unwrap_or(7);
    // One specimen's stains (same places), and blobs at other places.
    let volumes: Vec<Volume> = (0..3).map(|c| channel(n, 1, c + 1)).collect();
    let elsewhere = channel(n, 2, 2);
    let colours = [[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, 1.0, 1.0]];
    let tf = |rgb: [f32; 3]| TransferFunction {
        domain: Some((0.0, 1.0)),
        opacity: Some(
            PiecewiseLinear::new("opacity", vec![(0.0, [0.0]), (0.15, [0.0]), (1.0, [0.6])])
                .unwrap(),
        ),
        color: Some(PiecewiseLinear::constant(rgb)),
    };
    // SCENE_BENCH_CLASS=pre or post: that classification only.
    let class = std::env::var("SCENE_BENCH_CLASS").ok();
    for classification in [Classification::Pre, Classification::Post] {
        let name = format!("{classification:?}").to_lowercase();
        if class.as_deref().is_some_and(|c| c != name) {
            continue;
        }
        let settings = |frame: usize| RenderSettings {
            width: 512,
            height: 512,
            step: 0.5,
            classification,
            camera: Camera {
                azimuth: 30.0 + 0.5 * frame as f64,
                elevation: 20.0,
                ..Camera::default()
            },
            transfer_function: tf(colours[0]),
            ..RenderSettings::default()
        };
        let one = Renderer::new(&volumes[0]).unwrap();
        let scene = |k: usize| {
            Scene::new(
                volumes[..k]
                    .iter()
                    .map(|v| Renderer::new(v).unwrap())
                    .collect(),
            )
            .unwrap()
        };
        // Each case its own scene: a scene keeps the classification of its
        // last frame, which another look would redo every frame.
        let (two, two_clear, three) = (scene(2), scene(2), scene(3));
        let apart = Scene::new(vec![
            Renderer::new(&volumes[0]).unwrap(),
            Renderer::new(&elsewhere).unwrap(),
        ])
        .unwrap();
        let request = |k: usize, frame: usize, mix: Mix| {
            let s = settings(frame);
            SceneSettings {
                looks: (0..k)
                    .map(|c| Look {
                        transfer_function: tf(colours[c]),
                        ..Look::of(&s)
                    })
                    .collect(),
                settings: s,
                mix,
            }
        };
        let only = std::env::var("SCENE_BENCH_ONLY").ok();
        let clear = |f: usize| {
            let mut r = request(2, f, Mix::Composite);
            r.looks[1].visible = true;
            r.looks[1].transfer_function.opacity = Some(PiecewiseLinear::constant([0.0]));
            r
        };
        let cases: [(&str, Frame); 7] = [
            (
                "1 channel (its renderer)",
                Box::new(|f| drop(one.render(FrameRequest::new(&settings(f))).unwrap().image())),
            ),
            (
                "2 channels, 2nd clear",
                Box::new(|f| {
                    drop(
                        two_clear
                            .render(FrameRequest::new(&clear(f)))
                            .unwrap()
                            .image(),
                    )
                }),
            ),
            (
                "2 channels, composite",
                Box::new(|f| {
                    drop(
                        two.render(FrameRequest::new(&request(2, f, Mix::Composite)))
                            .unwrap()
                            .image(),
                    )
                }),
            ),
            (
                "2 apart, composite",
                Box::new(|f| {
                    drop(
                        apart
                            .render(FrameRequest::new(&request(2, f, Mix::Composite)))
                            .unwrap()
                            .image(),
                    )
                }),
            ),
            (
                "2 channels, additive",
                Box::new(|f| {
                    drop(
                        two.render(FrameRequest::new(&request(2, f, Mix::Additive)))
                            .unwrap()
                            .image(),
                    )
                }),
            ),
            (
                "3 channels, composite",
                Box::new(|f| {
                    drop(
                        three
                            .render(FrameRequest::new(&request(3, f, Mix::Composite)))
                            .unwrap()
                            .image(),
                    )
                }),
            ),
            (
                "3 channels, additive",
                Box::new(|f| {
                    drop(
                        three
                            .render(FrameRequest::new(&request(3, f, Mix::Additive)))
                            .unwrap()
                            .image(),
                    )
                }),
            ),
        ];
        let cases: Vec<_> = (cases.into_iter())
            .filter(|(name, _)| only.as_deref().is_none_or(|o| name.contains(o)))
            .collect();
        // A warm-up frame each: classification, lit bricks, packed voxels.
        for (_, case) in &cases {
            case(0);
        }
        let mut times = vec![Vec::new(); cases.len()];
        let mut cpu = vec![Vec::new(); cases.len()];
        for frame in 1..=frames {
            for (i, (_, case)) in cases.iter().enumerate() {
                let (t, c) = (Instant::now(), cpu_seconds());
                case(frame);
                times[i].push(t.elapsed().as_secs_f64());
                cpu[i].push(cpu_seconds() - c);
            }
        }
        let medians: Vec<f64> = times.into_iter().map(median).collect();
        let cpu: Vec<f64> = cpu.into_iter().map(median).collect();
        println!(
            "{n}³ channels at 512², step 0.5, {classification:?}-classified, {} threads, {frames} frames:",
            rayon::current_num_threads()
        );
        println!(
            "  {:<26} {:>8} {:>7} {:>10} {:>7}",
            "", "wall", "", "processor", ""
        );
        for (((name, _), m), c) in cases.iter().zip(&medians).zip(&cpu) {
            println!(
                "  {name:<26} {:>8.1} ms {:>5.2}× {:>8.1} ms {:>5.2}×",
                m * 1e3,
                m / medians[0], /* the first case shown */
                c * 1e3,
                c / cpu[0],
            );
        }
    }
}
