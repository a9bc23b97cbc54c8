//! `volray view`: serve a volume to a web browser (`volray-view`). Reads
//! INPUT and the starting `--tf` file once (the page cannot name files),
//! checks the starting view as `render` would, prints the page's URL with
//! its access token as the first line on standard output, opens a browser
//! where there is a display, and serves until Ctrl-C or SIGTERM, then
//! exits 0.
//!
//! `view/reproduce.rs` turns the page's states into `volray render`
//! commands (volray-app's words) and their settings; `view/browser.rs` opens the browser.

mod browser;
mod levels;
mod reproduce;
mod scene;

use crate::error::CliError;
use crate::flags::ViewerArgs;
use crate::session::{load, renderer_for, thread_pool};
use crate::settings::{from_volume, named_transfer_function, read_tf_file, settings_with_tf_text};
use reproduce::CliReproduce;
use std::net::SocketAddr;
use std::sync::Arc;
use volray_core::RenderSettings;
use volray_view::{Reproduce, Start, ViewState, Viewer};

/// The most tabs rendering at once, whatever the memory allows (the
/// memory itself is held to `--max-memory` by the viewer's ledger:
/// the volume, each tab's renderer, each frame in flight).
const MAX_TABS: usize = 8;

pub fn run(args: &ViewerArgs) -> Result<(), CliError> {
    if args.scene.is_scene() || args.scene.frames.is_some() {
        return scene::run(args);
    }
    let look = &args.view.look;
    let tf_text = look.tf_file().map(read_tf_file).transpose()?;
    let mut settings = settings_with_tf_text(&args.view, tf_text.as_deref())?;
    let mut named = named_transfer_function(look, tf_text.as_deref())?;
    // A chunked file is opened from its metadata, and only the level the
    // first drafts show is read (`view/levels.rs`).
    let pyramid = levels::open(args, &settings)?;
    let mut input = match &pyramid {
        Some(p) => p.start_input(args)?,
        None => load(&args.input, look.log)?,
    };
    // A transfer function chosen from the volume (`--tf auto`, `--labels`)
    // is the page's starting one, and its commands name it in full.
    from_volume(
        look,
        &mut settings.transfer_function,
        &mut input.volume,
        &input.name,
    )?;
    if look.labels && look.tf_file().is_none() {
        named = settings.transfer_function.clone();
    } else if look.auto_tf() {
        // The same points: `t` is relative to the window, whatever its units.
        named.opacity = settings.transfer_function.opacity.clone();
        named.color = settings.transfer_function.color.clone();
    }
    // The checks `render` makes: memory, non-finite values, the view.
    let renderer = renderer_for(&args.view, &settings, &input)?;
    renderer
        .prepare(&settings)
        .map_err(|e| crate::session::render_failure(&args.view, &input.name, e))?;
    drop(renderer);
    let cache_budget = crate::session::cache_budget(&args.view, &settings, &input)?;
    let non_finite = input.non_finite(args.view.sampling.nonfinite.into());

    let state = start_state(args, &settings);
    state.check().map_err(|e| {
        CliError::input(format!(
            "the starting view is beyond the viewer's bounds: {e}"
        ))
    })?;
    let volume = &input.volume;
    let grid = match &pyramid {
        // The frames' memory is checked against the level each renders.
        Some(p) => p.coarsest_grid(),
        None => (volume.dims(), volume.spacing(), volume.sample_type()),
    };
    let reproduce = CliReproduce::new(args, named, grid, non_finite, input.max_memory)
        .with_level(levels::level_word(args, pyramid.as_ref()));
    reproduce
        .reproduce(&state)
        .map_err(|e| CliError::input(format!("{}: {e}", input.name)))?;
    let mut hello = Start {
        name: &input.name,
        volume,
        log: look.log,
        state: &state,
        settings: &settings,
        others: Vec::new(),
        time: None,
    }
    .hello();
    if let Some(p) = &pyramid {
        p.describe(&mut hello);
    }
    hello.fit = args.view.camera.size.is_none();
    let pool = thread_pool(args.view.threads)?;
    let labels = input.volume.is_labels();
    let figure = figure_context(args, &input);
    let viewer = Viewer {
        volume: Arc::new(input.volume),
        non_finite,
        cache_budget,
        max_memory: u128::from(input.max_memory),
        hello,
        reproduce: Arc::new(reproduce),
        pool: Arc::new(pool),
        max_sessions: MAX_TABS,
        levels: pyramid.map(|p| p.into_levels(labels)),
        others: Vec::new(),
        time: None,
        figure,
    };
    serve(args, viewer)
}

/// Serves `viewer` as `args` say until Ctrl-C or SIGTERM.
fn serve(args: &ViewerArgs, viewer: Viewer) -> Result<(), CliError> {
    let addr = SocketAddr::new(args.bind, args.port);
    let server = viewer.bind(addr).map_err(|e| CliError::io(e.to_string()))?;
    let url = server
        .url()
        .map_err(|e| CliError::io(format!("cannot read the bound address: {e}")))?;
    outln!("{url}");
    if !args.bind.is_loopback() {
        eprintln!(
            "volray: warning: listening on {}, reachable from other machines by anyone with the URL; prefer the default 127.0.0.1 with an SSH tunnel (ssh -L)",
            args.bind
        );
    }
    // The redirect page the browser was given stays until the viewer stops.
    let _redirect = if args.no_browser {
        None
    } else {
        browser::open(&url)
    };
    let stopper = server.stopper();
    crate::interrupt::stop_instead(move || stopper.stop());
    server.run().map_err(|e| CliError::io(e.to_string()))
}

/// The page's starting state: the view the flags describe (as
/// `volray.view` starts from its keywords, [`volray_view::start_state`]),
/// with the figure the flags ask for.
pub fn start_state(args: &ViewerArgs, settings: &RenderSettings) -> ViewState {
    let options = volray_options::Options {
        camera: crate::settings::camera(&args.view.camera),
        look: crate::settings::look(&args.view.look),
        ..Default::default()
    };
    ViewState {
        figure: figure_state(&args.figure),
        ..volray_view::start_state(&options, settings)
    }
}

/// The page's figure as the flags start it.
fn figure_state(args: &crate::flags::FigureArgs) -> volray_view::Figure {
    use crate::flags::{ColorBarSide as Flag, ScaleLength};
    volray_view::Figure {
        colorbar: args.colorbar.map(|side| match side {
            Flag::Right => volray_view::ColorBarSide::Right,
            Flag::Left => volray_view::ColorBarSide::Left,
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

/// What the frames' annotations need of `input`, as `volray render`
/// takes it (`figure.rs`).
pub fn figure_context(
    args: &ViewerArgs,
    input: &volray_app::input::Input,
) -> volray_view::FigureContext {
    let look = &args.view.look;
    volray_view::FigureContext {
        log: look.log,
        value_unit: volray_annotate::figure::preset_unit(look.preset.as_deref()).map(String::from),
        length_unit: (input.file.as_ref()).and_then(|(_, info)| info.length_unit.clone()),
        axis_names: crate::figure::axis_names(input).map(String::from),
    }
}
