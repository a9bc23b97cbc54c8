//! What every rendering command does around the renderer: reading the
//! input (with `--log`, through volray-app's `input`), building the
//! renderer (after the `--max-memory` check of volray-app's `memory`),
//! the worker threads, the progress bar and the note after a frame in
//! pieces, and saying which flag a render error is about. `render.rs`,
//! `animate.rs`, `bench.rs` and `paper.rs` share these.

use crate::error::CliError;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::Path;
use volray_app::AppError;
use volray_app::input::Input;
use volray_app::memory::png_bytes;
use volray_app::plan::{Chosen, Frames, Plan, StreamedInput};
use volray_core::{RenderError, RenderSettings, Renderer};
use volray_distributed::frame::FrameError;
use volray_distributed::streamed::{StreamError, StreamTimes};
use volray_flags::{InputArgs, ViewArgs};
use volray_io::format_bytes;

/// Reads the volume `args` name and, with `--log`, takes its log10.
pub fn load(args: &InputArgs, log: bool) -> Result<Input, CliError> {
    let input = volray_app::input::load_log(&args.request(), log)?;
    // How axes in different units were stretched for drawing.
    if let Some(note) = &input.display_note {
        eprintln!("volray: {}: {note}", input.name);
    }
    Ok(input)
}

/// volray-app's error as the CLI's, a render error naming its flag.
pub fn app_failure(view: &ViewArgs, e: AppError) -> CliError {
    app_failure_of(view, &e)
}

/// [`app_failure`] of an error kept (a rank's, told to the others).
pub fn app_failure_of(view: &ViewArgs, e: &AppError) -> CliError {
    match e {
        AppError::Render { name, error }
        | AppError::Stream {
            name,
            error: StreamError::Render(error),
        }
        | AppError::Frame {
            name,
            error: FrameError::Render(error),
        } => render_failure(view, name, error.clone()),
        AppError::Option(e) => crate::settings::refused(e.clone()),
        e => crate::error::word(e),
    }
}

/// How INPUT is rendered for frames of `settings` (volray-app's `plan`):
/// whole, or a chunked file's level in pieces; `--level auto` says what
/// it chose.
pub fn plan(
    args: &InputArgs,
    view: &ViewArgs,
    settings: &RenderSettings,
) -> Result<Plan, CliError> {
    let request = args.request();
    let frames = Frames {
        settings,
        non_finite: view.sampling.nonfinite.into(),
        log: view.look.log,
        labels: view.look.labels,
        // A 16-bit PNG quantises the frame first.
        extra: png_bytes(settings),
    };
    let spec = request.spec.name();
    let plan = volray_app::plan::plan(&request, &frames, &mut |c| say_chosen(&spec, c))
        .map_err(|e| app_failure(view, e))?;
    // How axes in different units were stretched for drawing.
    if let Plan::Streamed(s) = &plan
        && let Some(note) = &s.display_note
    {
        eprintln!("volray: {}: {note}", s.name);
    }
    Ok(plan)
}

/// The line `--level auto` prints as it chooses.
pub fn say_chosen(spec: &str, chosen: Chosen) {
    let [x, y, z] = chosen.dims;
    eprintln!(
        "volray: {}: level {} of {} ({x}x{y}x{z}), the coarsest whose voxels are no larger than a pixel (--level auto, the default for a multiscale image; --level 0 is the finest)",
        Path::new(spec).display(),
        chosen.level,
        chosen.levels
    );
}

/// The line that says how a frame was rendered in pieces.
pub fn streamed_note(s: &StreamedInput, times: &StreamTimes) -> String {
    let [x, y, z] = s.streamed.grid().dims;
    // What the level's frame went over: --max-memory, or one piece's
    // budget beneath it.
    let limit = format_bytes(u128::from(s.max_memory));
    let bound = if s.over_piece_budget() {
        let piece = format_bytes(u128::from(volray_lazy::PIECE_BUDGET));
        format!("a piece's {piece} (under --max-memory {limit})")
    } else {
        format!("--max-memory {limit}")
    };
    format!(
        "volray: {}: level {} ({x}x{y}x{z}) rendered in pieces, as it may take up to {} whole, over {}: {} of {} pieces read ({} voxels), {:.2} s reading, {:.2} s rendering",
        Path::new(&s.name).display(),
        s.level,
        format_bytes(s.whole),
        bound,
        times.read_pieces,
        times.pieces,
        times.read_voxels,
        times.read.as_secs_f64(),
        times.render.as_secs_f64()
    )
}

/// A progress bar on a terminal for work of at least 256² pixels, else a
/// hidden one.
pub fn progress_bar(pixels: u64) -> ProgressBar {
    if std::io::stderr().is_terminal() && pixels >= 256 * 256 {
        let bar = ProgressBar::new(pixels);
        bar.set_style(
            ProgressStyle::with_template("{spinner} rendering [{bar:40}] {percent}% ({eta} left)")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    }
}

/// The renderer of `input`'s volume (volray-app's `renderer`), refused
/// if rendering it may need more than `--max-memory`, or for its
/// non-finite values as `--nonfinite` says: one line naming the input
/// and the count, and the way out.
pub fn renderer_for<'v>(
    view: &ViewArgs,
    settings: &RenderSettings,
    input: &'v Input,
) -> Result<Renderer<'v>, CliError> {
    volray_app::renderer::renderer_for(input, settings, view.sampling.nonfinite.into())
        .map_err(|e| renderer_failure(view, e))
}

/// volray-app's refusal of a renderer worded with the flags: non-finite
/// values name `--nonfinite`.
pub fn renderer_failure(view: &ViewArgs, e: AppError) -> CliError {
    match e {
        AppError::Render {
            name,
            error: e @ RenderError::NonFinite { .. },
        } => CliError::input(format!(
            "{name}: {e}; use --nonfinite transparent to render them as empty space"
        )),
        e => app_failure(view, e),
    }
}

/// The brick caches' budget for rendering `input` with `settings`,
/// non-finite values as `--nonfinite` says (volray-app's `renderer`).
pub fn cache_budget(
    view: &ViewArgs,
    settings: &RenderSettings,
    input: &Input,
) -> Result<usize, CliError> {
    let non_finite = view.sampling.nonfinite.into();
    Ok(volray_app::renderer::cache_budget(
        input, settings, non_finite,
    )?)
}

/// A failure to render `name` as one line, naming the flag whose value
/// caused it: the core's errors say which setting, by variant.
pub fn render_failure(view: &ViewArgs, name: &str, e: RenderError) -> CliError {
    if let RenderError::SamplesChanged(_) = e {
        // The file, not the flags: an I/O failure.
        return CliError::io(format!("{name}: {e}"));
    }
    match flag_of(view, &e) {
        Some(flag) => CliError::input(format!("{name}: {flag}: {e}")),
        None => CliError::input(format!("{name}: {e}")),
    }
}

/// The flag whose value a core error is about, if one is.
fn flag_of(view: &ViewArgs, e: &RenderError) -> Option<String> {
    let camera = volray_flags::camera(&view.camera);
    volray_options::option_of(e, &camera)
        .map(|opt| volray_options::Naming::option(&volray_flags::Flags, opt))
}

/// A pool of `threads` workers (default: one per core).
pub fn thread_pool(threads: Option<u16>) -> Result<rayon::ThreadPool, CliError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n as usize);
    }
    builder
        .build()
        .map_err(|e| CliError::io(format!("cannot start worker threads: {e}")))
}

/// With `--tf auto` and no window, `input`'s volume as its log10 where
/// its values span decades (volray-app's `auto_log`), said on stderr.
pub fn auto_log(
    view: &ViewArgs,
    settings: &RenderSettings,
    input: &mut volray_app::input::Input,
) -> Result<(), CliError> {
    let look = volray_flags::look(&view.look);
    let note = volray_app::input::auto_log(&look, &settings.transfer_function, input, "--linear")?;
    if let Some(note) = note {
        eprintln!("volray: {note}");
    }
    Ok(())
}
