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

use crate::animate;
use crate::error::CliError;
use crate::flags::{
    ChannelColors, Channels, InputArgs, LookArgs, MixMode, RenderArgs, SceneArgs, ViewArgs,
};
use crate::input::{self, Input};
use crate::render::{OutputKind, output_kind, write_still};
use crate::session::{load, progress_bar, render_failure, renderer_for, thread_pool};
use crate::streamed::Plan;
use std::path::{Path, PathBuf};
use volray_core::scene::{Look, Mix, Scene, SceneSettings, overlaps};
use volray_core::{PiecewiseLinear, RenderError, RenderSettings, SceneError};
use volray_io::{FileInfo, VolumeFormat};
use volray_options::{LookOptions, Naming, Opt, Options, Tf};

/// The overlay options, as the refusal of an unknown one lists them.
const OVERLAY_OPTIONS: &str = "labels, colormap=NAME, preset=NAME, range=LO,HI, opacity=P,Q, tf=FILE.json, frame=N, channel=N, hidden";

/// One volume of the picture: what was read, its settings alone (whose
/// look becomes its [`Look`]), and where it came from.
pub struct Layer {
    pub input: Input,
    pub settings: RenderSettings,
    pub source: LayerSource,
}

impl Layer {
    /// Its look in the picture: shown unless an overlay's `hidden`.
    pub fn look(&self) -> Look {
        Look {
            visible: !matches!(&self.source, LayerSource::Overlay(o) if o.hidden),
            ..Look::of(&self.settings)
        }
    }
}

/// Where a volume of the picture came from.
#[derive(Debug, Clone, PartialEq)]
pub enum LayerSource {
    /// INPUT, alone.
    Input,
    /// A channel of INPUT: its number, and whether OME-Zarr's `c` picks
    /// it (`--channel`) rather than the file's frames (`--frame`).
    Channel { index: usize, zarr: bool },
    /// An `--overlay`.
    Overlay(OverlaySpec),
}

pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    refuse_unsupported(args)?;
    let animation = args.animation.turntable.map(|_| "--turntable");
    let kind = output_kind(&args.out.output, args.out.bit_depth, animation)?;
    if args.animation.fps.is_some() && animation.is_none() {
        return Err(CliError::input(
            "--fps applies to animations: give --turntable FRAMES",
        ));
    }
    let settings = crate::settings::settings(&args.view)?;
    crate::render::check_output(&args.out.output)?;
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
    crate::overwrite::refuse_overwriting_inputs(
        &crate::render::output_files(args, kind, 1),
        &inputs,
        &tf_files,
    )?;
    let pool = thread_pool(args.view.threads)?;

    // The first input: whole (a chunked one at the level asked for).
    let first_frame = match args.animation.turntable {
        Some(n) => animate::turntable_frame(&settings, 0, n as usize),
        None => settings.clone(),
    };
    let input_args = whole_input(
        &args.input,
        &args.view,
        &first_frame,
        "--channels and --overlay",
    )?;
    let layers = read_layers(&input_args, &args.view, &args.scene, &overlays, &settings)?;

    let names: Vec<&str> = layers.iter().map(|l| l.input.name.as_str()).collect();
    let renderers = (layers.iter())
        .map(|l| renderer_for(&args.view, &l.settings, &l.input))
        .collect::<Result<Vec<_>, _>>()?;
    let fail = |e: RenderError| scene_failure(&args.view, &names, e);
    let scene = Scene::new(renderers).map_err(|e| fail(RenderError::Scene(e)))?;
    let looks: Vec<Look> = layers.iter().map(Layer::look).collect();
    let mix = match args.scene.mix {
        Some(MixMode::Composite) => Mix::Composite,
        Some(MixMode::Additive) => Mix::Additive,
        None if args.scene.channels.is_some() => Mix::Additive,
        None => Mix::Composite,
    };
    // The progress bar counts each volume rendered apart (the additive
    // mix, the projections).
    let apart = mix == Mix::Additive || settings.blend.is_projection();
    let per_frame = settings.width * settings.height * if apart { layers.len() } else { 1 };
    let frame = |settings: RenderSettings, bar: &indicatif::ProgressBar| {
        let request = SceneSettings {
            settings,
            looks: looks.clone(),
            mix,
        };
        pool.install(|| scene.render_with_progress(&request, &|n| bar.inc(n as u64), None))
            .map_err(fail)
    };
    // The first volume's colour bar and scale bar, in the view that
    // frames every volume (`camera`: the frame's), and the box of each
    // volume for --outline.
    let boxes: Vec<_> = scene.layers().iter().map(|r| r.volume().bounds()).collect();
    let annotate = |camera: volray_core::Camera, image: &mut volray_core::Image| {
        let mut first = layers[0].settings.clone();
        first.camera = camera;
        first.camera.bounds = Some(first.camera.framed_bounds(scene.bounds()));
        let renderer = &scene.layers()[0];
        crate::figure::draw_framed(
            args,
            kind,
            &first,
            renderer,
            &layers[0].input,
            &boxes,
            renderer.volume().bounds(),
            image,
        )
    };
    match (kind, args.animation.turntable) {
        (OutputKind::Animation, Some(n)) => {
            let n = n as usize;
            let mut writer = animate::Writer::with_pixels(args, &settings, n, n * per_frame)?;
            for i in 0..n {
                let turned = animate::turntable_frame(&settings, i, n);
                let camera = turned.camera;
                let mut image = frame(turned, &writer.bar)?;
                annotate(camera, &mut image)?;
                writer.push(&image)?;
            }
            writer.finish()
        }
        (kind, _) => {
            let bar = progress_bar(per_frame as u64);
            let mut image = frame(settings.clone(), &bar)?;
            bar.finish_and_clear();
            annotate(layers[0].settings.camera, &mut image)?;
            write_still(args, kind, &image)
        }
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
    match crate::streamed::plan(input, view, settings)? {
        Plan::Streamed(streamed) => Err(CliError::input(format!(
            "{}: too large to read whole under --max-memory (it would be rendered in pieces from its chunks), which {what} do not support: give a coarser --level or raise --max-memory",
            streamed.name
        ))),
        Plan::Whole { level } => Ok(crate::streamed::at_level(input, level)),
    }
}

/// The `--overlay` specs, parsed.
pub fn overlay_specs(scene: &SceneArgs) -> Result<Vec<OverlaySpec>, CliError> {
    (scene.overlay.iter())
        .map(|spec| OverlaySpec::parse(spec))
        .collect()
}

/// The volumes of the picture, each read whole with its look: INPUT (read
/// as `input_args` say) or its `--channels`, then each overlay, refused
/// where an overlay does not meet the first volume.
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
    let mut budget = Budget::new(input_args.max_memory);
    let mut layers = match &scene.channels {
        Some(which) => channels(input_args, view, scene, which, settings, &mut budget)?,
        None => {
            let mut input = load(input_args, view.look.log)?;
            budget.add(&input.volume);
            let mut settings = settings.clone();
            crate::settings::file_window(
                &view.look,
                &mut settings.transfer_function,
                (input.file.as_ref()).and_then(|(_, info)| info.display_window()),
            );
            crate::settings::from_volume(
                &view.look,
                &mut settings.transfer_function,
                &mut input.volume,
                &input.name,
            )?;
            vec![Layer {
                input,
                settings,
                source: LayerSource::Input,
            }]
        }
    };
    for (overlay, tf_text) in overlays.iter().zip(&tf_texts) {
        let mut layer = (overlay.load(view, budget.left(), tf_text.as_deref()))
            .map_err(|e| budget.explain(e))?;
        budget.add(&layer.input.volume);
        layer.input.max_memory = budget.limit;
        let first = &layers[0].input;
        if !overlaps(&layer.input.volume, &first.volume) {
            let ((a, b), (c, d)) = (layer.input.volume.bounds(), first.volume.bounds());
            return Err(CliError::input(format!(
                "--overlay {}: its box ({a} .. {b}) does not meet the box of {} ({c} .. {d}): check its origin and spacing",
                overlay.spec, first.name
            )));
        }
        layers.push(layer);
    }
    Ok(layers)
}

/// `--max-memory` shared by the volumes of one picture: each is read
/// under what the ones read before it left (a mapped volume's pages are
/// the system's to drop, and hold nothing). Each volume's renderer is
/// then checked against the whole limit on its own (`renderer_for`), not
/// against what the others' hold: a gap, for volumes whose renderers'
/// structures (brick caches, a cleaned copy) are large beside them.
pub struct Budget {
    limit: u64,
    held: u64,
}

impl Budget {
    fn new(max_memory: Option<u64>) -> Self {
        Budget {
            limit: max_memory.unwrap_or_else(volray_io::default_max_memory),
            held: 0,
        }
    }

    fn add(&mut self, volume: &volray_core::Volume) {
        if !volume.samples().is_external() {
            let [x, y, z] = volume.dims();
            let bytes = (x * y * z * volume.sample_type().bytes()) as u64;
            self.held = self.held.saturating_add(bytes);
        }
    }

    /// The limit the next volume is read under.
    fn left(&self) -> Option<u64> {
        Some(self.limit.saturating_sub(self.held))
    }

    /// A refusal of the next volume, saying what the others hold.
    fn explain(&self, e: CliError) -> CliError {
        if self.held == 0 {
            return e;
        }
        CliError {
            message: format!(
                "{} (the volumes read before it hold {} of --max-memory {})",
                e.message,
                volray_io::format_bytes(u128::from(self.held)),
                volray_io::format_bytes(u128::from(self.limit))
            ),
            ..e
        }
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
    if args.scene.frames.is_some() {
        return Err(CliError::input(format!(
            "{flag} and --frames cannot be combined: give one of them"
        )));
    }
    if args.scene.channels.is_some() {
        refuse_channel_look(&args.view.look)?;
    }
    Ok(())
}

/// Refuses the look flags that do not apply to `--channels`, whose
/// colours are `--channel-colors`' (render's and view's).
pub fn refuse_channel_look(look: &LookArgs) -> Result<(), CliError> {
    for (given, other) in [
        (look.labels, "--labels"),
        (look.preset.is_some(), "--preset"),
        (look.colormap.is_some(), "--colormap"),
    ] {
        if given {
            return Err(CliError::input(format!(
                "--channels colours each channel (--channel-colors): {other} does not apply to channels (give it to an --overlay instead)"
            )));
        }
    }
    Ok(())
}

/// A scene's render error as one line, naming the volume it is about.
fn scene_failure(view: &ViewArgs, names: &[&str], e: RenderError) -> CliError {
    match e {
        RenderError::Scene(SceneError::Layer { layer, error }) => {
            render_failure(view, names.get(layer).unwrap_or(&names[0]), *error)
        }
        e => render_failure(view, names[0], e),
    }
}

/// The channels `which` of INPUT (read as `input_args` say), each with
/// its look.
fn channels(
    input_args: &InputArgs,
    view: &ViewArgs,
    scene: &SceneArgs,
    which: &Channels,
    settings: &RenderSettings,
    budget: &mut Budget,
) -> Result<Vec<Layer>, CliError> {
    let spec = input_args.input.as_deref().unwrap_or(input::DEMO);
    if volray_data::is_source_spec(spec) {
        return Err(CliError::input(format!(
            "--channels: {spec} is a built-in source, one volume: give a file holding several channels"
        )));
    }
    let log = view.look.log;
    let first = load(input_args, log)?;
    budget.add(&first.volume);
    let Some((format, info)) = &first.file else {
        return Err(CliError::input(format!(
            "--channels: {spec} is not a file holding several channels"
        )));
    };
    let zarr = *format == VolumeFormat::Zarr;
    let count = channel_count(*format, info);
    // Which reader option picks a channel: OME-Zarr's `c` (its `t` stays
    // --frame's), else the file's frames.
    let (picked, flag) = if zarr {
        (input_args.channel, "--channel")
    } else {
        (input_args.frame, "--frame")
    };
    if picked.is_some() {
        return Err(CliError::input(format!(
            "--channels picks the channels of {spec}; {flag} picks one: give one of them"
        )));
    }
    let (indices, colors) = picked_channels(scene.channel_colors.as_ref(), which, spec, count)?;
    let mut first = Some(first);
    let mut layers = Vec::with_capacity(indices.len());
    for (&index, &rgb) in indices.iter().zip(&colors) {
        let mut input = match first.take() {
            Some(input) if index == 0 => input,
            _ => {
                let mut one = input_args.clone();
                if zarr {
                    one.channel = Some(index);
                } else {
                    one.frame = Some(index);
                }
                one.max_memory = budget.left();
                let mut input = load(&one, log).map_err(|e| budget.explain(e))?;
                budget.add(&input.volume);
                input.max_memory = budget.limit;
                input
            }
        };
        input.name = format!("{spec} (channel {index})");
        let mut settings = settings.clone();
        let tf = &mut settings.transfer_function;
        tf.color = Some(channel_color(rgb, settings.blend.is_projection()));
        crate::settings::file_window(
            &view.look,
            tf,
            input.file.as_ref().and_then(|(_, i)| i.display_window()),
        );
        crate::settings::from_volume(&view.look, tf, &mut input.volume, &input.name)?;
        layers.push(Layer {
            input,
            settings,
            source: LayerSource::Channel { index, zarr },
        });
    }
    Ok(layers)
}

/// How many channels a file holds, as its reader says: an OME-Zarr
/// image's `c` axis (the `channels` header entry), else its frames.
pub fn channel_count(format: VolumeFormat, info: &FileInfo) -> usize {
    if format == VolumeFormat::Zarr {
        (info.header.iter())
            .find(|(k, _)| k == "channels")
            .and_then(|(_, v)| v.parse::<usize>().ok())
            .unwrap_or(1)
    } else {
        info.frames
    }
}

/// The channels `which` of the `count` that `spec` holds, and their
/// colours (`--channel-colors`, else the palette): refused in one line
/// where there are none to render together, one is out of range, or the
/// colours do not match them.
pub fn picked_channels(
    channel_colors: Option<&ChannelColors>,
    which: &Channels,
    spec: &str,
    count: usize,
) -> Result<(Vec<usize>, Vec<[f32; 3]>), CliError> {
    if count < 2 {
        return Err(CliError::input(format!(
            "--channels: {spec} holds one volume, no channels to render together (volray info {spec} says what it holds)"
        )));
    }
    let indices: Vec<usize> = match which {
        Channels::All => (0..count).collect(),
        Channels::Some(list) => list.clone(),
    };
    if let Some(bad) = indices.iter().find(|&&i| i >= count) {
        return Err(CliError::input(format!(
            "--channels {bad}: {spec} holds {count} channels, numbered from 0"
        )));
    }
    let colors = match channel_colors {
        Some(given) if given.0.len() != indices.len() => {
            return Err(CliError::input(format!(
                "--channel-colors: {} colour(s) for {} channels: give one per channel",
                given.0.len(),
                indices.len()
            )));
        }
        Some(given) => given.0.clone(),
        None => (0..indices.len())
            .map(volray_options::colors::channel_colour)
            .collect(),
    };
    Ok((indices, colors))
}

/// A channel's colour transfer function: its colour at every value where
/// samples are composited (the opacity says how much of it), from black
/// to it over the window where the projections show the value through
/// the colour map.
fn channel_color(rgb: [f32; 3], projection: bool) -> PiecewiseLinear<3> {
    if projection {
        PiecewiseLinear::new("color", vec![(0.0, [0.0; 3]), (1.0, rgb)]).expect("colours in [0, 1]")
    } else {
        PiecewiseLinear::constant(rgb)
    }
}

/// An `--overlay FILE[:OPTIONS]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OverlaySpec {
    /// As given, for messages.
    pub spec: String,
    pub file: String,
    pub labels: bool,
    pub colormap: Option<String>,
    pub preset: Option<String>,
    pub range: Option<(f64, f64)>,
    pub opacity: Option<(f32, f32)>,
    pub tf: Option<String>,
    pub frame: Option<usize>,
    /// OME-Zarr's `c` (as `--channel`).
    pub channel: Option<usize>,
    /// Placed and framed, not drawn (`Look::visible`).
    pub hidden: bool,
}

impl OverlaySpec {
    /// Parses `spec`: the options are after the last ':' whose remainder
    /// reads as options (so `file.h5:/dataset` stays a file spec).
    fn parse(spec: &str) -> Result<Self, CliError> {
        let (file, options) = (spec.char_indices().rev())
            .filter(|&(_, c)| c == ':')
            .find_map(|(at, _)| option_tokens(&spec[at + 1..]).map(|o| (&spec[..at], o)))
            .unwrap_or((spec, Vec::new()));
        let mut parsed = OverlaySpec {
            spec: spec.to_string(),
            file: file.to_string(),
            ..Default::default()
        };
        let refuse = |message: String| CliError::input(format!("--overlay {spec}: {message}"));
        let mut seen: Vec<&str> = Vec::new();
        for (name, value) in &options {
            if seen.contains(&name.as_str()) {
                return Err(refuse(format!("option \"{name}\" is given twice")));
            }
            seen.push(name);
            let value = match (name.as_str(), value) {
                ("labels", None) => {
                    parsed.labels = true;
                    continue;
                }
                ("hidden", None) => {
                    parsed.hidden = true;
                    continue;
                }
                ("labels" | "hidden", Some(_)) => {
                    return Err(refuse(format!("{name} takes no value")));
                }
                (_, Some(v)) => v.as_str(),
                _ => unreachable!("only labels and hidden are bare words"),
            };
            let bad = |e: String| refuse(format!("{name}={value}: {e}"));
            match name.as_str() {
                "colormap" => parsed.colormap = Some(value.to_string()),
                "preset" => parsed.preset = Some(value.to_string()),
                "range" => parsed.range = Some(crate::flags::parse_range(value).map_err(bad)?),
                "opacity" => {
                    parsed.opacity = Some(crate::flags::parse_opacity(value).map_err(bad)?)
                }
                "tf" => parsed.tf = Some(value.to_string()),
                "frame" => {
                    parsed.frame = Some(
                        value
                            .trim()
                            .parse()
                            .map_err(|_| bad("not a frame number (from 0)".to_string()))?,
                    )
                }
                "channel" => {
                    parsed.channel = Some(
                        value
                            .trim()
                            .parse()
                            .map_err(|_| bad("not a channel number (from 0)".to_string()))?,
                    )
                }
                _ => {
                    return Err(refuse(format!(
                        "unknown option \"{name}\" ({OVERLAY_OPTIONS})"
                    )));
                }
            }
        }
        if parsed.file.is_empty() {
            return Err(refuse("no file before the options".to_string()));
        }
        Ok(parsed)
    }

    /// The overlay read, with its look.
    fn load(
        &self,
        view: &ViewArgs,
        max_memory: Option<u64>,
        tf_text: Option<&str>,
    ) -> Result<Layer, CliError> {
        let refuse = |e: volray_options::OptionError| {
            CliError::input(format!(
                "--overlay {}: {}",
                self.spec,
                e.message(&OverlayNaming)
            ))
        };
        let input_args = InputArgs {
            input: Some(self.file.clone()),
            dims: None,
            dtype: None,
            endian: None,
            spacing: None,
            format: None,
            frame: self.frame,
            array: None,
            level: None,
            channel: self.channel,
            max_memory,
        };
        let mut input = load(&input_args, false).map_err(|e| CliError {
            message: format!("--overlay: {}", e.message),
            ..e
        })?;
        let (look, mut settings) = self.settings(view, tf_text)?;
        volray_options::file_window(
            &look,
            &mut settings.transfer_function,
            input.file.as_ref().and_then(|(_, i)| i.display_window()),
        );
        volray_options::from_volume(
            &look,
            &mut settings.transfer_function,
            &mut input.volume,
            &input.name,
        )
        .map_err(refuse)?;
        Ok(Layer {
            input,
            settings,
            source: LayerSource::Overlay(self.clone()),
        })
    }

    /// Its options' look (with the shared flags of `view`) and settings,
    /// before anything is chosen from its volume.
    pub fn settings(
        &self,
        view: &ViewArgs,
        tf_text: Option<&str>,
    ) -> Result<(LookOptions, RenderSettings), CliError> {
        let refuse = |e: volray_options::OptionError| {
            CliError::input(format!(
                "--overlay {}: {}",
                self.spec,
                e.message(&OverlayNaming)
            ))
        };
        // The shared flags without the first volume's `--tf` (whose text
        // is not read here): the overlay's look is its own options'.
        let shared = crate::settings::options(view, Some(""))?;
        let look = LookOptions {
            opacity: self.opacity,
            tf: self.tf.as_ref().map(|path| Tf::Json {
                source: path.clone(),
                text: tf_text.unwrap_or_default().to_string(),
            }),
            preset: self.preset.clone(),
            colormap: self.colormap.clone(),
            labels: self.labels,
            label_opacity: None,
            show_labels: None,
            range: self.range,
            iso: None,
            iso_thickness: None,
            log: false,
            blend: match shared.look.blend {
                volray_options::BlendMode::Iso => volray_options::BlendMode::Composite,
                blend => blend,
            },
            ..shared.look.clone()
        };
        let options = Options {
            look: look.clone(),
            ..shared
        };
        let settings = volray_options::settings(&options).map_err(refuse)?;
        Ok((look, settings))
    }
}

/// The options of a remainder after ':', as (name, value) pairs: tokens
/// split at ','; `name=value` starts an option, a bare number continues
/// the value before (`range=0,100`), `labels` is a bare word. `None`
/// where the remainder does not read as options.
fn option_tokens(rest: &str) -> Option<Vec<(String, Option<String>)>> {
    let mut options: Vec<(String, Option<String>)> = Vec::new();
    for token in rest.split(',') {
        let token = token.trim();
        if let Some((name, value)) = token.split_once('=') {
            let word = !name.is_empty()
                && (name.chars()).all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if !word {
                return None;
            }
            options.push((name.to_string(), Some(value.to_string())));
        } else if token == "labels" || token == "hidden" {
            options.push((token.to_string(), None));
        } else if token.parse::<f64>().is_ok()
            && let Some((_, Some(value))) = options.last_mut()
        {
            value.push(',');
            value.push_str(token);
        } else {
            return None;
        }
    }
    Some(options)
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

/// How an overlay's options are written: `preset=`, `labels`; the shared
/// flags as flags.
struct OverlayNaming;

impl OverlayNaming {
    fn own(opt: Opt) -> bool {
        matches!(
            opt,
            Opt::Opacity | Opt::Tf | Opt::Preset | Opt::Colormap | Opt::Labels | Opt::Range
        )
    }
}

impl Naming for OverlayNaming {
    fn option(&self, opt: Opt) -> String {
        match opt {
            Opt::Labels => "labels".to_string(),
            opt if Self::own(opt) => format!("{}=", opt.name()),
            opt => format!("--{}", opt.name()),
        }
    }

    fn with_value(&self, opt: Opt, value: &str) -> String {
        if Self::own(opt) {
            format!("{}={value}", opt.name())
        } else {
            format!("--{} {value}", opt.name())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(spec: &str) -> OverlaySpec {
        OverlaySpec::parse(spec).unwrap()
    }

    #[test]
    fn overlay_options_follow_the_last_colon_that_reads_as_options() {
        let o = parsed("seg.nii.gz:labels");
        assert_eq!((o.file.as_str(), o.labels), ("seg.nii.gz", true));
        let o = parsed("ct.nii:range=0,100,opacity=0,0.5,colormap=magma,frame=2");
        assert_eq!(o.file, "ct.nii");
        assert_eq!(o.range, Some((0.0, 100.0)));
        assert_eq!(o.opacity, Some((0.0, 0.5)));
        assert_eq!(o.colormap.as_deref(), Some("magma"));
        assert_eq!(o.frame, Some(2));
        // File specs with a ':' of their own stay whole.
        assert_eq!(parsed("file.h5:/dataset").file, "file.h5:/dataset");
        assert_eq!(parsed("file.nc:/var").file, "file.nc:/var");
        let o = parsed("file.h5:/group/data:labels,preset=mr");
        assert_eq!(o.file, "file.h5:/group/data");
        assert_eq!(o.preset.as_deref(), Some("mr"));
        assert_eq!(parsed("plain.nrrd").file, "plain.nrrd");
        let message = |spec: &str| OverlaySpec::parse(spec).unwrap_err().message;
        assert_eq!(
            message("seg.nii.gz:color=red"),
            format!("--overlay seg.nii.gz:color=red: unknown option \"color\" ({OVERLAY_OPTIONS})")
        );
        assert!(message("a.nii:range=5,1").contains("range=5,1"));
        assert!(message("a.nii:labels,labels").contains("twice"));
    }
}
