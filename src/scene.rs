//! `volray render` of several volumes in one picture (volray-core's
//! [`Scene`]): the channels of INPUT (`--channels`, each in its colour,
//! `--channel-colors`) and volumes over it (`--overlay FILE[:OPTIONS]`),
//! mixed as `--mix` says; a still or a `--turntable`.
//!
//! Each volume's look is built as the first volume's is, by volray-options
//! from the same kind of options: a channel takes the shared look flags
//! (its opacity chosen from its own histogram by default, its own value
//! window unless `--range`) with its colour as a constant colour transfer
//! function; an overlay takes the options after its ':' (`labels`,
//! `colormap=`, `preset=`, `range=`, `opacity=`, `tf=`, `frame=`) with the
//! shared shading. Each volume is read whole and checked against
//! `--max-memory` on its own (`session.rs`). Plain renders never come here.
//! The volumes are read by `volray_app::scene` (`read.rs`); here are the
//! flags, the refusals worded with them, and the frames written.

use crate::animate;
use crate::error::CliError;
use crate::outfile::{OutputKind, output_kind, write_still};
use crate::session::{progress_bar, render_failure, renderer_for, thread_pool};
use std::path::{Path, PathBuf};
use volray_app::animation::{Turntable, Views};
use volray_app::input;
use volray_app::plan::Plan;
use volray_app::scene::{
    self, ChannelAxis, ChannelPick, Failure, First, Layer, LayerError, LayerSource, OverlaySpec,
    Overlays, Refused, channel_axis, channels_at, default_mix, time_range,
};
use volray_core::scene::{Mix, Scene, SceneSettings};
use volray_core::{FrameRequest, Render, RenderError, RenderSettings, Rendered, SceneError};
use volray_flags::{Channels, InputArgs, LookArgs, RenderArgs, SceneArgs, ViewArgs};

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    refuse_unsupported(args)?;
    let animation = match (args.animation.turntable, args.scene.frames) {
        (Some(_), _) => Some("--turntable"),
        (None, Some(_)) => Some("--frames"),
        (None, None) => None,
    };
    let kind = output_kind(&args.out.output, args.out.bit_depth, animation)?;
    if args.animation.fps.is_some() && animation.is_none() {
        return Err(CliError::input(
            "--fps applies to animations: give --turntable FRAMES",
        ));
    }
    let settings = crate::settings::settings(&args.view)?;
    crate::outfile::check_output(&args.out.output)?;
    let overlays = overlay_specs(&args.scene)?;
    let first_spec = args.input.input.as_deref().unwrap_or(input::DEMO);
    let inputs: Vec<String> = std::iter::once(first_spec.to_string())
        .chain(overlays.iter().map(|o| o.file.clone()))
        .collect();
    let tf_files: Vec<&Path> = (args.view.look.tf_file().into_iter())
        .chain(
            overlays
                .iter()
                .filter_map(|o| o.tf.as_deref().map(Path::new)),
        )
        .collect();
    volray_app::reads::refuse_overwriting_inputs(
        &crate::outfile::output_files(args, kind, 1),
        &inputs,
        &tf_files,
    )?;
    let pool = thread_pool(args.view.threads)?;

    // The first input: whole (a chunked one at the level asked for).
    let first_frame = match args.animation.turntable {
        Some(n) => Turntable(n as usize).frame(&settings, 0),
        None => settings.clone(),
    };
    let input_args = whole_input(
        &args.input,
        &args.view,
        &first_frame,
        "--channels and --overlay",
    )?;
    let layers = read_layers(&input_args, &args.view, &args.scene, &overlays, &settings)?;
    let pictures = Pictures {
        args,
        kind,
        pool: &pool,
        mix: mix(&args.scene),
    };
    if let Some(range) = args.scene.frames {
        return pictures.time_walk(&input_args, layers, &settings, range);
    }
    let scene = pictures.scene(&layers)?;
    // The progress bar counts each volume rendered apart (the additive
    // mix, the projections).
    let apart = pictures.mix == Mix::Additive || settings.blend.is_projection();
    let per_frame = settings.width * settings.height * if apart { layers.len() } else { 1 };
    match (kind, args.animation.turntable) {
        (OutputKind::Animation, Some(n)) => {
            let views = Turntable(n as usize);
            let n = views.frames();
            let mut writer = animate::Writer::with_pixels(args, &settings, n, n * per_frame)?;
            for i in 0..n {
                let turned = views.frame(&settings, i);
                let camera = turned.camera;
                let image = pictures.picture(&scene, &layers, turned, camera, &writer.bar)?;
                writer.push(&image)?;
            }
            writer.finish()
        }
        (kind, _) => {
            let bar = progress_bar(per_frame as u64);
            let camera = layers[0].settings.camera;
            let image = pictures.picture(&scene, &layers, settings.clone(), camera, &bar)?;
            bar.finish_and_clear();
            write_still(args, kind, &image)
        }
    }
}

/// The frames of a picture of several volumes: its scene, each frame
/// rendered and annotated as the first volume's.
struct Pictures<'a> {
    args: &'a RenderArgs,
    kind: OutputKind,
    pool: &'a rayon::ThreadPool,
    mix: Mix,
}

impl Pictures<'_> {
    /// The scene of `layers`, each volume's renderer within `--max-memory`,
    /// their caches sharing what the frames leave.
    fn scene<'v>(&self, layers: &'v [Layer]) -> Result<Scene<'v>, CliError> {
        let view = &self.args.view;
        let renderers = (layers.iter())
            .map(|l| renderer_for(view, &l.settings, &l.input))
            .collect::<Result<Vec<_>, _>>()?;
        let each: Vec<_> = layers.iter().map(|l| (&l.input, &l.settings)).collect();
        let mode = view.sampling.nonfinite.into();
        let renderers = volray_app::renderer::share_caches(renderers, &each, mode);
        Scene::new(renderers).map_err(|e| scene_failure(view, layers, RenderError::Scene(e)))
    }

    /// One frame of `scene` (of `layers`) with `settings`, annotated as
    /// the first volume's in the view that frames every volume (`camera`:
    /// the frame's), with the box of each volume for `--outline`.
    fn picture(
        &self,
        scene: &Scene,
        layers: &[Layer],
        settings: RenderSettings,
        camera: volray_core::Camera,
        bar: &indicatif::ProgressBar,
    ) -> Result<volray_core::Image, CliError> {
        let request = SceneSettings {
            settings,
            looks: layers.iter().map(Layer::look).collect(),
            mix: self.mix,
        };
        let report = |n: usize| bar.inc(n as u64);
        let mut image = (self.pool)
            .install(|| scene.render(FrameRequest::new(&request).reporting(&report)))
            .map(Rendered::image)
            .map_err(|e| scene_failure(&self.args.view, layers, e))?;
        let boxes: Vec<_> = scene.layers().iter().map(|r| r.volume().bounds()).collect();
        let mut first = layers[0].settings.clone();
        first.camera = camera;
        first.camera.bounds = Some(first.camera.framed_bounds(scene.bounds()));
        let renderer = &scene.layers()[0];
        crate::figure::draw_framed(
            self.args,
            self.kind,
            &first,
            renderer,
            &layers[0].input,
            &boxes,
            renderer.volume().bounds(),
            &mut image,
        )?;
        Ok(image)
    }

    /// `--channels` with `--frames`: the channels at each time point of
    /// the range, one frame each, every channel with the look (transfer
    /// function, window) it has at the first, as a series of inputs has
    /// one transfer function; each time point's volumes read after the
    /// last one's are dropped.
    fn time_walk(
        &self,
        input_args: &InputArgs,
        first: Vec<Layer>,
        settings: &RenderSettings,
        range: volray_flags::Frames,
    ) -> Result<(), CliError> {
        let args = self.args;
        let spec = args.input.input.as_deref().unwrap_or(input::DEMO);
        let (count, axis) = match &first[0].input.file {
            Some((_, info)) => channel_axis(info),
            None => (1, ChannelAxis::Channel),
        };
        let count = match (axis, &first[0].input.file) {
            (ChannelAxis::Channel, Some((_, info))) => info.time_points,
            _ => {
                return Err(CliError::input(format!(
                    "--channels renders the {count} time points of {spec} (one channel) together: --frames cannot walk them too"
                )));
            }
        };
        let end = time_range(range.start, range.end, count, spec).map_err(refused)?;
        let n = end - range.start;
        let files = crate::outfile::output_files(args, self.kind, n);
        volray_app::reads::refuse_overwriting_inputs(&files, &[spec.to_string()], &[])?;
        let per_frame = settings.width * settings.height * first.len();
        let mut writer = animate::Writer::with_pixels(args, settings, n, n * per_frame)?;
        // The looks of time point 0, read first; its volumes rendered if
        // the range starts there, else dropped now.
        let looks: Vec<(LayerSource, RenderSettings)> = (first.iter())
            .map(|l| (l.source.clone(), l.settings.clone()))
            .collect();
        let mut layers = (range.start == 0).then_some(first);
        for t in range.start..end {
            let now = match layers.take() {
                Some(first) => first,
                None => channels_at(&input_args.request(), args.view.look.log, t, &looks)
                    .map_err(layer_failure)?,
            };
            let scene = self.scene(&now)?;
            let camera = now[0].settings.camera;
            let image = self.picture(&scene, &now, settings.clone(), camera, &writer.bar)?;
            drop(scene);
            drop(now);
            writer.push(&image)?;
        }
        writer.finish()
    }
}

/// INPUT read whole (a chunked file at the level `plan` picks for a frame
/// of `settings`), refused where it would be rendered in pieces, which
/// `what` does not support.
pub fn whole_input(
    input: &InputArgs,
    view: &ViewArgs,
    settings: &RenderSettings,
    what: &str,
) -> Result<InputArgs, CliError> {
    match crate::session::plan(input, view, settings)? {
        Plan::Streamed(streamed) => Err(CliError::input(format!(
            "{}: too large to read whole under --max-memory (it would be rendered in pieces from its chunks), which {what} do not support: give a coarser --level or raise --max-memory",
            streamed.name
        ))),
        Plan::Whole { level } => Ok(input.at_level(level)),
    }
}

/// The `--overlay` specs, parsed.
pub fn overlay_specs(scene: &SceneArgs) -> Result<Vec<OverlaySpec>, CliError> {
    (scene.overlay.iter())
        .map(|spec| OverlaySpec::parse(spec).map_err(refused))
        .collect()
}

/// How the volumes mix: `--mix`, else additive for channels.
pub fn mix(scene: &SceneArgs) -> Mix {
    match scene.mix {
        Some(volray_flags::MixMode::Composite) => Mix::Composite,
        Some(volray_flags::MixMode::Additive) => Mix::Additive,
        None => default_mix(scene.channels.is_some()),
    }
}

/// A scene's refusal as an input error.
fn refused(e: Refused) -> CliError {
    CliError::input(e.0)
}

/// The channels `which` of the `count` that `spec` holds, and their
/// colours (`--channel-colors`, else the palette): `mpirun`'s
/// `--channels` (one process reads them through `read_layers`).
#[cfg(feature = "mpi")]
pub fn picked(
    scene: &SceneArgs,
    which: &Channels,
    spec: &str,
    count: usize,
) -> Result<(Vec<usize>, Vec<[f32; 3]>), CliError> {
    let which = match which {
        Channels::All => None,
        Channels::Some(list) => Some(&list[..]),
    };
    let colors = scene.channel_colors.as_ref().map(|c| &c.0[..]);
    volray_app::scene::picked_channels(colors, which, spec, count).map_err(refused)
}

/// Refuses the look flags that do not apply to `--channels`, whose
/// colours are `--channel-colors`' (render's and view's).
pub fn refuse_channel_look(look: &LookArgs) -> Result<(), CliError> {
    volray_app::scene::refuse_channel_look(&volray_flags::look(look)).map_err(refused)
}

/// The volumes of the picture, each read whole with its look
/// (`volray_app::scene::read_layers`): INPUT (read as `input_args` say)
/// or its `--channels`, then each overlay.
pub fn read_layers(
    input_args: &InputArgs,
    view: &ViewArgs,
    scene: &SceneArgs,
    overlays: &[OverlaySpec],
    settings: &RenderSettings,
) -> Result<Vec<Layer>, CliError> {
    let tf_texts = (overlays.iter())
        .map(|o| {
            o.tf.as_deref()
                .map(|tf| read_overlay_tf(&o.spec, tf))
                .transpose()
        })
        .collect::<Result<Vec<_>, _>>()?;
    let request = input_args.request();
    let look = volray_flags::look(&view.look);
    let first = First {
        request: &request,
        log: view.look.log,
        look: &look,
    };
    let colors = scene.channel_colors.as_ref().map(|c| &c.0[..]);
    let channels = scene.channels.as_ref().map(|which| ChannelPick {
        which: match which {
            Channels::All => None,
            Channels::Some(list) => Some(&list[..]),
        },
        colors,
    });
    // The shared flags without the first volume's `--tf` (whose text
    // is not read here): an overlay's look is its own options'.
    let shared = crate::settings::options(view, Some(""))?;
    let overlays = Overlays {
        specs: overlays,
        tf_texts: &tf_texts,
        shared: &shared,
    };
    scene::read_layers(&first, channels, &overlays, settings).map_err(layer_failure)
}

/// A volume of the picture refused, worded with the flags: the reader's
/// error as `load`'s, an overlay's after `--overlay:`, saying what the
/// volumes read before it hold.
fn layer_failure(e: LayerError) -> CliError {
    let error = match *e.failure {
        Failure::Read(e) => CliError::from(e),
        Failure::OverlayRead(e) => {
            let e = CliError::from(e);
            CliError {
                message: format!("--overlay: {}", e.message),
                ..e
            }
        }
        Failure::Option(e) => crate::settings::refused(e),
        Failure::Refused(e) => refused(e),
    };
    match e.after {
        Some(budget) => CliError {
            message: budget.explain(&error.message),
            ..error
        },
        None => error,
    }
}

/// The refusals of what several volumes in one picture do not take.
fn refuse_unsupported(args: &RenderArgs) -> Result<(), CliError> {
    let flag = if args.scene.channels.is_some() {
        "--channels"
    } else {
        "--overlay"
    };
    if !args.animation.series.is_empty() {
        return Err(CliError::input(format!(
            "{flag} renders INPUT with its channels or overlays in one picture: several inputs (a series) are not supported with it"
        )));
    }
    if args.scene.frames.is_some() && !args.scene.overlay.is_empty() {
        return Err(CliError::input(
            "--overlay and --frames cannot be combined: give one of them",
        ));
    }
    if args.scene.frames.is_some() && args.animation.turntable.is_some() {
        return Err(CliError::input(
            "--frames animates the time points of INPUT: give --frames or --turntable, not both",
        ));
    }
    if args.scene.frames.is_some() && args.input.frame.is_some() {
        return Err(CliError::input(
            "--frames renders the time points of INPUT; --frame picks one: give one of them",
        ));
    }
    if args.scene.channels.is_some() {
        refuse_channel_look(&args.view.look)?;
    }
    Ok(())
}

/// A scene's render error as one line, naming the volume it is about.
fn scene_failure(view: &ViewArgs, layers: &[Layer], e: RenderError) -> CliError {
    let name = |i: usize| layers.get(i).unwrap_or(&layers[0]).input.name.as_str();
    match e {
        RenderError::Scene(SceneError::Layer { layer, error }) => {
            render_failure(view, name(layer), *error)
        }
        e => render_failure(view, name(0), e),
    }
}

/// Reads the `tf=` file of the overlay `spec`, refused as `--tf` is.
fn read_overlay_tf(spec: &str, path: &str) -> Result<String, CliError> {
    crate::settings::read_tf_file(&PathBuf::from(path)).map_err(|e| CliError {
        message: format!(
            "--overlay {spec}: {}",
            e.message.replacen("--tf ", "tf=", 1)
        ),
        ..e
    })
}
