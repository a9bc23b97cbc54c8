//! Animations of `volray render`, rendered frame by frame into volray-io's
//! [`Animation`] writer (animated PNG, GIF or numbered PNGs), which
//! publishes its file only once every frame is in: a failed run leaves
//! nothing behind.
//!
//! - A **turntable** orbits the view point about the up vector, frame `i`
//!   of `n` at azimuth `--azimuth + 360·i/n`. The orthographic window (or
//!   the perspective eye's distance) fits the bounding sphere rather than
//!   the box ([`Fit::Sphere`](volray_core::Fit::Sphere)), so the object keeps its scale as it turns
//!   instead of breathing with its box's outline. Each frame's view is
//!   volray-app's (`animation::Views`, of which a turntable is one); here
//!   the frames are rendered, annotated and written.
//! - A **series** renders several volumes, one frame each, as they are
//!   given: the paper's "repeat the calculation for various unit-cell
//!   parameters and see". Every frame has the same transfer function (the
//!   value window spans all the volumes unless one is given) and the same
//!   framing (the box around all the volumes), so the frames differ only
//!   where the data do. The volumes are read one at a time, twice (first
//!   for their ranges and bounds, then to render), so a long series never
//!   has to fit in memory. The first pass is volray-app's
//!   (`animation::series_settings`).
//! - **Time points** (`--frames`) are a series of one file's frames
//!   (`--frame 0, 1, ...`: a 4-D NIfTI's volumes, an OME-Zarr image's
//!   `t`, NetCDF time), read and rendered as a series of files is.

use crate::error::CliError;
use crate::outfile::OutputKind;
use crate::session::{
    app_failure, load, progress_bar, render_failure, renderer_failure, renderer_for, streamed_note,
};
use rayon::ThreadPool;
use volray_app::animation::{Views, series_settings};
use volray_app::plan::Plan;
use volray_core::{FrameRequest, Image, Render, RenderSettings, Rendered, Renderer};
use volray_flags::{InputArgs, RenderArgs};
use volray_io::Animation;

/// The views `views` of INPUT (`--turntable FRAMES`: volray-app's
/// `Turntable`), one frame each.
pub fn views(
    args: &RenderArgs,
    base: &RenderSettings,
    pool: &ThreadPool,
    views: &dyn Views,
) -> Result<(), CliError> {
    // The level and the road (whole or in pieces) are chosen for the
    // first frame: a turntable's framing fits the bounding sphere, so
    // every frame shows the volume at one scale.
    let frames = views.frames();
    let first = views.frame(base, 0);
    let input_args = match crate::session::plan(&args.input, &args.view, &first)? {
        Plan::Streamed(mut streamed) => {
            crate::figure::refuse(&args.figure, "a volume rendered piece by piece")?;
            let base = &(streamed
                .settings_from_volume(&volray_flags::look(&args.view.look), base.clone()))
            .map_err(|e| app_failure(&args.view, e))?;
            let mut writer = Writer::new(args, base, frames)?;
            let mut last = None;
            for i in 0..frames {
                let frame = views.frame(base, i);
                let (image, times) = pool
                    .install(|| streamed.render(&frame, &|_| {}))
                    .map_err(|e| app_failure(&args.view, e))?;
                writer.push(&image)?;
                last = Some(times);
            }
            writer.finish()?;
            // As a still says it was rendered in pieces, once for the
            // animation: the last frame's pieces and times.
            if let Some(times) = last {
                eprintln!(
                    "{} (the last of {frames} frames)",
                    streamed_note(&streamed, &times)
                );
            }
            return Ok(());
        }
        Plan::Whole { level } => args.input.at_level(level),
    };
    let mut input = load(&input_args, args.view.look.log)?;
    crate::session::auto_log(&args.view, base, &mut input)?;
    let base = &crate::settings::from_input(args, base, &mut input)?;
    let fail = |e: volray_core::RenderError| render_failure(&args.view, &input.name, e);
    let renderer = renderer_for(&args.view, base, &input)?;
    let mut writer = Writer::new(args, base, frames)?;
    for i in 0..frames {
        let frame = views.frame(base, i);
        let mut image = writer.render(pool, &renderer, &frame).map_err(fail)?;
        // Annotated in the frame's own view: the triad turns, the outline
        // and a perspective scale bar follow it.
        crate::figure::draw(
            args,
            OutputKind::Animation,
            &frame,
            &renderer,
            &input,
            &mut image,
        )?;
        writer.push(&image)?;
    }
    writer.finish()
}

/// Several inputs: one frame per volume in `specs`, in order.
pub fn series(
    args: &RenderArgs,
    specs: &[String],
    base: &RenderSettings,
    pool: &ThreadPool,
) -> Result<(), CliError> {
    let inputs: Vec<InputArgs> = (specs.iter())
        .map(|spec| InputArgs {
            input: Some(spec.clone()),
            ..args.input.clone()
        })
        .collect();
    series_of(args, &inputs, base, pool)
}

/// `--frames`: the time points of INPUT (its frames, as `--frame` counts
/// them), one frame each, as a series of inputs is rendered.
pub fn time_points(
    args: &RenderArgs,
    kind: OutputKind,
    base: &RenderSettings,
    pool: &ThreadPool,
) -> Result<(), CliError> {
    let spec = args
        .input
        .input
        .as_deref()
        .unwrap_or(volray_app::input::DEMO);
    let refuse = |why: String| Err(CliError::input(format!("--frames: {spec}: {why}")));
    if volray_data::is_source_spec(spec) {
        return refuse("a built-in source has one time point: give a file holding several".into());
    }
    if args.input.frame.is_some() {
        return Err(CliError::input(
            "--frames renders the time points of INPUT; --frame picks one: give one of them",
        ));
    }
    // The count, from the first time point's file information.
    let count = match &load(&args.input, false)?.file {
        Some((_, info)) => info.time_points,
        None => 1,
    };
    if count < 2 {
        return refuse("it holds one time point (volray info says what it holds)".into());
    }
    let range = args.scene.frames.expect("--frames given");
    let end = range.end.unwrap_or(count);
    if range.start >= count || end > count {
        let given = match range.end {
            Some(e) => format!("{}:{e}", range.start),
            None => format!("{}:", range.start),
        };
        return Err(CliError::input(format!(
            "--frames {given}: {spec} holds {count} time points, numbered from 0"
        )));
    }
    volray_app::reads::refuse_overwriting_inputs(
        &crate::outfile::output_files(args, kind, end - range.start),
        &[spec.to_string()],
        &args.view.look.tf_file().into_iter().collect::<Vec<_>>(),
    )?;
    let inputs: Vec<InputArgs> = (range.start..end)
        .map(|t| InputArgs {
            frame: Some(t),
            ..args.input.clone()
        })
        .collect();
    series_of(args, &inputs, base, pool)
}

/// One frame per volume `inputs` name, in order: one transfer function
/// and one framing for all.
fn series_of(
    args: &RenderArgs,
    inputs: &[InputArgs],
    base: &RenderSettings,
    pool: &ThreadPool,
) -> Result<(), CliError> {
    // Pass 1: one window, framing and transfer function for all.
    let look = &args.view.look;
    let requests: Vec<_> = inputs.iter().map(InputArgs::request).collect();
    let non_finite = args.view.sampling.nonfinite.into();
    let options = volray_flags::look(look);
    let settings = series_settings(&requests, base, &options, non_finite, pool)
        .map_err(|e| renderer_failure(&args.view, e))?;

    // Pass 2: render each.
    let mut writer = Writer::new(args, &settings, inputs.len())?;
    for one in inputs {
        let mut input = load(one, args.view.look.log)?;
        input.volume.set_labels(look.labels);
        let fail = |e: volray_core::RenderError| render_failure(&args.view, &input.name, e);
        let renderer = renderer_for(&args.view, &settings, &input)?;
        let mut image = writer.render(pool, &renderer, &settings).map_err(fail)?;
        // One window and one view for every frame: the same colour bar and
        // scale bar in each (a perspective one at the centre of the box
        // framing them all); the outline of this frame's volume.
        let framed = settings.camera.framed_bounds(input.volume.bounds());
        crate::figure::draw_framed(
            args,
            OutputKind::Animation,
            &settings,
            &renderer,
            &input,
            &[input.volume.bounds()],
            framed,
            &mut image,
        )?;
        writer.push(&image)?;
    }
    writer.finish()
}

/// The animation being written, with its progress bar.
pub struct Writer {
    animation: Animation,
    pub bar: indicatif::ProgressBar,
}

impl Writer {
    /// Starts the animation `args` asks for: `frames` frames of the size
    /// in `settings`.
    fn new(args: &RenderArgs, settings: &RenderSettings, frames: usize) -> Result<Self, CliError> {
        Self::with_pixels(
            args,
            settings,
            frames,
            frames * settings.width * settings.height,
        )
    }

    /// [`Writer::new`], its progress bar counting `pixels` in all.
    pub fn with_pixels(
        args: &RenderArgs,
        settings: &RenderSettings,
        frames: usize,
        pixels: usize,
    ) -> Result<Self, CliError> {
        let animation = Animation::create(
            &args.out.output,
            settings.width,
            settings.height,
            frames,
            args.animation.fps.unwrap_or(crate::outfile::DEFAULT_FPS),
        )?;
        let bar = progress_bar(pixels as u64);
        Ok(Writer { animation, bar })
    }

    fn render(
        &self,
        pool: &ThreadPool,
        renderer: &Renderer,
        settings: &RenderSettings,
    ) -> Result<Image, volray_core::RenderError> {
        let report = |n: usize| self.bar.inc(n as u64);
        pool.install(|| renderer.render(FrameRequest::new(settings).reporting(&report)))
            .map(Rendered::image)
    }

    pub fn push(&mut self, image: &Image) -> Result<(), CliError> {
        Ok(self.animation.push(image)?)
    }

    pub fn finish(self) -> Result<(), CliError> {
        self.bar.finish_and_clear();
        self.animation.finish()?;
        Ok(())
    }
}
