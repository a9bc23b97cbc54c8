//! The page's state as a `volray render` command, and the settings of
//! that command: `volray view`'s [`Reproduce`].
//!
//! A state becomes words (`render INPUT --azimuth 30 ... -o view.png`),
//! the words are parsed by the same clap parser and turned into settings
//! by the same `settings.rs` as a real `volray render`, with the
//! transfer-function file's text handed over instead of read. The frame
//! the page shows is therefore the command's frame, pixel for pixel, by
//! construction (and `tests/view_browser.rs` runs the command to check).
//!
//! What the page sets comes from the state; everything else from the
//! flags `volray view` was started with, dropped where the state makes it
//! inapplicable (lighting flags under `--no-shading` or a projection,
//! opacity flags under a projection), as `render` would refuse them.

use crate::error::CliError;
use crate::flags::{Cli, Command, ViewerArgs};
use crate::settings::settings_with_tf_text;
use clap::Parser;
use volray_app::input;
use volray_core::glam::DVec3;
use volray_core::scene::{Look, Mix};
use volray_core::{NonFinite, Phong, SampleType, TransferFunction};
use volray_view::{
    BlendMode, Refusal, Reproduce, Reproduction, START_COLOURS, SceneLooks, ViewState, WHITE,
};

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

/// `volray view`'s flags, kept as the words of the command lines it writes.
pub struct CliReproduce {
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
    /// The volume's grid and sample type, how its non-finite values are
    /// rendered, and the memory limit, for the memory check.
    grid: ([usize; 3], DVec3, SampleType),
    non_finite: NonFinite,
    max_memory: u64,
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
pub struct SceneWords {
    /// What picks the first volume's channel: `--frame K` or
    /// `--channel K` (none for an input with overlays).
    pub first: Vec<String>,
    pub others: Vec<OtherWords>,
    pub mix: Mix,
}

/// A scene's volume after the first.
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

impl CliReproduce {
    /// The command lines of a `volray view` started with `args`, whose
    /// transfer function (`--tf`, `--preset`, `--colormap`, `--range`) is
    /// `start`, for a volume of `grid` (dims, spacing, sample type) whose
    /// non-finite values are rendered as `non_finite` says.
    pub fn new(
        args: &ViewerArgs,
        start: TransferFunction,
        grid: ([usize; 3], DVec3, SampleType),
        non_finite: NonFinite,
        max_memory: u64,
    ) -> Self {
        let inp = &args.input;
        let cam = &args.view.camera;
        let look = &args.view.look;
        let sampling = &args.view.sampling;
        let mut reading = Words::default();
        reading.opt("--dims", inp.dims.map(|[x, y, z]| format!("{x},{y},{z}")));
        reading.opt("--dtype", inp.dtype.clone());
        reading.opt("--endian", inp.endian.clone());
        reading.opt("--spacing", inp.spacing.map(v3));
        reading.opt("--format", inp.format.clone());
        reading.opt("--frame", inp.frame.map(|f| f.to_string()));
        reading.opt("--array", inp.array.clone());
        reading.opt("--channel", inp.channel.map(|c| c.to_string()));
        reading.opt("--max-memory", inp.max_memory.map(|m| m.to_string()));

        let mut always = Words::default();
        always.opt("--up", (cam.up != [0.0, 0.0, 1.0]).then(|| v3(cam.up)));
        always.flag("--reference", sampling.reference);
        always.flag("--jitter", sampling.jitter);
        always.opt(
            "--nonfinite",
            (volray_core::NonFinite::from(sampling.nonfinite)
                == volray_core::NonFinite::Transparent)
                .then(|| "transparent".to_string()),
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

        CliReproduce {
            input: inp.input.as_deref().unwrap_or(input::DEMO).to_string(),
            reading: reading.0,
            always: always.0,
            shaping: shaping.0,
            iso_thickness: iso_thickness.0,
            lighting: lighting.0,
            light_color: light_color.0,
            ramp: look.opacity,
            start,
            log: look.log,
            grid,
            non_finite,
            max_memory,
            scene: None,
            time: false,
            value_unit: volray_annotate::figure::preset_unit(look.preset.as_deref())
                .map(String::from),
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

    /// The arguments of the `volray render` command of `state` (after
    /// `volray`), and the transfer-function file's JSON if it names one.
    #[cfg(test)]
    pub fn words(&self, state: &ViewState) -> Result<(Vec<String>, Option<String>), Refusal> {
        self.scene_words(state)
            .map(|(words, json, _)| (words, json))
    }

    /// The command's words, its `--tf` file's JSON, and the files a
    /// scene's `--overlay`s name.
    fn scene_words(&self, state: &ViewState) -> Result<SceneWordsOf, Refusal> {
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
                        name => match volray_view::solid_colour(name) {
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
            let mix = match scene.mix {
                Mix::Composite => "composite",
                Mix::Additive => "additive",
            };
            w.opt("--mix", Some(mix.to_string()));
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

    /// The looks of a scene's other volumes as `render` makes them of the
    /// command's words: `--overlay`s with their files' texts.
    fn scene_looks(
        &self,
        args: &crate::flags::RenderArgs,
        files: Vec<(String, String)>,
    ) -> Result<Option<SceneLooks>, Refusal> {
        let Some(scene) = &self.scene else {
            return Ok(None);
        };
        let refuse = |e: CliError| Refusal(e.message);
        let specs = crate::scene::overlay_specs(&args.scene).map_err(refuse)?;
        let mut looks = Vec::with_capacity(specs.len());
        for (spec, other) in specs.iter().zip(&scene.others) {
            let look = if spec.labels {
                other.start_look.clone()
            } else {
                let text = (files.iter())
                    .find(|(name, _)| Some(name) == spec.tf.as_ref())
                    .map(|(_, text)| text.as_str());
                let (_, settings) = spec.settings(&args.view, text).map_err(refuse)?;
                Look::of(&settings)
            };
            looks.push(Look {
                visible: !spec.hidden,
                ..look
            });
        }
        let mix = match args.scene.mix {
            Some(crate::flags::MixMode::Additive) => Mix::Additive,
            _ => Mix::Composite,
        };
        Ok(Some(SceneLooks {
            looks,
            mix,
            tf_files: files,
        }))
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

impl Reproduce for CliReproduce {
    fn reproduce(&self, state: &ViewState) -> Result<Reproduction, Refusal> {
        let (words, json, files) = self.scene_words(state)?;
        let argv = std::iter::once("volray").chain(words.iter().map(String::as_str));
        let cli =
            Cli::try_parse_from(argv).map_err(|e| Refusal(crate::flags::one_line_error(&e)))?;
        let Command::Render(args) = cli.command else {
            unreachable!("the words start with render")
        };
        let refuse = |e: CliError| Refusal(e.message);
        let settings = settings_with_tf_text(&args.view, json.as_deref()).map_err(refuse)?;
        // The frame must fit with no brick cache (as `render` checks).
        let need = volray_app::memory::render_bytes(self.grid, &settings, self.non_finite, 0);
        if need > u128::from(self.max_memory) {
            return Err(Refusal(format!(
                "a {}x{} frame may take up to {}, more than --max-memory {}",
                settings.width,
                settings.height,
                volray_io::format_bytes(need),
                volray_io::format_bytes(u128::from(self.max_memory))
            )));
        }
        let command = std::iter::once("volray".to_string())
            .chain(words.iter().map(|w| shell_quote(w)))
            .collect::<Vec<_>>()
            .join(" ");
        let scene = self.scene_looks(&args, files)?;
        Ok(Reproduction {
            settings,
            command,
            tf_file: json.map(|json| (TF_FILE.to_string(), json)),
            scene,
        })
    }
}

/// A command's words, its `--tf` file's JSON, and its `--overlay`s'
/// files: name and JSON.
type SceneWordsOf = (Vec<String>, Option<String>, Vec<(String, String)>);

/// Command-line words being written.
#[derive(Default)]
struct Words(Vec<String>);

impl Words {
    fn word(&mut self, word: &str) {
        self.0.push(word.to_string());
    }

    /// `flag value`, when there is a value.
    fn opt(&mut self, flag: &str, value: Option<String>) {
        if let Some(value) = value {
            self.0.push(flag.to_string());
            self.0.push(value);
        }
    }

    /// `flag`, when set.
    fn flag(&mut self, flag: &str, set: bool) {
        if set {
            self.word(flag);
        }
    }
}

fn v3([x, y, z]: [f64; 3]) -> String {
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
fn shell_quote(word: &str) -> String {
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
    use crate::flags::Cli;
    use crate::settings::{named_transfer_function, settings};
    use volray_view::BlendMode;

    fn viewer(extra: &[&str]) -> ViewerArgs {
        let argv = [&["volray", "view", "blobs:16"][..], extra].concat();
        match Cli::try_parse_from(argv).unwrap().command {
            Command::View(args) => args,
            _ => unreachable!(),
        }
    }

    fn reproduce(extra: &[&str]) -> (CliReproduce, ViewState) {
        let args = viewer(extra);
        let start = named_transfer_function(&args.view.look, None).unwrap();
        let settings = settings(&args.view).unwrap();
        let state = super::super::start_state(&args, &settings);
        let max_memory = args.input.max_memory.unwrap_or(1 << 30);
        let grid = ([16; 3], DVec3::ONE, SampleType::F32);
        let r = CliReproduce::new(&args, start, grid, NonFinite::Refuse, max_memory);
        (r, state)
    }

    /// The settings `render` makes of the command's words.
    fn render_settings(words: &[String], json: Option<&str>) -> volray_core::RenderSettings {
        let argv = std::iter::once("volray").chain(words.iter().map(String::as_str));
        let Command::Render(args) = Cli::try_parse_from(argv).unwrap().command else {
            unreachable!()
        };
        settings_with_tf_text(&args.view, json).unwrap()
    }

    #[test]
    fn the_starting_state_is_the_starting_command() {
        let flags = [
            "--azimuth",
            "30",
            "--elevation",
            "-12.5",
            "--zoom",
            "1.5",
            "--size",
            "320x200",
            "--colormap",
            "magma",
            "--range",
            "0.1,0.9",
            "--opacity",
            "0.05,0.6",
            "--ambient",
            "0.2",
            "--background",
            "0.1,0.2,0.3",
            "--step",
            "0.5",
        ];
        let (r, state) = reproduce(&flags);
        let out = r.reproduce(&state).unwrap();
        assert_eq!(
            out.command,
            "volray render blobs:16 --size 320x200 --zoom 1.5 --azimuth 30 --elevation -12.5 \
             --step 0.5 --range 0.1,0.9 --opacity 0.05,0.6 --ambient 0.2 --colormap magma \
             --background 0.1,0.2,0.3 -o view.png"
        );
        assert_eq!(out.tf_file, None);
        // The same settings as the flags give `render`.
        let render = [&["volray", "render", "-o", "x.png", "blobs:16"][..], &flags].concat();
        let Command::Render(args) = Cli::try_parse_from(render).unwrap().command else {
            unreachable!()
        };
        assert_eq!(out.settings, settings(&args.view).unwrap());
    }

    #[test]
    fn a_ct_presets_colour_bar_is_in_hounsfield_units_on_the_command_too() {
        let (r, mut state) = reproduce(&["--preset", "ct-bone"]);
        let without = r.reproduce(&state).unwrap().command;
        assert!(!without.contains("--units"), "{without}");
        state.figure.colorbar = Some(volray_view::ColorBarSide::Right);
        let (words, _) = r.words(&state).unwrap();
        assert!(
            words.windows(2).any(|w| w == ["--units", "HU"]),
            "{words:?}"
        );
        assert!(!words.iter().any(|w| w == "--preset"), "{words:?}");
        // Without a CT preset, render would say no unit either.
        let (r, mut state) = reproduce(&["--colormap", "magma"]);
        state.figure.colorbar = Some(volray_view::ColorBarSide::Right);
        let command = r.reproduce(&state).unwrap().command;
        assert!(!command.contains("--units"), "{command}");
    }

    #[test]
    fn a_white_ramp_is_named_so_that_render_does_not_choose_its_own() {
        let (r, mut state) = reproduce(&["--opacity", "0.05,0.6"]);
        state.colormap = WHITE.to_string();
        state.opacity = None;
        let out = r.reproduce(&state).unwrap();
        assert!(
            out.command.contains("--opacity 0.05,0.6") && out.command.contains("--tf"),
            "{}",
            out.command
        );
        let (words, json) = r.words(&state).unwrap();
        let argv = std::iter::once("volray").chain(words.iter().map(String::as_str));
        let Command::Render(args) = Cli::try_parse_from(argv).unwrap().command else {
            unreachable!()
        };
        assert!(!args.view.look.auto_tf());
        let s = render_settings(&words, json.as_deref());
        assert_eq!(s.transfer_function.opacity, None);
        assert_eq!(s.transfer_function.color, None);
        assert_eq!(s.opacity_ramp, (0.05, 0.6));
        assert_eq!(out.settings, s);
    }

    #[test]
    fn edited_states_round_trip_through_the_command() {
        let (r, start) = reproduce(&["--gradient-opacity", "0.1,0.5", "--specular", "0.5"]);
        let mut state = start.clone();
        state.azimuth = -37.25;
        state.elevation = 89.5;
        state.zoom = 2.375;
        state.look_at = Some([0.125, -3.5, 1e-3]);
        state.perspective = Some(35.0);
        state.window = Some([0.1234567, 0.9]);
        state.opacity = Some(vec![
            [0.0, 0.0],
            [0.3333, 0.1234],
            [0.3333, 0.5],
            [1.0, 0.7],
        ]);
        state.colormap = "viridis".into();
        state.background = [1.0, 0.5, 0.25];
        let out = r.reproduce(&state).unwrap();
        let (name, json) = out.tf_file.clone().unwrap();
        assert_eq!(name, TF_FILE);
        assert!(out.command.contains("--tf view-tf.json"), "{}", out.command);
        assert!(
            out.command
                .contains("--gradient-opacity 0.1,0.5 --specular 0.5")
        );
        let s = &out.settings;
        assert_eq!(
            (s.camera.azimuth, s.camera.elevation, s.camera.zoom),
            (-37.25, 89.5, 2.375)
        );
        assert_eq!(s.camera.look_at, Some(DVec3::new(0.125, -3.5, 1e-3)));
        assert_eq!(s.transfer_function.domain, Some((0.1234567, 0.9)));
        let points: Vec<(f32, [f32; 1])> = s
            .transfer_function
            .opacity
            .as_ref()
            .unwrap()
            .points()
            .to_vec();
        assert_eq!(
            points,
            [
                (0.0, [0.0]),
                (0.3333, [0.1234]),
                (0.3333, [0.5]),
                (1.0, [0.7])
            ]
        );
        assert_eq!(s.background, [1.0, 0.5, 0.25]);
        // The words parse to the same settings with the JSON as a file's text.
        let (words, json2) = r.words(&state).unwrap();
        assert_eq!(json2.as_deref(), Some(json.as_str()));
        assert_eq!(&render_settings(&words, Some(&json)), s);

        // A projection drops what only compositing uses; no shading drops the lighting.
        state.blend = BlendMode::Mip;
        let out = r.reproduce(&state).unwrap();
        assert!(out.command.contains("--blend mip"));
        assert!(!out.command.contains("--gradient-opacity") && !out.command.contains("--specular"));
        assert_eq!(out.tf_file, None);
        state.blend = BlendMode::Iso;
        state.iso = Some(0.25);
        state.shading = false;
        let out = r.reproduce(&state).unwrap();
        assert!(
            out.command.contains("--blend iso --iso 0.25"),
            "{}",
            out.command
        );
        assert!(out.command.contains("--no-shading") && !out.command.contains("--specular"));
        assert_eq!(out.settings.iso.unwrap().value, 0.25);
    }

    #[test]
    fn the_starting_depth_cues_are_in_the_command_where_they_apply() {
        let (r, start) = reproduce(&["--shadows", "--ambient-occlusion", "5"]);
        let out = r.reproduce(&start).unwrap();
        assert!(
            out.command.contains("--shadows --ambient-occlusion 5"),
            "{}",
            out.command
        );
        assert!(out.settings.shadows);
        assert_eq!(out.settings.ambient_occlusion, Some(5.0));
        // Unlit: no light to shadow, but the ambient light is still occluded.
        let mut state = start.clone();
        state.shading = false;
        let out = r.reproduce(&state).unwrap();
        assert!(!out.settings.shadows, "{}", out.command);
        assert_eq!(out.settings.ambient_occlusion, Some(5.0));
        // A projection drops both.
        state.blend = BlendMode::Mip;
        let out = r.reproduce(&state).unwrap();
        assert!(!out.command.contains("--shadows") && !out.command.contains("--ambient-occlusion"));
        assert_eq!(out.settings.ambient_occlusion, None);
    }

    #[test]
    fn crop_clip_and_lighting_from_the_page_are_the_commands() {
        let (r, start) = reproduce(&["--crop", "-1,1,-1,1,-1,1", "--light-color", "1,0.9,0.8"]);
        assert_eq!(start.crop, Some([[-1.0; 3], [1.0; 3]]), "the flags' crop");
        let mut state = start.clone();
        state.crop = Some([[-0.5, -1.0, -1.0], [1.0, 0.25, 1.0]]);
        state.clip = vec![[[0.0, 0.0, 0.125], [0.0, 0.0, -1.0]]];
        state.lighting = Some(volray_view::Lighting {
            ambient: 0.25,
            diffuse: 0.5,
            specular: 0.75,
            shininess: 40.0,
            light: Some([1.0, 0.0, 0.0]),
        });
        let out = r.reproduce(&state).unwrap();
        for part in [
            "--clip 0,0,0.125,0,0,-1",
            "--crop -0.5,1,-1,0.25,-1,1",
            "--ambient 0.25 --diffuse 0.5 --specular 0.75 --shininess 40 --light 1,0,0 --light-color 1,0.9,0.8",
        ] {
            assert!(out.command.contains(part), "{part}: {}", out.command);
        }
        let (words, json) = r.words(&state).unwrap();
        let s = render_settings(&words, json.as_deref());
        assert_eq!(s, out.settings);
        assert_eq!(s.phong.diffuse, [0.5; 3]);
        assert_eq!(s.phong.shininess, 40.0);
        assert_eq!(s.light_direction, Some(DVec3::X));
        // No shading: no lighting words, whatever the state sets.
        state.shading = false;
        let out = r.reproduce(&state).unwrap();
        assert!(!out.command.contains("--ambient") && !out.command.contains("--light"));
    }

    #[test]
    fn log_windows_are_written_in_the_data_units() {
        let (r, mut state) = reproduce(&["--log", "--range", "0.01,1"]);
        let out = r.reproduce(&state).unwrap();
        assert!(
            out.command.contains("--log --range 0.01,1"),
            "{}",
            out.command
        );
        state.window = Some([-1.0, 0.0]);
        let out = r.reproduce(&state).unwrap();
        assert!(out.command.contains("--range 0.1,1 "), "{}", out.command);
        assert_eq!(out.settings.transfer_function.domain, Some((-1.0, 0.0)));
        state.window = Some([-1.0, 400.0]);
        assert!(r.reproduce(&state).unwrap_err().0.contains("beyond"));
    }

    #[test]
    fn starting_functions_are_carried_in_the_file() {
        let (r, state) = reproduce(&["--preset", "electron-density"]);
        assert_eq!(state.colormap, START_COLOURS);
        let out = r.reproduce(&state).unwrap();
        let (_, json) = out.tf_file.unwrap();
        let tf = TransferFunction::from_json(&json).unwrap();
        let preset = volray_core::transfer::presets::preset("electron-density").unwrap();
        assert_eq!(tf.opacity, preset.opacity);
        assert_eq!(tf.color, preset.color);
        assert_eq!(out.settings.transfer_function.opacity, preset.opacity);
    }

    #[test]
    fn refusals_are_one_line_messages() {
        let (r, mut state) = reproduce(&[]);
        state.colormap = START_COLOURS.into();
        assert!(
            r.reproduce(&state)
                .unwrap_err()
                .0
                .contains("pick a colour map")
        );
        let (r, mut state) = reproduce(&["--max-memory", "1M"]);
        state.width = 4096;
        state.height = 4096;
        let e = r.reproduce(&state).unwrap_err().0;
        assert!(
            e.contains("4096x4096 frame may take up to")
                && e.contains("more than --max-memory 1 MiB"),
            "{e}"
        );
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
