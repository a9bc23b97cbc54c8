//! `volray bench`: time whole frames, of one volume or of the peer
//! benchmark's workloads (`--peers`): the flags, and the tables printed.
//! How frames are timed, and the peers' workloads, are
//! `volray_app::bench`'s.

use crate::error::CliError;
use crate::session::{load, render_failure, renderer_for, thread_pool};
use crate::settings::settings;
use std::path::Path;
use volray_app::bench::peers::{self, Peers};
use volray_app::bench::{JsonRow, Timed, median, ms, time_frames, write_json};
use volray_core::Method;
use volray_flags::BenchArgs;

pub fn run(args: &BenchArgs) -> Result<(), CliError> {
    match &args.peers {
        Some(dir) => {
            if let Some(input) = &args.input.input {
                return Err(CliError::input(format!(
                    "{input}: --peers times the peers' volumes; give INPUT or --peers, not both"
                )));
            }
            let pool = thread_pool(args.view.threads)?;
            let peers = Peers {
                dir,
                cases: args.cases.as_ref().map(|c| c.0.clone()),
                frames: args.frames,
                shadows: args.view.look.shadows,
                ambient_occlusion: args.view.look.ambient_occlusion,
                vs_vtk: args.vs_vtk,
                python: args.peers_python.as_deref(),
            };
            let rows = peers::run(&peers, &pool, &mut |line| outln!("{line}"))?;
            if let Some(path) = &args.json {
                write_json(path, &rows)?;
            }
            Ok(())
        }
        None => {
            if let Some(json) = &args.json {
                let input = args
                    .input
                    .input
                    .as_deref()
                    .unwrap_or(volray_app::input::DEMO);
                let tf: Vec<&Path> = args.view.look.tf_file().into_iter().collect();
                volray_app::reads::refuse_overwriting_inputs(
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

/// `volray bench INPUT`: the frames of one volume.
fn one_volume(args: &BenchArgs) -> Result<(), CliError> {
    let mut input = load(&args.input, args.view.look.log)?;
    let mut base = settings(&args.view)?;
    // What the look leaves to the volume, as `render` leaves it.
    let look = volray_flags::look(&args.view.look);
    volray_app::look::leave_to_volume(&look, &mut base.transfer_function, &mut input)
        .map_err(crate::settings::refused)?;
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
