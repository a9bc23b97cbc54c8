//! `mpirun -np N volray render|bench …` (built with `--features mpi`):
//! the flags turned into volray-app's distributed job (`volray_app::
//! distributed`: the input split among the ranks, each rank's
//! `--max-memory`, the frame composited on rank 0, the times), what a
//! distributed run refuses, and the output rank 0 writes.

use crate::error::CliError;
use crate::render::{self, OutputKind};
use crate::session::{app_failure, app_failure_of};
use crate::settings::settings;
use volray_app::AppError;
use volray_app::distributed::{self, Job, Mpi};
use volray_app::scene::{ChannelAxis, channel_axis};
use volray_core::RenderSettings;
use volray_distributed::frame::Failure;
use volray_distributed::transport::Transport;
use volray_flags::{BenchArgs, MixMode, RenderArgs, ViewArgs};

/// Whether this process runs under an MPI launcher, and so renders as one
/// rank of a distributed run.
pub fn launched() -> bool {
    distributed::launched()
}

/// `volray render` under `mpirun`: one still image, written by rank 0.
pub fn render(args: &RenderArgs) -> Result<(), CliError> {
    distributed::ranked(|| render_rank(args))
}

/// [`render`] on this rank.
fn render_rank(args: &RenderArgs) -> Result<(), CliError> {
    if !args.scene.overlay.is_empty() || args.scene.frames.is_some() {
        return Err(CliError::input(
            "under mpirun, render writes one still image of one grid: --overlay (volumes on other grids) and --frames are rendered by one process",
        ));
    }
    if args.figure.any() {
        return Err(CliError::input(format!(
            "{}: under mpirun, render writes the bare frame: annotations are drawn by one process",
            args.figure.first_flag()
        )));
    }
    if args.animation.turntable.is_some()
        || args.animation.keyframes.is_some()
        || !args.animation.series.is_empty()
    {
        return Err(CliError::input(
            "under mpirun, render writes one still image: --turntable, --keyframes and series are rendered by one process",
        ));
    }
    let kind = render::output_kind(&args.out.output, args.out.bit_depth, None)?;
    if matches!(kind, OutputKind::Gif) {
        return Err(CliError::input(format!(
            "{}: under mpirun, write .png or .exr",
            args.out.output.display()
        )));
    }
    let settings = settings(&args.view)?;
    let mpi = start(args.view.threads)?;
    let view = &args.view;
    let words = |e: &AppError| failed(view, e);
    // Rank 0 writes the file: it alone checks where.
    let checked = if mpi.rank() == 0 {
        render::check_output(&args.out.output).and_then(|_| {
            let spec = args
                .input
                .input
                .as_deref()
                .unwrap_or(volray_app::input::DEMO);
            volray_app::reads::refuse_overwriting_inputs(
                &render::output_files(args, kind, 1),
                &[spec.to_string()],
                &args.view.look.tf_file().into_iter().collect::<Vec<_>>(),
            )
            .map_err(CliError::from)
        })
    } else {
        Ok(())
    };
    distributed::agree_on(&mpi, checked.map_err(refusal), &words)
        .map_err(|e| app_failure(view, e))?;
    let job = job(&args.input, view, settings);
    let image = match &args.scene.channels {
        Some(which) => {
            let look = &view.look;
            if look.labels || look.preset.is_some() || look.colormap.is_some() {
                return Err(CliError::input(
                    "--channels colours each channel: --labels, --preset and --colormap do not apply",
                ));
            }
            let spec = job.request.spec.name();
            if volray_data::is_source_spec(&spec) || args.input.channel.is_some() {
                return Err(CliError::input(format!(
                    "--channels: give a file holding several channels, without --channel ({spec})"
                )));
            }
            let axis_of = |info: &volray_io::FileInfo| {
                let (count, axis) = channel_axis(info);
                (count, axis == ChannelAxis::Channel)
            };
            let pick =
                |count| crate::scene::picked(&args.scene, which, &spec, count).map_err(refusal);
            if job.settings.blend.is_projection() {
                return Err(CliError::input(
                    "--channels under mpirun: the projections (--blend mip, ...) are rendered by one process",
                ));
            }
            let additive = match args.scene.mix {
                Some(MixMode::Composite) => false,
                Some(MixMode::Additive) | None => true,
            };
            distributed::channels(&mpi, &job, (&axis_of, &pick), additive, &words)
        }
        None => distributed::render(&mpi, &job, &words),
    };
    if let Some(image) = image.map_err(|e| app_failure(view, e))? {
        render::write_still(args, kind, &image)?;
    }
    Ok(())
}

/// `volray bench` under `mpirun`: per-rank times of each stage, medians
/// over the frames (each turned half a degree further, as `bench` does),
/// printed by rank 0.
pub fn bench(args: &BenchArgs) -> Result<(), CliError> {
    distributed::ranked(|| bench_rank(args))
}

/// [`bench`] on this rank.
fn bench_rank(args: &BenchArgs) -> Result<(), CliError> {
    if args.peers.is_some() {
        return Err(CliError::input(
            "under mpirun, bench renders INPUT: --peers runs in one process",
        ));
    }
    let base = settings(&args.view)?;
    let mpi = start(args.view.threads)?;
    let view = &args.view;
    let words = |e: &AppError| failed(view, e);
    let job = job(&args.input, view, base);
    let table = distributed::bench(&mpi, &job, args.frames as usize, &words)
        .map_err(|e| app_failure(view, e))?;
    if let Some(table) = table {
        print!("{table}");
    }
    Ok(())
}

/// The distributed job the flags describe.
fn job(input: &volray_flags::InputArgs, view: &ViewArgs, settings: RenderSettings) -> Job {
    Job {
        request: input.request(),
        settings,
        look: volray_flags::look(&view.look),
        non_finite: view.sampling.nonfinite.into(),
    }
}

/// Rayon's global pool of `threads` workers (default: one per core; MPI
/// is called from the main thread only, the rendering within a rank runs
/// on the pool), then MPI.
fn start(threads: Option<u16>) -> Result<Mpi, CliError> {
    distributed::threads(threads)
        .map_err(|e| CliError::io(format!("cannot start worker threads: {e}")))?;
    distributed::initialize().ok_or_else(|| CliError::io("MPI could not be initialised"))
}

/// The CLI's own refusal, carried through volray-app's agreement.
fn refusal(e: CliError) -> AppError {
    AppError::Refused {
        message: e.message,
        bad_input: e.code == 1,
    }
}

/// A rank's error as the ranks agree on it, worded with the flags, its
/// exit code kept: a corrupt file is bad input (1) on every rank, as in
/// one process.
fn failed(view: &ViewArgs, e: &AppError) -> Failure {
    let e = app_failure_of(view, e);
    Failure {
        message: e.message,
        bad_input: e.code == 1,
    }
}
