//! `volray render`: INPUT → Volume → Renderer → Image → PNG or OpenEXR;
//! with `--turntable`, `--frames` or several inputs, an animation
//! (`animate.rs`); with `--channels` or `--overlay`, several volumes in
//! one picture (`scene.rs`).

use crate::animate;
// The output file, as `distributed.rs` (MPI) takes it from here.
use crate::error::CliError;
pub use crate::outfile::{OutputKind, check_output, output_files, output_kind, write_still};
use crate::session::{
    app_failure, load, progress_bar, render_failure, renderer_for, streamed_note, thread_pool,
};
use crate::settings::settings;
use volray_app::animation::Turntable;
use volray_app::input;
use volray_app::plan::Plan;
use volray_core::{FrameRequest, Render, RenderSettings, Rendered};
use volray_flags::RenderArgs;

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    refuse_scene_flags_alone(args)?;
    if crate::movie::wanted(args) {
        return crate::movie::run(args);
    }
    crate::movie::refuse_movie_flags(args)?;
    if args.scene.is_scene() {
        return crate::scene::run(args);
    }
    let specs = specs(args);
    let animation = animation_reason(args)?;
    let kind = output_kind(&args.out.output, args.out.bit_depth, animation)?;
    if args.animation.fps.is_some() && animation.is_none() {
        return Err(CliError::input(
            "--fps applies to animations: give --turntable FRAMES, --frames or several inputs",
        ));
    }
    let settings = settings(&args.view)?;
    check_output(&args.out.output)?;
    volray_app::reads::refuse_overwriting_inputs(
        &output_files(args, kind, specs.len()),
        &specs,
        &args.view.look.tf_file().into_iter().collect::<Vec<_>>(),
    )?;
    let pool = thread_pool(args.view.threads)?;
    match (kind, args.animation.turntable) {
        (OutputKind::Animation, Some(frames)) => {
            animate::views(args, &settings, &pool, &Turntable(frames as usize))
        }
        (OutputKind::Animation, None) if args.scene.frames.is_some() => {
            animate::time_points(args, kind, &settings, &pool)
        }
        (OutputKind::Animation, None) => animate::series(args, &specs, &settings, &pool),
        (kind, _) => still(args, &settings, &pool, kind),
    }
}

/// One frame of one volume, to an image file.
fn still(
    args: &RenderArgs,
    settings: &RenderSettings,
    pool: &rayon::ThreadPool,
    kind: OutputKind,
) -> Result<(), CliError> {
    let input_args = match crate::session::plan(&args.input, &args.view, settings)? {
        Plan::Streamed(mut streamed) => {
            crate::figure::refuse(&args.figure, "a volume rendered piece by piece")?;
            let settings = &(streamed
                .settings_from_volume(&volray_flags::look(&args.view.look), settings.clone()))
            .map_err(|e| app_failure(&args.view, e))?;
            let bar = progress_bar((settings.width * settings.height) as u64);
            let (image, times) = pool
                .install(|| streamed.render(settings, &|n| bar.inc(n as u64)))
                .map_err(|e| app_failure(&args.view, e))?;
            bar.finish_and_clear();
            write_still(args, kind, &image)?;
            eprintln!("{}", streamed_note(&streamed, &times));
            return Ok(());
        }
        Plan::Whole { level } => args.input.at_level(level),
    };
    let mut input = load(&input_args, args.view.look.log)?;
    crate::session::auto_log(&args.view, settings, &mut input)?;
    let settings = &crate::settings::from_input(args, settings, &mut input)?;
    let renderer = renderer_for(&args.view, settings, &input)?;
    let bar = progress_bar((settings.width * settings.height) as u64);
    let mut image = pool
        .install(|| renderer.render(FrameRequest::new(settings).reporting(&|n| bar.inc(n as u64))))
        .map(Rendered::image)
        .map_err(|e| render_failure(&args.view, &input.name, e))?;
    bar.finish_and_clear();
    crate::figure::draw(args, kind, settings, &renderer, &input, &mut image)?;

    write_still(args, kind, &image)
}

/// The inputs in order: INPUT (or the demo volume), then MORE.
fn specs(args: &RenderArgs) -> Vec<String> {
    let first = args.input.input.as_deref().unwrap_or(input::DEMO);
    std::iter::once(first.to_string())
        .chain(args.animation.series.iter().cloned())
        .collect()
}

/// The flags of several volumes that mean nothing without `--channels`
/// or `--overlay`, and `--frames` with what it cannot take, refused.
fn refuse_scene_flags_alone(args: &RenderArgs) -> Result<(), CliError> {
    let scene = &args.scene;
    if !scene.is_scene() {
        if scene.channel_colors.is_some() {
            return Err(CliError::input(
                "--channel-colors colours the channels of --channels: give --channels",
            ));
        }
        if scene.mix.is_some() {
            return Err(CliError::input(
                "--mix mixes several volumes: give --channels or --overlay",
            ));
        }
    }
    if scene.frames.is_some() {
        if args.animation.turntable.is_some() {
            return Err(CliError::input(
                "--frames animates the time points of INPUT: give --frames or --turntable, not both",
            ));
        }
        if !args.animation.series.is_empty() {
            return Err(CliError::input(
                "--frames animates the time points of one input: give one input with it",
            ));
        }
    }
    Ok(())
}

/// Why the output is an animation (the flag that asks for one), or
/// `None` for a single frame. A turntable of a series is refused: which
/// frame would turn how far is not obvious.
fn animation_reason(args: &RenderArgs) -> Result<Option<&'static str>, CliError> {
    if args.scene.frames.is_some() {
        return Ok(Some("--frames"));
    }
    match (args.animation.turntable, args.animation.series.is_empty()) {
        (Some(_), false) => Err(CliError::input(
            "--turntable renders one volume: give one input, or several inputs without --turntable",
        )),
        (Some(_), true) => Ok(Some("--turntable")),
        (None, false) => Ok(Some("several inputs")),
        (None, true) => Ok(None),
    }
}
