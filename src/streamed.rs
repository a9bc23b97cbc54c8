//! `volray render` of a chunked volume (Zarr, OME-Zarr): which level
//! (`--level auto`), and, where that level is too large to render whole
//! under `--max-memory`, rendering it piece by piece from its chunks
//! (volray-distributed's `Streamed`), never reading it whole.
//!
//! The order: the file is opened from its metadata alone; `--level auto`
//! picks the level for the picture (volray-options' `level`); the level's
//! frame is bounded as a whole volume's would be (`memory.rs`). Within
//! `--max-memory` it is read whole and rendered as any file is (the same
//! pixels as `--level N`); beyond it, or beyond one piece's
//! [`volray_lazy::PIECE_BUDGET`] (lighter and faster then), in pieces of at
//! most that each.

use crate::error::CliError;
use crate::flags::{InputArgs, ViewArgs};
use crate::input;
use crate::session::render_failure;
use std::path::{Path, PathBuf};
use volray_core::{FrameRequest, Image, NonFinite, Render, RenderSettings, Rendered};
use volray_distributed::streamed::{StreamError, StreamTimes, Streamed};
use volray_io::{MapPolicy, format_bytes};
use volray_lazy::{Chunked, Found, LookError, Plan as LazyPlan};
use volray_options::level::LevelChoice;

/// How INPUT is rendered.
pub enum Plan {
    /// Read whole (or mapped), as every file is: at this level, if any.
    Whole { level: Option<usize> },
    /// Rendered piece by piece from its chunks.
    Streamed(Box<StreamedInput>),
}

/// A chunked volume rendered piece by piece.
pub struct StreamedInput {
    pub name: String,
    pub streamed: Streamed,
    /// The labels or histogram found in the level, once.
    found: Found,
    /// The file's display window (OME-Zarr `omero`), the default `--range`.
    window: Option<(f64, f64)>,
    /// What the note after a frame says: the level, and why in pieces.
    level: usize,
    whole: u128,
    max_memory: u64,
}

/// Decides how INPUT is rendered for frames of `settings`: opens a
/// chunked file from its metadata, picks its level, and streams it when
/// that level's frame would not fit `--max-memory` whole. Other inputs
/// (built-in sources, formats read whole or mapped) are read whole.
pub fn plan(
    args: &InputArgs,
    view: &ViewArgs,
    settings: &RenderSettings,
) -> Result<Plan, CliError> {
    let spec = args.input.as_deref().unwrap_or(input::DEMO);
    let requested = args.level;
    if volray_data::is_source_spec(spec) {
        return Ok(Plan::Whole { level: None });
    }
    let max_memory = args
        .max_memory
        .unwrap_or_else(volray_io::default_max_memory);
    let Some(mut chunked) = open_chunked(args, spec, max_memory)? else {
        return Ok(Plan::Whole {
            level: fixed_level(args),
        });
    };
    if requested == Some(LevelChoice::Auto) {
        let chosen = chunked
            .auto_level(settings)
            .map_err(|e| CliError::input(format!("{spec}: {e}")))?;
        let levels = chunked.levels();
        let [x, y, z] = levels[chosen].dims;
        eprintln!(
            "volray: {}: level {chosen} of {} ({x}x{y}x{z}), the coarsest whose voxels are no larger than a pixel (--level auto)",
            display(spec),
            levels.len()
        );
        chunked = chunked.at_level(chosen)?;
    }
    let mode: NonFinite = view.sampling.nonfinite.into();
    // A 16-bit PNG quantises the frame first: 8 bytes a pixel (memory.rs).
    let png = 8 * settings.width as u128 * settings.height as u128;
    let plan = if view.look.log {
        // The log of the level, found piece by piece after a pass over it
        // for its smallest positive value.
        chunked
            .plan_log(settings, mode, max_memory, png)
            .map_err(|e| CliError::input(format!("--log: {spec}: {e}")))?
    } else {
        chunked.plan(settings, mode, max_memory, png)
    };
    match plan {
        LazyPlan::Whole { level, .. } => Ok(Plan::Whole { level: Some(level) }),
        LazyPlan::Pieces {
            level,
            need,
            streamed,
        } => Ok(Plan::Streamed(Box::new(StreamedInput {
            name: spec.to_string(),
            streamed: streamed.with_labels(view.look.labels),
            found: Found::default(),
            window: chunked.info().display_window(),
            level,
            whole: need,
            max_memory,
        }))),
    }
}

/// The level `--level N` names; `None` for `auto` or none.
pub fn fixed_level(args: &InputArgs) -> Option<usize> {
    match args.level {
        Some(LevelChoice::Index(n)) => Some(n),
        _ => None,
    }
}

/// Opens INPUT (`spec`) from its metadata where it is stored in chunks, at
/// the level `--level N` names (0 for `auto`, which the caller resolves);
/// `None` for a file read whole or mapped. `--level auto` on such a file
/// is refused: it has one level.
pub fn open_chunked(
    args: &InputArgs,
    spec: &str,
    max_memory: u64,
) -> Result<Option<Chunked>, CliError> {
    let path = PathBuf::from(spec);
    let numbered = InputArgs {
        level: fixed_level(args).map(LevelChoice::Index),
        ..args.clone()
    };
    let opts = input::read_options(&numbered, spec, &path, max_memory, MapPolicy::IfLarger)?;
    let chunked = Chunked::open(&path, &opts)?;
    if chunked.is_none() && args.level == Some(LevelChoice::Auto) {
        return Err(CliError::input(format!(
            "{spec}: --level auto applies to multiscale images (OME-Zarr); this file holds one level"
        )));
    }
    Ok(chunked)
}

/// The input flags reading INPUT whole at `level` (`--level auto`
/// resolved to a number).
pub fn at_level(args: &InputArgs, level: Option<usize>) -> InputArgs {
    InputArgs {
        // Unresolved (a built-in source): as given, for the reader to refuse.
        level: level.map(LevelChoice::Index).or(args.level),
        ..args.clone()
    }
}

fn display(spec: &str) -> String {
    Path::new(spec).display().to_string()
}

impl StreamedInput {
    /// `settings` with what the flags leave to the volume (`--labels`,
    /// `--tf auto`), found piece by piece (volray-lazy's [`Found`], which
    /// the Python module shares).
    pub fn settings_from_volume(
        &mut self,
        view: &ViewArgs,
        mut settings: RenderSettings,
    ) -> Result<RenderSettings, CliError> {
        let look = crate::settings::look(&view.look);
        let name = self.name.clone();
        crate::settings::file_window(&view.look, &mut settings.transfer_function, self.window);
        let found = self
            .found
            .apply(&mut self.streamed, &look, &mut settings, &name);
        match found {
            Ok(()) => Ok(settings),
            Err(LookError::Stream(e)) => Err(self.failure(view, e)),
            Err(LookError::Refused(e)) => Err(crate::settings::refused(e)),
        }
    }

    /// One frame.
    pub fn render(
        &mut self,
        view: &ViewArgs,
        settings: &RenderSettings,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<(Image, StreamTimes), CliError> {
        self.streamed
            .render(FrameRequest::new(settings).reporting(progress))
            .map(Rendered::image_and_times)
            .map_err(|e| self.failure(view, e))
    }

    /// The line that says how a frame was rendered.
    pub fn note(&self, times: &StreamTimes) -> String {
        let [x, y, z] = self.streamed.grid().dims;
        format!(
            "volray: {}: level {} ({x}x{y}x{z}) rendered in pieces, as it may take up to {} whole, over {}: {} of {} pieces read ({} voxels), {:.2} s reading, {:.2} s rendering",
            display(&self.name),
            self.level,
            format_bytes(self.whole),
            self.bound(),
            times.read_pieces,
            times.pieces,
            times.read_voxels,
            times.read.as_secs_f64(),
            times.render.as_secs_f64()
        )
    }

    /// What the level's frame went over: --max-memory, or one piece's
    /// budget beneath it ([`volray_lazy::Chunked::plan`]).
    fn bound(&self) -> String {
        let limit = format_bytes(u128::from(self.max_memory));
        if self.max_memory > volray_lazy::PIECE_BUDGET {
            let piece = format_bytes(u128::from(volray_lazy::PIECE_BUDGET));
            format!("a piece's {piece} (under --max-memory {limit})")
        } else {
            format!("--max-memory {limit}")
        }
    }

    /// A failed step as the CLI's error.
    fn failure(&self, view: &ViewArgs, e: StreamError) -> CliError {
        match e {
            StreamError::Read(message) => CliError::io(message),
            StreamError::TooLarge(message) => CliError::input(format!(
                "{}: {message}: raise --max-memory, or pick a coarser --level",
                self.name
            )),
            StreamError::Render(e) => render_failure(view, &self.name, e),
        }
    }
}
