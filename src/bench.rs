//! `volray bench`: time whole frames of one volume.
//!
//! A frame is everything after the volume is in memory and its
//! view-independent gradients are computed (as VTK caches its normals):
//! stage 1 (shade and classify every voxel for this view) and stage 2 (cast
//! the rays into the frame buffer); PNG encoding is not timed. One warm-up
//! frame, then `--frames` timed ones, each turned a further half degree
//! about the up axis so that no view-dependent work is reused.

use crate::cli::BenchArgs;
use crate::error::CliError;
use crate::input;
use crate::render::{settings, thread_pool};
use std::time::Instant;
use volray_core::glam::{DQuat, DVec3};
use volray_core::{Method, RenderSettings, Renderer};

pub fn run(args: &BenchArgs) -> Result<(), CliError> {
    let input = input::load(&args.input)?;
    let base = settings(&args.view)?;
    let pool = thread_pool(args.view.threads)?;
    let fail = |e: volray_core::RenderError| CliError::input(format!("{}: {e}", input.name));

    pool.install(|| {
        let start = Instant::now();
        let renderer = Renderer::new(&input.volume).map_err(fail)?;
        let prepare = start.elapsed().as_secs_f64();

        let volume = renderer.volume();
        let look_at = base.camera.look_at.unwrap_or(volume.centre());
        let view_point = base.camera.view_point.unwrap_or(look_at + DVec3::X);
        let axis = base.camera.up.normalize();
        let [nx, ny, nz] = volume.dims();
        println!(
            "volray bench: {} ({nx}x{ny}x{nz}), {}x{} pixels, step {} voxel, {} threads, {} path",
            input.name,
            base.width,
            base.height,
            base.step,
            rayon::current_num_threads(),
            if base.method == Method::Fast { "fast" } else { "reference" },
        );
        println!("gradients and value range (once per volume): {:.1} ms", prepare * 1e3);
        println!("{:>6} {:>12} {:>12} {:>12}", "frame", "stage 1 ms", "stage 2 ms", "total ms");

        let mut times = Vec::new();
        let mut samples = 0usize;
        for frame in 0..=args.frames {
            let turn = DQuat::from_axis_angle(axis, (0.5 * frame as f64).to_radians());
            let settings = RenderSettings {
                camera: volray_core::Camera {
                    view_point: Some(look_at + turn * (view_point - look_at)),
                    look_at: Some(look_at),
                    ..base.camera
                },
                ..base.clone()
            };
            let t0 = Instant::now();
            let prepared = renderer.prepare(&settings).map_err(fail)?;
            let shaded = renderer.stage1(&settings, &prepared.view);
            let t1 = Instant::now();
            let image = renderer.stage2(&settings, &prepared, &shaded, &|_| {});
            let t2 = Instant::now();
            std::hint::black_box(image);
            let (s1, s2) = ((t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64());
            if frame == 0 {
                println!("{:>6} {:>12.2} {:>12.2} {:>12.2}", "warm", s1 * 1e3, s2 * 1e3, (s1 + s2) * 1e3);
                samples = nominal_samples(&prepared);
                continue;
            }
            println!("{frame:>6} {:>12.2} {:>12.2} {:>12.2}", s1 * 1e3, s2 * 1e3, (s1 + s2) * 1e3);
            times.push((s1, s2, s1 + s2));
        }
        let median = |pick: fn(&(f64, f64, f64)) -> f64| {
            let mut v: Vec<f64> = times.iter().map(pick).collect();
            v.sort_by(f64::total_cmp);
            let n = v.len();
            if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
        };
        let (m1, m2, total) = (median(|t| t.0), median(|t| t.1), median(|t| t.2));
        println!("{:>6} {:>12.2} {:>12.2} {:>12.2}", "median", m1 * 1e3, m2 * 1e3, total * 1e3);
        println!(
            "nominal samples per second: {:.3e} ({samples} samples per frame, before early termination)",
            samples as f64 / total
        );
        Ok(())
    })
}

/// Samples the rays of `frame` would take without early termination.
fn nominal_samples(frame: &volray_core::render::Frame) -> usize {
    let view = &frame.view;
    (0..view.height)
        .flat_map(|row| (0..view.width).map(move |col| (col, row)))
        .filter_map(|(col, row)| frame.grid.ray(view, col, row, frame.step))
        .map(|ray| ray.count())
        .sum()
}
