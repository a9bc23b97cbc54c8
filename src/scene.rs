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

pub(crate) mod channels;
mod layer;

use channels::read_channels;
pub use channels::refuse_channel_look;
use layer::Budget;
pub use layer::{ChannelAxis, Layer, LayerSource, channel_axis};

use crate::animate;
use crate::error::CliError;
use crate::flags::{InputArgs, MixMode, RenderArgs, SceneArgs, ViewArgs};
use crate::input;
use crate::render::{OutputKind, output_kind, write_still};
use crate::session::{load, progress_bar, render_failure, renderer_for, thread_pool};
use crate::streamed::Plan;
use std::path::{Path, PathBuf};
use volray_core::scene::{Look, Mix, Scene, SceneSettings, overlaps};
use volray_core::{FrameRequest, Render, RenderError, RenderSettings, Rendered, SceneError};
use volray_options::{LookOptions, Naming, Opt, Options, Tf};

/// The overlay options, as the refusal of an unknown one lists them.
const OVERLAY_OPTIONS: &str = "labels, colormap=NAME, preset=NAME, range=LO,HI, opacity=P,Q, tf=FILE.json, frame=N, channel=N, hidden";

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
    let mix = match args.scene.mix {
        Some(MixMode::Composite) => Mix::Composite,
        Some(MixMode::Additive) => Mix::Additive,
        None if args.scene.channels.is_some() => Mix::Additive,
        None => Mix::Composite,
    };
    if let Some(range) = args.scene.frames {
        let walk = TimeWalk {
            args,
            kind,
            settings: &settings,
            pool: &pool,
            mix,
        };
        return walk.run(&input_args, layers, range);
    }

    let names: Vec<&str> = layers.iter().map(|l| l.input.name.as_str()).collect();
    let renderers = (layers.iter())
        .map(|l| renderer_for(&args.view, &l.settings, &l.input))
        .collect::<Result<Vec<_>, _>>()?;
    let fail = |e: RenderError| scene_failure(&args.view, &names, e);
    let scene = Scene::new(renderers).map_err(|e| fail(RenderError::Scene(e)))?;
    let looks: Vec<Look> = layers.iter().map(Layer::look).collect();
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
        let report = |n: usize| bar.inc(n as u64);
        pool.install(|| scene.render(FrameRequest::new(&request).reporting(&report)))
            .map(Rendered::image)
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

/// `--channels` with `--frames`: the channels at each time point of the
/// range, one frame each, every channel with the look (transfer function,
/// window) it has at the first, as a series of inputs has one transfer
/// function; each time point's volumes read after the last one's are
/// dropped.
struct TimeWalk<'a> {
    args: &'a RenderArgs,
    kind: OutputKind,
    settings: &'a RenderSettings,
    pool: &'a rayon::ThreadPool,
    mix: Mix,
}

impl TimeWalk<'_> {
    fn run(
        &self,
        input_args: &InputArgs,
        first: Vec<Layer>,
        range: crate::flags::Frames,
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
        let end = range.end.unwrap_or(count);
        if count < 2 || range.start >= count || end > count {
            return Err(CliError::input(format!(
                "--frames {}:{end}: {spec} holds {count} time point(s), numbered from 0",
                range.start
            )));
        }
        let n = end - range.start;
        let files = crate::render::output_files(args, self.kind, n);
        crate::overwrite::refuse_overwriting_inputs(&files, &[spec.to_string()], &[])?;
        let per_frame = self.settings.width * self.settings.height * first.len();
        let mut writer = animate::Writer::with_pixels(args, self.settings, n, n * per_frame)?;
        // The looks of time point 0, read first; its volumes rendered if
        // the range starts there, else dropped now.
        let looks: Vec<(LayerSource, RenderSettings)> = (first.iter())
            .map(|l| (l.source.clone(), l.settings.clone()))
            .collect();
        let mut layers = (range.start == 0).then_some(first);
        for t in range.start..end {
            let now = match layers.take() {
                Some(first) => first,
                None => self.read_at(input_args, t, &looks)?,
            };
            let image = self.picture(&now, &writer.bar)?;
            drop(now);
            writer.push(&image)?;
        }
        writer.finish()
    }

    /// The channels of `looks` at time point `t`, each with its look.
    fn read_at(
        &self,
        input_args: &InputArgs,
        t: usize,
        looks: &[(LayerSource, RenderSettings)],
    ) -> Result<Vec<Layer>, CliError> {
        let spec = input_args.input.as_deref().unwrap_or(input::DEMO);
        let at = InputArgs {
            frame: Some(t),
            ..input_args.clone()
        };
        let mut budget = Budget::new(at.max_memory);
        let mut layers = Vec::with_capacity(looks.len());
        for (source, settings) in looks {
            let LayerSource::Channel { index, axis } = source else {
                unreachable!("--frames takes channels only");
            };
            let mut one = axis.pick(&at, *index);
            one.max_memory = budget.left();
            let mut input = load(&one, self.args.view.look.log).map_err(|e| budget.explain(e))?;
            budget.add(&input.volume);
            input.max_memory = budget.limit;
            input.name = format!("{spec} (channel {index}, time point {t})");
            layers.push(Layer {
                input,
                settings: settings.clone(),
                source: source.clone(),
            });
        }
        Ok(layers)
    }

    /// One frame of `layers`, annotated as the first volume's.
    fn picture(
        &self,
        layers: &[Layer],
        bar: &indicatif::ProgressBar,
    ) -> Result<volray_core::Image, CliError> {
        let view = &self.args.view;
        let names: Vec<&str> = layers.iter().map(|l| l.input.name.as_str()).collect();
        let renderers = (layers.iter())
            .map(|l| renderer_for(view, &l.settings, &l.input))
            .collect::<Result<Vec<_>, _>>()?;
        let fail = |e: RenderError| scene_failure(view, &names, e);
        let scene = Scene::new(renderers).map_err(|e| fail(RenderError::Scene(e)))?;
        let request = SceneSettings {
            settings: self.settings.clone(),
            looks: layers.iter().map(Layer::look).collect(),
            mix: self.mix,
        };
        let mut image = (self.pool)
            .install(|| scene.render(FrameRequest::new(&request).reporting(&|n| bar.inc(n as u64))))
            .map(Rendered::image)
            .map_err(fail)?;
        let boxes: Vec<_> = scene.layers().iter().map(|r| r.volume().bounds()).collect();
        let mut first = layers[0].settings.clone();
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
        Some(which) => read_channels(input_args, view, scene, which, settings, &mut budget)?,
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
fn scene_failure(view: &ViewArgs, names: &[&str], e: RenderError) -> CliError {
    match e {
        RenderError::Scene(SceneError::Layer { layer, error }) => {
            render_failure(view, names.get(layer).unwrap_or(&names[0]), *error)
        }
        e => render_failure(view, names[0], e),
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
