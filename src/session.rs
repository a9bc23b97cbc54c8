//! What every rendering command does around the renderer: reading the
//! input (with `--log`), building the renderer (after the `--max-memory`
//! check of `memory.rs`), the worker threads, the progress bar, and
//! saying which flag a render error is about. `render.rs`, `animate.rs`,
//! `bench.rs` and `paper.rs` share these.

use crate::error::CliError;
use crate::flags::{InputArgs, ViewArgs};
use crate::input::{self, Input};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use volray_core::{RenderError, RenderSettings, Renderer};

/// Reads the volume `args` name and, with `--log`, takes its log10.
pub fn load(args: &InputArgs, log: bool) -> Result<Input, CliError> {
    let mut input = input::load(args)?;
    if log {
        input.volume = input
            .volume
            .to_log10()
            .map_err(|e| CliError::input(format!("--log: {}: {e}", input.name)))?;
    }
    Ok(input)
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

/// The renderer of `input`'s volume, its non-finite values refused or
/// rendered as empty space as `--nonfinite` says, refused if rendering it
/// may need more than `--max-memory` (see `memory.rs`). A refusal is one
/// line naming the input and the count, and the way out.
pub fn renderer_for<'v>(
    view: &ViewArgs,
    settings: &RenderSettings,
    input: &'v Input,
) -> Result<Renderer<'v>, CliError> {
    let budget = crate::memory::cache_budget(view, settings, input)?;
    let (name, volume) = (&input.name, &input.volume);
    let mode = input.non_finite(view.sampling.nonfinite.into());
    let renderer = Renderer::with_non_finite(volume, mode).map_err(|e| match e {
        RenderError::NonFinite { .. } => CliError::input(format!(
            "{name}: {e}; use --nonfinite transparent to render them as empty space"
        )),
        e => render_failure(view, name, e),
    })?;
    Ok(renderer.with_cache_budget(budget))
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
    let camera = crate::settings::camera(&view.camera);
    volray_options::option_of(e, &camera)
        .map(|opt| volray_options::Naming::option(&crate::settings::Flags, opt))
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
