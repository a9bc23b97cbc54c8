//! The page's state as a `volray render` command, and the settings of
//! that command: `volray view`'s [`Reproduce`].
//!
//! volray-app spells a state as the words of the command
//! (`render INPUT --azimuth 30 ... -o view.png`, its
//! `reproduce::command`); here the words are parsed by the same clap
//! parser and turned into settings by the same `settings.rs` as a real
//! `volray render`, with the transfer-function file's text handed over
//! instead of read. The frame the page shows is therefore the command's
//! frame, pixel for pixel, by construction (and `tests/view_browser.rs`
//! runs the command to check).

use crate::{Cli, Command, Flags, InputArgs, ViewerArgs};
use clap::Parser;
use volray_app::input;
pub use volray_app::reproduce::command::SceneWords;
use volray_app::reproduce::command::{CommandWords, TF_FILE, Words, shell_quote, v3};
use volray_app::reproduce::state::ViewState;
use volray_app::reproduce::viewer::{Refusal, Reproduce, Reproduction, SceneLooks};
use volray_app::scene::OverlaySpec;
use volray_core::RenderSettings;
use volray_core::glam::DVec3;
use volray_core::scene::{Look, Mix};
use volray_core::{NonFinite, SampleType, TransferFunction};

/// `volray view`'s flags, kept as the words of the command lines it
/// writes, and what the memory check of each command's frame needs.
pub struct CliReproduce {
    words: CommandWords,
    /// The volume's grid and sample type, how its non-finite values are
    /// rendered, and the memory limit, for the memory check.
    grid: ([usize; 3], DVec3, SampleType),
    non_finite: NonFinite,
    max_memory: u64,
}

impl CliReproduce {
    /// The command lines of a `volray view` started with `args`, whose
    /// transfer function (`--tf`, `--preset`, `--colormap`, `--range`) is
    /// `start`, for a volume of `grid` (dims, spacing, sample type) whose
    /// non-finite values are rendered as `non_finite` says; `auto_log`
    /// where `--tf auto` took the log10 of the volume (volray-app's
    /// `input::auto_log`): its commands then say `--log`, as the page
    /// shows log units.
    pub fn new(
        args: &ViewerArgs,
        start: TransferFunction,
        grid: ([usize; 3], DVec3, SampleType),
        non_finite: NonFinite,
        (max_memory, auto_log): (u64, bool),
    ) -> Self {
        let mut look = crate::look(&args.view.look);
        look.log |= auto_log;
        let options = volray_options::Options {
            camera: crate::camera(&args.view.camera),
            look,
            sampling: crate::sampling(&args.view.sampling),
        };
        let input = args.input.input.as_deref().unwrap_or(input::DEMO);
        let reading = reading(&args.input);
        CliReproduce {
            words: CommandWords::new(input.to_string(), reading, &options, start),
            grid,
            non_finite,
            max_memory,
        }
    }

    /// The same, for a scene whose other volumes `scene` describes.
    pub fn with_scene(mut self, scene: SceneWords) -> Self {
        self.words = self.words.with_scene(scene);
        self
    }

    /// The same, for a viewer of a time axis: the state's time point is
    /// the command's `--frame`.
    pub fn with_time(mut self) -> Self {
        self.words = self.words.with_time();
        self
    }

    /// The same, its commands reading the level `level` names (`auto` or
    /// a number), if any: a multiscale volume's.
    pub fn with_level(mut self, level: Option<String>) -> Self {
        self.words = self.words.with_level(level);
        self
    }

    /// The arguments of the `volray render` command of `state` (after
    /// `volray`), and the transfer-function file's JSON if it names one.
    #[cfg(test)]
    pub fn words(&self, state: &ViewState) -> Result<(Vec<String>, Option<String>), Refusal> {
        self.words
            .words(state)
            .map(|(words, json, _)| (words, json))
    }

    /// The looks of a scene's other volumes as `render` makes them of the
    /// command's words: `--overlay`s with their files' texts.
    fn scene_looks(
        &self,
        args: &crate::RenderArgs,
        files: Vec<(String, String)>,
    ) -> Result<Option<SceneLooks>, Refusal> {
        let Some(scene) = self.words.scene() else {
            return Ok(None);
        };
        let specs = (args.scene.overlay.iter())
            .map(|spec| OverlaySpec::parse(spec).map_err(|e| Refusal(e.0)))
            .collect::<Result<Vec<_>, _>>()?;
        let mut looks = Vec::with_capacity(specs.len());
        for (spec, other) in specs.iter().zip(&scene.others) {
            let look = if spec.labels {
                other.start_look.clone()
            } else {
                let text = (files.iter())
                    .find(|(name, _)| Some(name) == spec.tf.as_ref())
                    .map(|(_, text)| text.as_str());
                let shared = crate::options(&args.view, Some(""));
                let (_, settings) = spec.settings(shared, text).map_err(|e| Refusal(e.0))?;
                Look::of(&settings)
            };
            looks.push(Look {
                visible: !spec.hidden,
                ..look
            });
        }
        let mix = match args.scene.mix {
            Some(crate::MixMode::Additive) => Mix::Additive,
            _ => Mix::Composite,
        };
        Ok(Some(SceneLooks {
            looks,
            mix,
            tf_files: files,
        }))
    }
}

impl Reproduce for CliReproduce {
    fn reproduce(&self, state: &ViewState) -> Result<Reproduction, Refusal> {
        let (words, json, files) = self.words.words(state)?;
        let argv = std::iter::once("volray").chain(words.iter().map(String::as_str));
        let cli = Cli::try_parse_from(argv).map_err(|e| Refusal(crate::one_line_error(&e)))?;
        let Command::Render(args) = cli.command else {
            unreachable!("the words start with render")
        };
        let settings = settings_with_tf_text(&args.view, json.as_deref())?;
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

/// The render settings the view arguments give with the `--tf` file's
/// text, refused in the flags' words (as `volray render` would refuse
/// them).
pub fn settings_with_tf_text(
    view: &crate::ViewArgs,
    tf_text: Option<&str>,
) -> Result<RenderSettings, Refusal> {
    volray_options::settings(&crate::options(view, tf_text)).map_err(|e| Refusal(e.message(&Flags)))
}

/// The page's starting state: the view the flags describe (as
/// `volray.view` starts from its keywords, volray-app's `start_state`),
/// with the figure the flags ask for.
pub fn start_state(args: &ViewerArgs, settings: &RenderSettings) -> ViewState {
    let options = volray_options::Options {
        camera: crate::camera(&args.view.camera),
        look: crate::look(&args.view.look),
        ..Default::default()
    };
    ViewState {
        figure: figure_state(&args.figure),
        ..volray_app::reproduce::options::start_state(&options, settings)
    }
}

/// The page's figure as the flags start it.
fn figure_state(args: &crate::FigureArgs) -> volray_app::reproduce::state::Figure {
    use crate::{ColorBarSide as Flag, ScaleLength};
    volray_app::reproduce::state::Figure {
        colorbar: args.colorbar.map(|side| match side {
            Flag::Right => volray_app::reproduce::state::ColorBarSide::Right,
            Flag::Left => volray_app::reproduce::state::ColorBarSide::Left,
        }),
        scale_bar: args.scale_bar.is_some(),
        scale_length: match args.scale_bar {
            Some(ScaleLength::Given(l)) => Some(l),
            _ => None,
        },
        axes: args.axes,
        outline: args.outline,
        title: args.title.clone(),
        label: args.label.clone(),
    }
}

/// INPUT's reading flags, as given.
fn reading(inp: &InputArgs) -> Vec<String> {
    let mut reading = Words::default();
    reading.opt("--dims", inp.dims.map(|[x, y, z]| format!("{x},{y},{z}")));
    reading.opt("--dtype", inp.dtype.clone());
    reading.opt("--endian", inp.endian.clone());
    reading.opt("--spacing", inp.spacing.map(v3));
    reading.opt("--scale", inp.scale.map(v3));
    reading.opt("--format", inp.format.clone());
    reading.opt("--frame", inp.frame.map(|f| f.to_string()));
    reading.opt("--series", inp.series.clone());
    reading.opt("--array", inp.array.clone());
    reading.opt("--channel", inp.channel.map(|c| c.to_string()));
    reading.opt("--max-memory", inp.max_memory.map(|m| m.to_string()));
    reading.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_app::reproduce::state::{BlendMode, START_COLOURS, WHITE};

    fn named_transfer_function(
        look: &crate::LookArgs,
        _tf_text: Option<&str>,
    ) -> Result<TransferFunction, volray_options::OptionError> {
        volray_options::named_transfer_function(&crate::look(look))
    }

    fn settings(view: &crate::ViewArgs) -> Result<RenderSettings, Refusal> {
        settings_with_tf_text(view, None)
    }

    fn viewer(extra: &[&str]) -> ViewerArgs {
        let argv = [&["volray", "view", "blobs:16"][..], extra].concat();
        match Cli::try_parse_from(argv).unwrap().command {
            Command::View(args) => args,
            _ => unreachable!(),
        }
    }

    fn reproduce(extra: &[&str]) -> (CliReproduce, ViewState) {
        reproduce_logged(extra, false)
    }

    /// [`reproduce`], the volume's log10 taken by `--tf auto` or not.
    fn reproduce_logged(extra: &[&str], auto_log: bool) -> (CliReproduce, ViewState) {
        let args = viewer(extra);
        let start = named_transfer_function(&args.view.look, None).unwrap();
        let settings = settings(&args.view).unwrap();
        let state = start_state(&args, &settings);
        let max_memory = args.input.max_memory.unwrap_or(1 << 30);
        let grid = ([16; 3], DVec3::ONE, SampleType::F32);
        let r = CliReproduce::new(
            &args,
            start,
            grid,
            NonFinite::Refuse,
            (max_memory, auto_log),
        );
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
        state.figure.colorbar = Some(volray_app::reproduce::state::ColorBarSide::Right);
        let (words, _) = r.words(&state).unwrap();
        assert!(
            words.windows(2).any(|w| w == ["--units", "HU"]),
            "{words:?}"
        );
        assert!(!words.iter().any(|w| w == "--preset"), "{words:?}");
        // Without a CT preset, render would say no unit either.
        let (r, mut state) = reproduce(&["--colormap", "magma"]);
        state.figure.colorbar = Some(volray_app::reproduce::state::ColorBarSide::Right);
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
        state.lighting = Some(volray_app::reproduce::state::Lighting {
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
    fn the_command_keeps_the_scale_it_was_started_with() {
        let (r, state) = reproduce(&["--scale", "1,1,0.5"]);
        let command = r.reproduce(&state).unwrap().command;
        assert!(command.contains(" --scale 1,1,0.5"), "{command}");
        let (r, state) = reproduce(&[]);
        assert!(!r.reproduce(&state).unwrap().command.contains("--scale"));
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
    fn a_volume_whose_log_tf_auto_took_is_reproduced_with_log() {
        let (r, state) = reproduce_logged(&[], true);
        let out = r.reproduce(&state).unwrap();
        assert!(out.command.contains(" --log"), "{}", out.command);
        let (r, state) = reproduce_logged(&[], false);
        let out = r.reproduce(&state).unwrap();
        assert!(!out.command.contains("--log"), "{}", out.command);
    }
}
