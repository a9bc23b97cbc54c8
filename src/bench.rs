//! `volray bench`: time whole frames, of one volume or of the peer
//! benchmark's workloads (`--peers`, see [`peers`]).
//!
//! A frame is everything after the volume is in memory: classification
//! (done on the first frame and kept while the transfer function stays the
//! same, as VTK keeps its normals), lighting the voxels for this view,
//! binning the bricks into tiles and casting the rays into the frame
//! buffer; PNG encoding is not timed. One warm-up view (rendered for at
//! least a quarter of a second, untimed, so that the CPU is awake), then
//! `--frames` timed ones, each turned a further half degree about the up
//! axis so that no view-dependent work is reused.

mod peers;
mod vtk;

use crate::error::CliError;
use crate::flags::BenchArgs;
use crate::session::{load, render_failure, renderer_for, thread_pool};
use crate::settings::settings;
use std::path::Path;
use std::time::{Duration, Instant};
use volray_core::{
    Camera, FrameRequest, FrameTimes, Image, Method, Render, RenderSettings, Renderer,
};

pub fn run(args: &BenchArgs) -> Result<(), CliError> {
    match &args.peers {
        Some(dir) => {
            if let Some(input) = &args.input.input {
                return Err(CliError::input(format!(
                    "{input}: --peers times the peers' volumes; give INPUT or --peers, not both"
                )));
            }
            peers::run(args, dir)
        }
        None => {
            if let Some(json) = &args.json {
                let input = args
                    .input
                    .input
                    .as_deref()
                    .unwrap_or(volray_app::input::DEMO);
                let tf: Vec<&Path> = args.view.look.tf_file().into_iter().collect();
                crate::overwrite::refuse_overwriting_inputs(
                    std::slice::from_ref(json),
                    &[input.to_string()],
                    &tf,
                )?;
            }
            // clap's `requires = "peers"` lapses when a view option that
            // conflicts with --peers is given; refuse here as well.
            for (given, flag) in [
                (args.cases.is_some(), "--cases"),
                (args.vs_vtk, "--vs-vtk"),
                (args.peers_python.is_some(), "--peers-python"),
            ] {
                if given {
                    return Err(CliError::input(format!(
                        "{flag} applies to the peer benchmark: give --peers DIR"
                    )));
                }
            }
            one_volume(args)
        }
    }
}

/// One timed frame.
#[derive(Debug, Clone, Copy)]
pub struct Timed {
    /// Wall time of the whole frame, seconds.
    pub wall: f64,
    /// The fast path's breakdown (`None` on the reference path).
    pub parts: Option<FrameTimes>,
}

/// The least time the warm-up view is rendered for, untimed. A CPU that
/// was idle (while the volume was read, or while VTK ran) comes back to
/// full speed only after some tens of milliseconds of work; VTK's harness
/// gets that while Python imports VTK.
const WARM_UP: Duration = Duration::from_millis(250);

/// Renders the warm-up view (`base`'s camera) until [`WARM_UP`] has passed,
/// then `frames` timed frames each turned half a degree further about the
/// up axis, calling `report` after the first warm-up frame (frame 0, which
/// includes the classification) and after each timed one. Returns the
/// warm-up image and the timed frames.
pub fn time_frames(
    renderer: &Renderer,
    base: &RenderSettings,
    frames: u32,
    mut report: impl FnMut(u32, &Timed),
) -> Result<(Image, Vec<Timed>), volray_core::RenderError> {
    let mut image = Image::new(base.width, base.height, [0.0; 4]);
    let render = |frame: u32, image: &mut Image| {
        // Orbit about the up axis through the view reference (VTK's
        // azimuth), for either projection and with or without --view.
        let settings = RenderSettings {
            camera: Camera {
                azimuth: base.camera.azimuth + 0.5 * frame as f64,
                ..base.camera
            },
            ..base.clone()
        };
        let t0 = Instant::now();
        let parts = match settings.method {
            Method::Fast => {
                let reusing = std::mem::replace(image, Image::new(0, 0, [0.0; 4]));
                let request = FrameRequest::new(&settings).reusing(reusing);
                let (rendered, times) = renderer.render(request)?.image_and_times();
                *image = rendered;
                Some(times)
            }
            Method::Reference => {
                *image = renderer.render(FrameRequest::new(&settings))?.image();
                None
            }
        };
        Ok::<_, volray_core::RenderError>(Timed {
            wall: t0.elapsed().as_secs_f64(),
            parts,
        })
    };
    let start = Instant::now();
    report(0, &render(0, &mut image)?);
    let warm = image.clone();
    while start.elapsed() < WARM_UP {
        render(0, &mut image)?;
    }
    let mut timed = Vec::new();
    for frame in 1..=frames {
        let t = render(frame, &mut image)?;
        report(frame, &t);
        timed.push(t);
    }
    Ok((warm, timed))
}

/// The median of `values` (the mean of the middle two for an even count).
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// Milliseconds of one part of a frame, for the tables.
fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// One row of `--json`.
pub struct JsonRow {
    pub dataset: String,
    pub window: usize,
    pub threads: usize,
    pub median_s: f64,
    /// VTK's median on the same workload, when it ran.
    pub vtk_median_s: Option<f64>,
}

/// Writes `rows` to `path` as a JSON list, atomically.
pub fn write_json(path: &Path, rows: &[JsonRow]) -> Result<(), CliError> {
    let list: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            let mut v = serde_json::json!({
                "dataset": r.dataset,
                "window": r.window,
                "threads": r.threads,
                "median_s": r.median_s,
            });
            if let Some(vtk) = r.vtk_median_s {
                v["vtk_median_s"] = vtk.into();
            }
            v
        })
        .collect();
    let text = serde_json::to_string_pretty(&list).expect("plain values serialise");
    volray_io::write_atomically(path, |w| writeln!(w, "{text}"))?;
    Ok(())
}

/// `volray bench INPUT`: the frames of one volume.
fn one_volume(args: &BenchArgs) -> Result<(), CliError> {
    let mut input = load(&args.input, args.view.look.log)?;
    let mut base = settings(&args.view)?;
    crate::settings::from_volume(
        &args.view.look,
        &mut base.transfer_function,
        &mut input.volume,
        &input.name,
    )?;
    let pool = thread_pool(args.view.threads)?;
    let fail = |e: volray_core::RenderError| render_failure(&args.view, &input.name, e);

    let median_s = pool.install(|| {
        let renderer = renderer_for(&args.view, &base, &input)?;
        let [nx, ny, nz] = input.volume.dims();
        outln!(
            "volray bench: {} ({nx}x{ny}x{nz}), {}x{} pixels, step {} voxel, {} threads, {} path",
            input.name,
            base.width,
            base.height,
            base.step,
            rayon::current_num_threads(),
            if base.method == Method::Fast {
                "fast"
            } else {
                "reference"
            },
        );
        outln!(
            "{:>6} {:>11} {:>9} {:>15} {:>10}",
            "frame", "classify ms", "bin ms", "shade+cast ms", "total ms"
        );
        let row = |frame: u32, t: &Timed| {
            let name = if frame == 0 {
                "warm".to_string()
            } else {
                frame.to_string()
            };
            match t.parts {
                Some(p) => outln!(
                    "{name:>6} {:>11.2} {:>9.2} {:>15.2} {:>10.2}",
                    ms(p.classify),
                    ms(p.bin),
                    ms(p.cast),
                    t.wall * 1e3
                ),
                None => outln!("{name:>6} {:>48.2}", t.wall * 1e3),
            }
        };
        let (_, timed) = time_frames(&renderer, &base, args.frames, row).map_err(fail)?;
        let total = median(timed.iter().map(|t| t.wall).collect());
        outln!("{:>6} {:>48.2}", "median", total * 1e3);
        let frame = renderer.prepare(&base).map_err(fail)?;
        let samples = nominal_samples(&frame);
        outln!(
            "nominal samples per second: {:.3e} ({samples} samples per frame, before skipping and early termination)",
            samples as f64 / total
        );
        Ok::<f64, CliError>(total)
    })?;
    if let Some(path) = &args.json {
        let row = JsonRow {
            dataset: input.name.clone(),
            window: base.width,
            threads: pool.current_num_threads(),
            median_s,
            vtk_median_s: None,
        };
        write_json(path, &[row])?;
    }
    Ok(())
}

/// Samples the rays of `frame` would take without skipping or early
/// termination.
fn nominal_samples(frame: &volray_core::Frame) -> usize {
    frame.nominal_samples()
}
