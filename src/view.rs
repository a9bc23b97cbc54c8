//! `volray view`: serve a volume to a web browser (`volray-view`). Reads
//! INPUT and the starting `--tf` file once (the page cannot name files),
//! checks the starting view as `render` would, prints the page's URL with
//! its access token as the first line on standard output, opens a browser
//! where there is a display, and serves until Ctrl-C or SIGTERM, then
//! exits 0.
//!
//! volray-flags' `reproduce` turns the page's states into `volray render`
//! commands (volray-app's words) and their settings; `view/browser.rs` opens the browser.

mod browser;
mod scene;

use crate::error::CliError;
use crate::session::{load, renderer_for, thread_pool};
use crate::settings::{named_transfer_function, read_tf_file, settings_with_tf_text};
use std::net::SocketAddr;
use std::path::Path;
use std::sync::Arc;
use volray_app::input::{self, Input};
use volray_core::RenderSettings;
use volray_flags::ViewerArgs;
use volray_flags::reproduce::{CliReproduce, start_state};
use volray_io::format_bytes;
use volray_options::level::LevelChoice;
use volray_view::DRAFT_SHARE;
use volray_view::launch::Launch;
use volray_view::open::{OpenError, Opened};

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
    // first drafts show is read (volray-view's `open`).
    let pyramid = open_levels(args, &settings)?;
    let mut input = match &pyramid {
        Some(p) => Input {
            volume: p.start_volume()?,
            name: args
                .input
                .input
                .as_deref()
                .unwrap_or(input::DEMO)
                .to_string(),
            file: None,
            max_memory: args.input.request().max_memory(),
            display_note: None,
            auto_log: false,
        },
        None => load(&args.input, look.log)?,
    };
    // `--tf auto`'s log window of values spanning decades, for a volume
    // read whole (levels read as the frames need them keep their values).
    if pyramid.is_none() {
        let look = volray_flags::look(look);
        let tf = &settings.transfer_function;
        if let Some(note) = volray_app::input::auto_log(&look, tf, &mut input, "--linear")? {
            eprintln!("volray: {note}");
        }
    }
    // What the look leaves to the volume, as `render` leaves it (volray-
    // app's `look`: a CT's look, the file's display window, `--labels` in
    // the colours the file gives them, `--tf auto`), is the page's
    // starting transfer function, and its commands name it in full.
    let tf = &mut settings.transfer_function;
    let ct = volray_app::look::leave_to_volume(&volray_flags::look(look), tf, &mut input)
        .map_err(crate::settings::refused)?;
    if let Some(note) = ct {
        eprintln!("volray: {}: {note}", input.name);
        named = settings.transfer_function.clone();
    } else if look.labels && look.tf_file().is_none() {
        named = settings.transfer_function.clone();
    } else if look.auto_tf() {
        // The same points: `t` is relative to the window, whatever its units.
        named.opacity = settings.transfer_function.opacity.clone();
        named.color = settings.transfer_function.color.clone();
        // The window the histogram was refined to, where none was given.
        named.domain = named.domain.or(settings.transfer_function.domain);
    }
    // The checks `render` makes: memory, non-finite values, the view.
    let renderer = renderer_for(&args.view, &settings, &input)?;
    renderer
        .prepare(&settings)
        .map_err(|e| crate::session::render_failure(&args.view, &input.name, e))?;
    drop(renderer);
    let non_finite = input.non_finite(args.view.sampling.nonfinite.into());
    let volume = &input.volume;
    let grid = match &pyramid {
        // The frames' memory is checked against the level each renders.
        Some(p) => p.coarsest_grid(),
        None => (volume.dims(), volume.spacing(), volume.sample_type()),
    };
    let limits = (input.max_memory, input.auto_log);
    let reproduce = CliReproduce::new(args, named, grid, non_finite, limits)
        .with_level(level_word(args, pyramid.as_ref()));
    let mut launch = launch(args, input, settings, reproduce)?;
    launch.levels = pyramid;
    serve(args, launch)
}

/// The viewer of `input` with `settings` as the flags start it, its
/// commands `reproduce`'s: one volume, no time axis, no levels, the
/// starting state the flags'.
fn launch(
    args: &ViewerArgs,
    input: Input,
    settings: RenderSettings,
    reproduce: CliReproduce,
) -> Result<Launch, CliError> {
    let cache_budget = crate::session::cache_budget(&args.view, &settings, &input)?;
    let non_finite = input.non_finite(args.view.sampling.nonfinite.into());
    let figure = figure_context(args, &input);
    Ok(Launch {
        name: input.name,
        log: args.view.look.log || input.auto_log,
        volume: input.volume,
        state: start_state(args, &settings),
        settings,
        others: Vec::new(),
        time: None,
        levels: None,
        fit: args.view.camera.size.is_none(),
        non_finite,
        cache_budget,
        max_memory: u128::from(input.max_memory),
        reproduce: Arc::new(reproduce),
        pool: thread_pool(args.view.threads)?,
        max_sessions: MAX_TABS,
        figure,
    })
}

/// Serves `launch` as `args` say until Ctrl-C or SIGTERM.
fn serve(args: &ViewerArgs, launch: Launch) -> Result<(), CliError> {
    let viewer = launch
        .viewer()
        .map_err(|e| CliError::input(e.to_string()))?;
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

/// What the frames' annotations need of `input`, as `volray render`
/// takes it (`figure.rs`).
pub fn figure_context(
    args: &ViewerArgs,
    input: &volray_app::input::Input,
) -> volray_view::FigureContext {
    let look = &args.view.look;
    volray_view::FigureContext {
        log: look.log || input.auto_log,
        value_unit: volray_annotate::figure::preset_unit(look.preset.as_deref()).map(String::from),
        length_unit: (input.file.as_ref()).and_then(|(_, info)| info.length_unit.clone()),
        axis_names: crate::figure::axis_names(input).map(String::from),
    }
}

/// Opens INPUT level by level (volray-view's `open`) when it is a chunked
/// file and neither `--log` nor `--spacing` is given (volray-view's
/// levels are not taken to log10 or respaced yet); `None` for any other
/// input, read whole. `settings` are the starting view's.
fn open_levels(args: &ViewerArgs, settings: &RenderSettings) -> Result<Option<Opened>, CliError> {
    let inp = &args.input;
    let spec = inp.input.as_deref().unwrap_or(input::DEMO);
    if volray_data::is_source_spec(spec) {
        return Ok(None);
    }
    if args.view.look.log || inp.spacing.is_some() {
        if inp.level == Some(LevelChoice::Auto) {
            return Err(CliError::input(format!(
                "{spec}: --level auto: the viewer reads a multiscale image's levels as its frames need them, but not yet with --log or --spacing: give a level number, 0 the finest"
            )));
        }
        return Ok(None);
    }
    let request = inp.request();
    let max_memory = request.max_memory();
    let Some(chunked) = volray_app::plan::open_chunked(&request, max_memory)? else {
        return Ok(None);
    };
    let fixed = request.fixed_level();
    let non_finite = args.view.sampling.nonfinite.into();
    let scale = request.scale;
    let opened = volray_view::open::open_levels(&chunked, fixed, settings, non_finite, max_memory.into(), scale)
        .map_err(|e| match e {
            OpenError::Read(e) => CliError::from(e),
            OpenError::CoarsestTooLarge { dims: [x, y, z], need, limit } => CliError::input(format!(
                "{spec}: its coarsest level ({x}x{y}x{z}) may take up to {} to render whole, more than the 1/{DRAFT_SHARE} of --max-memory {} the viewer gives the frames while the view moves: raise --max-memory",
                format_bytes(need),
                format_bytes(limit)
            )),
            e => CliError::input(format!("{spec}: {e}")),
        })?;
    let count = opened.pyramid.len();
    let [x, y, z] = opened.pyramid.grid(opened.start).dims;
    let when_still = match fixed {
        Some(n) => format!("level {n}"),
        None => format!(
            "the level each still needs (--level auto; {} for the start)",
            opened.still
        ),
    };
    eprintln!(
        "volray: {}: {count} level{}; the view shows level {} ({x}x{y}x{z}) while it moves, {when_still} when still",
        Path::new(spec).display(),
        if count == 1 { "" } else { "s" },
        opened.start
    );
    // How axes in different units are stretched for drawing.
    if let Some(note) = &opened.display_note {
        eprintln!("volray: {}: {note}", Path::new(spec).display());
    }
    Ok(Some(opened))
}

/// The `--level` word of the commands the page shows: the level the
/// stills show (`auto` for a multiscale image opened level by level
/// without `--level`), or the `--level N` given.
fn level_word(args: &ViewerArgs, opened: Option<&Opened>) -> Option<String> {
    match (args.input.level, opened) {
        (Some(LevelChoice::Index(n)), _) => Some(n.to_string()),
        (_, Some(o)) if o.pyramid.len() > 1 => Some("auto".to_string()),
        _ => None,
    }
}
