//! The page's state as `volray render` words: the command a viewer's
//! Command box shows, whose frame is the page's (`volray view` parses the
//! words back with its own flags' parser to render it, and
//! `tests/view_browser.rs` runs the command to check).
//!
//! What the page sets comes from the state; everything else from the
//! flags the viewer was started with ([`CommandWords::new`], as
//! volray-options has them), dropped where the state makes it
//! inapplicable (lighting flags under `--no-shading` or a projection,
//! opacity flags under a projection), as `render` would refuse them. A
//! scene's other volumes are written as `--overlay`s with their look in
//! full ([`SceneWords`]).

use super::state::{BlendMode, START_COLOURS, ViewState, WHITE};
use super::viewer::Refusal;
use crate::scene::{ChannelAxis, Layer, LayerSource, mix_name};
use volray_annotate::figure::preset_unit;
use volray_core::scene::{Look, Mix};
use volray_core::{NonFinite, Phong, RenderSettings, TransferFunction};
use volray_options::Options;

/// The file the command writes and the transfer-function file it names.
pub const OUTPUT: &str = "view.png";
pub const TF_FILE: &str = "view-tf.json";

/// The transfer-function file of a scene's volume `n` (from 1, the
/// first's being [`TF_FILE`]).
pub fn layer_tf_file(n: usize) -> String {
    format!("view-tf-{n}.json")
}

/// The largest |log10| of a window end or isovalue written in the data's
/// units under `--log` (10^308 is near the end of `f64`).
const MAX_LOG: f64 = 300.0;

/// The flags a viewer was started with, kept as the words of the command
/// lines it writes.
#[derive(Debug, Clone)]
pub struct CommandWords {
    /// INPUT (the spec or path as given).
    input: String,
    /// Its reading flags.
    reading: Vec<String>,
    /// Flags that apply whatever the state: `--up`, `--reference`,
    /// `--jitter`, `--nonfinite`, `--log`.
    always: Vec<String>,
    /// Flags that shape the opacity of compositing:
    /// `--gradient-opacity`, `--post-classification`.
    shaping: Vec<String>,
    /// `--iso-thickness`, with an isosurface.
    iso_thickness: Vec<String>,
    /// The lighting flags, when lit and the state sets no lighting.
    lighting: Vec<String>,
    /// `--light-color`, when lit.
    light_color: Vec<String>,
    /// `--opacity P,Q` as given.
    ramp: Option<(f32, f32)>,
    /// The transfer function the flags named, its window in the data's
    /// units.
    start: TransferFunction,
    log: bool,
    /// A scene's other volumes, as the command's `--overlay`s.
    scene: Option<SceneWords>,
    /// Whether the viewer serves a time axis: the state's time point is
    /// the command's `--frame`.
    time: bool,
    /// The unit the page's colour bar gives its values (`HU` under a CT
    /// preset): the command, which names no preset, says it as `--units`.
    value_unit: Option<String>,
}

/// A scene's volumes after the first as the command writes them: each
/// an `--overlay` of its file with its look in full (`range=`, `tf=`),
/// whatever its starting options, so that the command is the frame.
#[derive(Debug, Clone)]
pub struct SceneWords {
    /// What picks the first volume's channel: `--frame K` or
    /// `--channel K` (none for an input with overlays).
    pub first: Vec<String>,
    pub others: Vec<OtherWords>,
    pub mix: Mix,
}

/// A scene's volume after the first.
#[derive(Debug, Clone)]
pub struct OtherWords {
    /// Its file, and the options that pick and classify it: `frame=K`,
    /// `channel=K`, `labels`.
    pub file: String,
    pub fixed: Vec<String>,
    /// Its starting transfer function, its domain the window it starts
    /// with (explicit: the value range where none was chosen).
    pub start: TransferFunction,
    /// Its starting opacity ramp.
    pub ramp: (f32, f32),
    /// A label volume keeps its label table's look (`start_look`), shown
    /// or hidden.
    pub labels: bool,
    pub start_look: Look,
}

impl SceneWords {
    /// The words of the picture of `layers` (read from INPUT, `spec`, at
    /// the time point `--frame` picks, `time`), mixed as `mix` says:
    /// the first volume's channel, every other volume's options.
    pub fn of(spec: &str, time: Option<usize>, layers: &[Layer], mix: Mix) -> Self {
        let others = (layers[1..].iter())
            .map(|layer| {
                let range = layer.input.volume.value_range();
                let (source, settings) = (&layer.source, &layer.settings);
                OtherWords::of(source, spec, time, settings, range, layer.look())
            })
            .collect();
        SceneWords {
            first: SceneWords::first_of(&layers[0].source),
            others,
            mix,
        }
    }

    /// What picks the first volume of a scene that came from `source`:
    /// its channel's `--channel K` or `--frame K`.
    pub fn first_of(source: &LayerSource) -> Vec<String> {
        match source {
            LayerSource::Channel { index, axis } => {
                vec![format!("--{}", axis.option()), index.to_string()]
            }
            _ => Vec::new(),
        }
    }
}

impl OtherWords {
    /// A volume after the first that came from `source`, with its
    /// `settings` alone, whose values range over `value_range`, and its
    /// starting `look`: a channel is INPUT (`spec`) at the time point
    /// `--frame` picks (`time`), the channel its axis names.
    pub fn of(
        source: &LayerSource,
        spec: &str,
        time: Option<usize>,
        settings: &RenderSettings,
        value_range: Option<(f32, f32)>,
        look: Look,
    ) -> Self {
        let (file, fixed, labels) = match source {
            LayerSource::Channel { index, axis } => {
                let mut fixed = vec![format!("{}={index}", axis.option())];
                if let (ChannelAxis::Channel, Some(t)) = (axis, time) {
                    fixed.push(format!("frame={t}"));
                }
                (spec.to_string(), fixed, false)
            }
            LayerSource::Overlay(o) => {
                let mut fixed = Vec::new();
                if let Some(f) = o.frame {
                    fixed.push(format!("frame={f}"));
                }
                if let Some(c) = o.channel {
                    fixed.push(format!("channel={c}"));
                }
                if o.labels {
                    fixed.push("labels".to_string());
                }
                (o.file.clone(), fixed, o.labels)
            }
            LayerSource::Input => unreachable!("only the first volume is INPUT"),
        };
        let mut start = settings.transfer_function.clone();
        if start.domain.is_none() {
            let (lo, hi) = value_range.unwrap_or((0.0, 1.0));
            start.domain = Some((f64::from(lo), f64::from(hi)));
        }
        OtherWords {
            file,
            fixed,
            start,
            ramp: settings.opacity_ramp,
            labels,
            start_look: look,
        }
    }
}

impl CommandWords {
    /// The command lines of a viewer of `input` (the spec or path as
    /// given), read with the flags `reading`, started with `options` (the
    /// flags as volray-options has them), whose transfer function
    /// (`--tf`, `--preset`, `--colormap`, `--range`) is `start`.
    pub fn new(
        input: String,
        reading: Vec<String>,
        options: &Options,
        start: TransferFunction,
    ) -> Self {
        let cam = &options.camera;
        let look = &options.look;
        let sampling = &options.sampling;

        let mut always = Words::default();
        always.opt("--up", (cam.up != [0.0, 0.0, 1.0]).then(|| v3(cam.up)));
        always.flag("--reference", sampling.reference);
        always.flag("--jitter", sampling.jitter);
        always.opt(
            "--nonfinite",
            (sampling.nonfinite == NonFinite::Transparent).then(|| "transparent".to_string()),
        );
        always.flag("--log", look.log);
        // Label normals; the colours and opacities go in the --tf file.
        always.flag("--labels", look.labels);

        let mut shaping = Words::default();
        shaping.opt(
            "--gradient-opacity",
            look.gradient_opacity.map(|(lo, hi)| format!("{lo},{hi}")),
        );
        shaping.flag("--post-classification", look.post_classification);

        let mut iso_thickness = Words::default();
        iso_thickness.opt("--iso-thickness", look.iso_thickness.map(|r| r.to_string()));

        let lit = Phong::default();
        let mut lighting = Words::default();
        lighting.opt(
            "--ambient",
            (look.ambient != lit.ambient).then(|| rgb(look.ambient)),
        );
        lighting.opt(
            "--diffuse",
            (look.diffuse != lit.diffuse).then(|| rgb(look.diffuse)),
        );
        lighting.opt(
            "--specular",
            (look.specular != lit.specular).then(|| rgb(look.specular)),
        );
        lighting.opt(
            "--shininess",
            (look.shininess != lit.shininess).then(|| look.shininess.to_string()),
        );
        lighting.opt("--light", look.light.map(v3));
        let mut light_color = Words::default();
        light_color.opt(
            "--light-color",
            (look.light_color != lit.light_color).then(|| rgb(look.light_color)),
        );
        lighting.0.extend(light_color.0.iter().cloned());

        CommandWords {
            input,
            reading,
            always: always.0,
            shaping: shaping.0,
            iso_thickness: iso_thickness.0,
            lighting: lighting.0,
            light_color: light_color.0,
            ramp: look.opacity,
            start,
            log: look.log,
            scene: None,
            time: false,
            value_unit: preset_unit(look.preset.as_deref()).map(String::from),
        }
    }

    /// The same, for a scene whose other volumes `scene` describes.
    pub fn with_scene(mut self, scene: SceneWords) -> Self {
        self.scene = Some(scene);
        self
    }

    /// The same, for a viewer of a time axis: the state's time point is
    /// the command's `--frame`.
    pub fn with_time(mut self) -> Self {
        self.time = true;
        self
    }

    /// The same, its commands reading the level `level` names (`auto` or
    /// a number), if any: a multiscale volume's.
    pub fn with_level(mut self, level: Option<String>) -> Self {
        if let Some(level) = level {
            self.reading.push("--level".into());
            self.reading.push(level);
        }
        self
    }

    /// The scene's other volumes, if any.
    pub fn scene(&self) -> Option<&SceneWords> {
        self.scene.as_ref()
    }

    /// The command's words, its `--tf` file's JSON, and the files a
    /// scene's `--overlay`s name.
    pub fn words(&self, state: &ViewState) -> Result<CommandOf, Refusal> {
        let mut w = Words::default();
        w.word("render");
        let dashed = self.input.starts_with('-');
        if !dashed {
            w.word(&self.input);
        }
        w.0.extend(self.reading.iter().cloned());
        match (self.time, state.time) {
            (true, Some(t)) => w.opt("--frame", Some(t.to_string())),
            (true, None) => return Err(Refusal("the state names no time point".into())),
            (false, Some(_)) => {
                return Err(Refusal("this viewer serves no time axis".into()));
            }
            (false, None) => {}
        }
        let others = self.scene.as_ref().map_or(&[][..], |s| &s.others[..]);
        if state.layers.len() != others.len() {
            return Err(Refusal(format!(
                "the state describes {} volume(s) beside the first; the viewer shows {}",
                state.layers.len(),
                others.len()
            )));
        }
        if let Some(scene) = &self.scene {
            w.0.extend(scene.first.iter().cloned());
        }
        let (width, height) = (state.width, state.height);
        w.opt(
            "--size",
            ((width, height) != (480, 480)).then(|| format!("{width}x{height}")),
        );
        w.opt("--view", state.view_point.map(v3));
        w.opt("--look-at", state.look_at.map(v3));
        w.opt("--perspective", state.perspective.map(|f| f.to_string()));
        w.opt(
            "--zoom",
            (state.zoom != 1.0).then(|| state.zoom.to_string()),
        );
        w.opt("--azimuth", Some(state.azimuth.to_string()));
        w.opt("--elevation", Some(state.elevation.to_string()));
        w.opt(
            "--step",
            (state.step != 1.0).then(|| state.step.to_string()),
        );
        for [point, normal] in &state.clip {
            w.opt("--clip", Some(format!("{},{}", v3(*point), v3(*normal))));
        }
        w.opt(
            "--crop",
            state.crop.map(|[lo, hi]| {
                format!(
                    "{},{},{},{},{},{}",
                    lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
                )
            }),
        );
        w.0.extend(self.always.iter().cloned());

        let projection = state.blend.is_projection();
        let blend = match state.blend {
            BlendMode::Composite => None,
            BlendMode::Mip => Some("mip"),
            BlendMode::Minip => Some("minip"),
            BlendMode::Average => Some("average"),
            BlendMode::Iso => Some("iso"),
        };
        w.opt("--blend", blend.map(str::to_string));
        if state.blend == BlendMode::Iso {
            let iso = state.iso.map(f64::from).unwrap_or_default();
            w.opt("--iso", Some(self.data_units(iso, "the isovalue")?));
            w.0.extend(self.iso_thickness.iter().cloned());
        }
        let window = match state.window {
            Some([lo, hi]) => Some((
                self.data_units(lo, "the window")?,
                self.data_units(hi, "the window")?,
            )),
            None => self
                .start
                .domain
                .map(|(lo, hi)| (lo.to_string(), hi.to_string())),
        };
        w.opt("--range", window.map(|(lo, hi)| format!("{lo},{hi}")));

        let opacity: Option<Vec<[f32; 2]>> = match &state.opacity {
            _ if projection => None,
            Some(points) => Some(points.clone()),
            None => self
                .start
                .opacity
                .as_ref()
                .map(|f| f.points().iter().map(|&(t, [a])| [t, a]).collect()),
        };
        if !projection {
            if opacity.is_none() {
                w.opt("--opacity", self.ramp.map(|(p, q)| format!("{p},{q}")));
            }
            w.0.extend(self.shaping.iter().cloned());
            if let (true, Some(l)) = (state.shading, &state.lighting) {
                w.opt("--ambient", Some(l.ambient.to_string()));
                w.opt("--diffuse", Some(l.diffuse.to_string()));
                w.opt("--specular", Some(l.specular.to_string()));
                w.opt("--shininess", Some(l.shininess.to_string()));
                w.opt("--light", l.light.map(v3));
                w.0.extend(self.light_color.iter().cloned());
            } else if state.shading {
                w.0.extend(self.lighting.iter().cloned());
            } else {
                w.word("--no-shading");
            }
            w.flag("--shadows", state.shading && state.shadows);
            let radius = state.ambient_occlusion.map(|r| r.to_string());
            w.opt("--ambient-occlusion", radius);
        }
        let colours = match state.colormap.as_str() {
            START_COLOURS => self.start.color.as_ref().map(|f| f.points().to_vec()),
            WHITE => None,
            name => {
                w.opt("--colormap", Some(name.to_string()));
                None
            }
        };
        if state.colormap == START_COLOURS && colours.is_none() {
            return Err(Refusal(
                "the starting transfer function has no colours: pick a colour map".into(),
            ));
        }
        // With no transfer function, colour map or isosurface, `render`
        // would choose its own from the volume (`--tf auto`): an empty one
        // keeps the page's ramp and white.
        let named_map = !matches!(state.colormap.as_str(), START_COLOURS | WHITE);
        let bare = !projection && state.blend != BlendMode::Iso && !named_map;
        let json = (opacity.is_some() || colours.is_some() || bare)
            .then(|| tf_json(opacity.as_deref(), colours.as_deref()));
        if json.is_some() {
            w.opt("--tf", Some(TF_FILE.to_string()));
        }
        w.opt(
            "--background",
            (state.background != [0.0; 3]).then(|| rgb(state.background)),
        );
        let mut files = Vec::new();
        if let Some(scene) = &self.scene {
            for (i, (layer, other)) in state.layers.iter().zip(&scene.others).enumerate() {
                let mut options = other.fixed.clone();
                if !other.labels {
                    let (lo, hi) = match layer.window {
                        Some([lo, hi]) => (lo, hi),
                        None => other.start.domain.expect("an explicit starting window"),
                    };
                    options.push(format!("range={lo},{hi}"));
                    let opacity: Option<Vec<[f32; 2]>> = match &layer.opacity {
                        Some(points) => Some(points.clone()),
                        None => (other.start.opacity.as_ref())
                            .map(|f| f.points().iter().map(|&(t, [a])| [t, a]).collect()),
                    };
                    if opacity.is_none() {
                        options.push(format!("opacity={},{}", other.ramp.0, other.ramp.1));
                    }
                    let colours = match layer.colormap.as_str() {
                        START_COLOURS => other.start.color.as_ref().map(|f| f.points().to_vec()),
                        WHITE => None,
                        name => match super::state::solid_colour(name) {
                            Some(c) => Some(vec![(0.0, c), (1.0, c)]),
                            None => {
                                options.push(format!("colormap={name}"));
                                None
                            }
                        },
                    };
                    let name = layer_tf_file(i + 2);
                    options.push(format!("tf={name}"));
                    files.push((name, tf_json(opacity.as_deref(), colours.as_deref())));
                }
                if !layer.visible {
                    options.push("hidden".into());
                }
                w.opt(
                    "--overlay",
                    Some(format!("{}:{}", other.file, options.join(","))),
                );
            }
            w.opt("--mix", Some(mix_name(scene.mix).to_string()));
        }
        let figure = &state.figure;
        w.opt(
            "--colorbar",
            figure.colorbar.map(|side| side.name().to_string()),
        );
        if figure.colorbar.is_some() {
            w.opt("--units", self.value_unit.clone());
        }
        if figure.scale_bar {
            match figure.scale_length {
                Some(l) => w.opt("--scale-bar", Some(l.to_string())),
                None => w.word("--scale-bar"),
            }
        }
        w.flag("--axes", figure.axes);
        w.flag("--outline", figure.outline);
        w.opt("--title", figure.title.clone());
        w.opt("--label", figure.label.clone());
        w.opt("-o", Some(OUTPUT.to_string()));
        if dashed {
            w.word("--");
            w.word(&self.input);
        }
        Ok((w.0, json, files))
    }

    /// `value` (as the renderer sees it) as the flags give it: with
    /// `--log`, 10^value.
    fn data_units(&self, value: f64, what: &str) -> Result<String, Refusal> {
        if !self.log {
            return Ok(value.to_string());
        }
        if value.abs() > MAX_LOG {
            return Err(Refusal(format!(
                "{what} {value} (log10) is beyond 10^±{MAX_LOG}"
            )));
        }
        Ok(10f64.powf(value).to_string())
    }
}

/// A command's words, its `--tf` file's JSON, and its `--overlay`s'
/// files: name and JSON.
pub type CommandOf = (Vec<String>, Option<String>, Vec<(String, String)>);

/// Command-line words being written.
#[derive(Debug, Default)]
pub struct Words(pub Vec<String>);

impl Words {
    pub fn word(&mut self, word: &str) {
        self.0.push(word.to_string());
    }

    /// `flag value`, when there is a value.
    pub fn opt(&mut self, flag: &str, value: Option<String>) {
        if let Some(value) = value {
            self.0.push(flag.to_string());
            self.0.push(value);
        }
    }

    /// `flag`, when set.
    pub fn flag(&mut self, flag: &str, set: bool) {
        if set {
            self.word(flag);
        }
    }
}

/// A point or direction, `x,y,z`.
pub fn v3([x, y, z]: [f64; 3]) -> String {
    format!("{x},{y},{z}")
}

/// One value when the three are equal, else `r,g,b`.
fn rgb([r, g, b]: [f32; 3]) -> String {
    if r == g && g == b {
        r.to_string()
    } else {
        format!("{r},{g},{b}")
    }
}

/// A transfer-function file: one point a line.
fn tf_json(opacity: Option<&[[f32; 2]]>, colours: Option<&[(f32, [f32; 3])]>) -> String {
    let lines = |rows: Vec<String>| format!("[\n    {}\n  ]", rows.join(",\n    "));
    let mut fields = Vec::new();
    if let Some(points) = opacity {
        let rows = points.iter().map(|[t, a]| format!("[{t}, {a}]")).collect();
        fields.push(format!("  \"opacity\": {}", lines(rows)));
    }
    if let Some(points) = colours {
        let rows = (points.iter())
            .map(|(t, [r, g, b])| format!("[{t}, {r}, {g}, {b}]"))
            .collect();
        fields.push(format!("  \"color\": {}", lines(rows)));
    }
    format!("{{\n{}\n}}\n", fields.join(",\n"))
}

/// `word` as a POSIX shell reads it back: as it is when it holds only
/// characters the shell leaves alone, else in single quotes.
pub fn shell_quote(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./:,=+@%".contains(c));
    if plain {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reproduce::state::LayerState;
    use crate::scene::OverlaySpec;

    /// The words of a viewer of `blobs:16` started with the defaults, and
    /// its starting state.
    fn start() -> (CommandWords, ViewState) {
        let options = Options::default();
        let settings = volray_options::settings(&options).unwrap();
        let state = crate::reproduce::options::start_state(&options, &settings);
        let tf = settings.transfer_function.clone();
        let words = CommandWords::new("blobs:16".into(), Vec::new(), &options, tf);
        (words, state)
    }

    #[test]
    fn the_starting_command_renders_input_with_the_pages_camera_to_view_png() {
        let (words, mut state) = start();
        state.azimuth = 30.5;
        state.zoom = 2.0;
        let (w, _, files) = words.words(&state).unwrap();
        assert_eq!(w[..2], ["render", "blobs:16"]);
        assert_eq!(w[w.len() - 2..], ["-o", OUTPUT]);
        for pair in [["--azimuth", "30.5"], ["--zoom", "2"], ["--elevation", "0"]] {
            assert!(w.windows(2).any(|p| p == pair), "{pair:?} in {w:?}");
        }
        assert!(files.is_empty(), "no scene, no overlay files");
        // An input that reads as a flag goes after `--`.
        let options = Options::default();
        let tf = TransferFunction::default();
        let dashed = CommandWords::new("-x.nrrd".into(), Vec::new(), &options, tf);
        let (w, _, _) = dashed.words(&state).unwrap();
        assert_eq!(w[w.len() - 2..], ["--", "-x.nrrd"]);
        assert_eq!(w.iter().filter(|w| *w == "-x.nrrd").count(), 1);
    }

    #[test]
    fn a_scenes_volumes_are_overlays_that_parse_back_to_their_looks() {
        let (words, mut state) = start();
        let settings = RenderSettings {
            transfer_function: TransferFunction::default(),
            opacity_ramp: (0.1, 0.6),
            ..RenderSettings::default()
        };
        let look = Look::of(&settings);
        let overlay = LayerSource::Overlay(OverlaySpec::parse("seg.nii:frame=2").unwrap());
        let channel = LayerSource::Channel {
            index: 1,
            axis: ChannelAxis::Channel,
        };
        let first = LayerSource::Channel {
            index: 0,
            axis: ChannelAxis::Channel,
        };
        let others = vec![
            OtherWords::of(
                &overlay,
                "in.tif",
                Some(3),
                &settings,
                Some((0.0, 10.0)),
                look.clone(),
            ),
            OtherWords::of(
                &channel,
                "in.tif",
                Some(3),
                &settings,
                Some((-1.0, 1.0)),
                look,
            ),
        ];
        let words = words.with_scene(SceneWords {
            first: SceneWords::first_of(&first),
            others,
            mix: Mix::Additive,
        });
        state.layers = vec![
            LayerState {
                visible: true,
                window: Some([1.0, 5.5]),
                opacity: Some(vec![[0.0, 0.0], [1.0, 0.5]]),
                colormap: "#ff0000".into(),
            },
            LayerState {
                visible: false,
                window: None,
                opacity: None,
                colormap: WHITE.into(),
            },
        ];
        let (w, _, files) = words.words(&state).unwrap();
        assert!(w.windows(2).any(|p| p == ["--channel", "0"]), "{w:?}");
        assert!(w.windows(2).any(|p| p == ["--mix", "additive"]), "{w:?}");
        let overlays: Vec<&str> = (w.windows(2))
            .filter(|p| p[0] == "--overlay")
            .map(|p| p[1].as_str())
            .collect();
        assert_eq!(
            overlays,
            [
                "seg.nii:frame=2,range=1,5.5,tf=view-tf-2.json",
                "in.tif:channel=1,frame=3,range=-1,1,opacity=0.1,0.6,tf=view-tf-3.json,hidden",
            ]
        );
        // Each parses back to the volume and look the page shows.
        let parsed: Vec<OverlaySpec> = (overlays.iter())
            .map(|o| OverlaySpec::parse(o).unwrap())
            .collect();
        assert_eq!(
            (parsed[0].file.as_str(), parsed[0].frame, parsed[0].range),
            ("seg.nii", Some(2), Some((1.0, 5.5)))
        );
        assert_eq!(
            (parsed[1].file.as_str(), parsed[1].channel, parsed[1].frame),
            ("in.tif", Some(1), Some(3))
        );
        assert_eq!(
            (parsed[1].range, parsed[1].opacity, parsed[1].hidden),
            (Some((-1.0, 1.0)), Some((0.1, 0.6)), true)
        );
        assert!(!parsed[0].hidden);
        // Their files hold the page's opacity points and colours.
        let names: Vec<&str> = files.iter().map(|(name, _)| name.as_str()).collect();
        assert_eq!(names, ["view-tf-2.json", "view-tf-3.json"]);
        let tf = TransferFunction::from_json(&files[0].1).unwrap();
        let opacity: Vec<(f32, [f32; 1])> = tf.opacity.unwrap().points().to_vec();
        assert_eq!(opacity, [(0.0, [0.0]), (1.0, [0.5])]);
        let red: Vec<(f32, [f32; 3])> = tf.color.unwrap().points().to_vec();
        assert_eq!(red, [(0.0, [1.0, 0.0, 0.0]), (1.0, [1.0, 0.0, 0.0])]);
        let white = TransferFunction::from_json(&files[1].1).unwrap();
        assert_eq!((white.opacity, white.color), (None, None));
        // The state must describe the volumes the viewer shows.
        state.layers.pop();
        assert!(words.words(&state).unwrap_err().0.contains("1 volume(s)"));
    }

    #[test]
    fn odd_words_are_quoted_for_the_shell() {
        assert_eq!(shell_quote("blobs:64"), "blobs:64");
        assert_eq!(shell_quote("-0.5,1e-3"), "-0.5,1e-3");
        assert_eq!(shell_quote("my scan.nrrd"), "'my scan.nrrd'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
        assert_eq!(shell_quote(""), "''");
        assert_eq!(shell_quote("$HOME"), "'$HOME'");
    }
}
