//! Planning an input: read whole (or mapped), or, for a chunked volume
//! (Zarr, OME-Zarr), which level (`--level auto`) and, where that level
//! is too large to render whole under the memory limit, rendering it
//! piece by piece from its chunks (volray-distributed's `Streamed`),
//! never reading it whole.
//!
//! The order: the file is opened from its metadata alone; `--level auto`
//! picks the level for the picture (volray-options' `level`); the level's
//! frame is bounded as a whole volume's would be (`memory.rs`). Within
//! the limit it is read whole and rendered as any file is (the same
//! pixels as `--level N`); beyond it, or beyond one piece's
//! [`volray_lazy::PIECE_BUDGET`] (lighter and faster then), in pieces of at
//! most that each.

use crate::error::AppError;
use crate::input::{self, Request, Spec};
use volray_core::{FrameRequest, Image, NonFinite, Render, RenderSettings, Rendered};
use volray_distributed::streamed::{StreamError, StreamTimes, Streamed};
use volray_io::MapPolicy;
use volray_lazy::{Chunked, Found, LookError, Plan as LazyPlan};
use volray_options::LookOptions;
use volray_options::level::LevelChoice;

/// How an input is rendered.
pub enum Plan {
    /// Read whole (or mapped), as every file is: at this level, if any.
    Whole { level: Option<usize> },
    /// Rendered piece by piece from its chunks.
    Streamed(Box<StreamedInput>),
}

/// A chunked volume rendered piece by piece.
pub struct StreamedInput {
    pub name: String,
    /// How its axes were stretched for drawing, where they were by the
    /// default rule (`display.rs`): the note a front end says.
    pub display_note: Option<String>,
    pub streamed: Streamed,
    /// The labels or histogram found in the level, once.
    found: Found,
    /// The file's display window (OME-Zarr `omero`), the default `--range`.
    window: Option<(f64, f64)>,
    /// The colours the file gives its labels, for `--labels`.
    label_colours: Vec<(i64, [f32; 3])>,
    /// The level, what it may take whole, and the limit (for the note
    /// after a frame).
    pub level: usize,
    pub whole: u128,
    pub max_memory: u64,
}

/// What `--level auto` chose, said as it is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Chosen {
    pub level: usize,
    /// How many levels the file has, and the chosen level's grid.
    pub levels: usize,
    pub dims: [usize; 3],
}

/// What a plan is for: the frames' settings, and the look options that
/// change what is read.
pub struct Frames<'a> {
    pub settings: &'a RenderSettings,
    pub non_finite: NonFinite,
    /// Values on a log scale (`--log`), and values as labels (`--labels`).
    pub log: bool,
    pub labels: bool,
    /// What the front end adds to each frame ([`crate::memory::Budget::extra`]).
    pub extra: u128,
}

/// Decides how `request`'s input is rendered for `frames`: opens a
/// chunked file from its metadata, picks its level (telling `chosen`
/// what `--level auto` chose), and streams it when that level's frame
/// would not fit the memory limit whole. Other inputs (built-in sources,
/// formats read whole or mapped) are read whole.
pub fn plan(
    request: &Request,
    frames: &Frames<'_>,
    chosen: &mut dyn FnMut(Chosen),
) -> Result<Plan, AppError> {
    if matches!(request.spec, Spec::Source(_)) {
        return Ok(Plan::Whole { level: None });
    }
    let spec = request.spec.name();
    let max_memory = request.max_memory();
    let Some(mut chunked) = open_chunked(request, max_memory)? else {
        return Ok(Plan::Whole {
            level: request.fixed_level(),
        });
    };
    let settings = frames.settings;
    // A multiscale image without a level named is drawn as `auto` would:
    // the first picture of a 2048³ pyramid need not read 16 GiB to show
    // 480² pixels (neuroglancer and napari pick by screen resolution too).
    // The level is said (`chosen`), and `level 0` names the finest.
    let auto = match request.level {
        Some(choice) => choice == LevelChoice::Auto,
        None => chunked.levels().len() > 1,
    };
    if auto {
        let level = (chunked.auto_level(settings)).map_err(|error| AppError::AutoLevel {
            spec: spec.clone(),
            error,
        })?;
        let levels = chunked.levels();
        chosen(Chosen {
            level,
            levels: levels.len(),
            dims: levels[level].dims,
        });
        chunked = chunked.at_level(level)?;
    }
    let Some(plan) = plan_level(&chunked, &spec, frames, max_memory, false)? else {
        unreachable!("a plan is made where none is kept")
    };
    match plan {
        LazyPlan::Whole { level, .. } => Ok(Plan::Whole { level: Some(level) }),
        LazyPlan::Pieces {
            level,
            need,
            streamed,
        } => {
            let (streamed, display_note) =
                stretched_pieces(&chunked, *streamed, frames, max_memory, request.scale);
            Ok(Plan::Streamed(Box::new(StreamedInput {
                name: spec,
                display_note,
                streamed: streamed.with_labels(frames.labels),
                found: Found::default(),
                window: chunked.info().display_window(),
                label_colours: crate::input::segment_colours(chunked.info()),
                level,
                whole: need,
                max_memory,
            })))
        }
    }
}

/// `streamed`, the pieces of `chunked`'s level planned for `frames`
/// under `max_memory`, stretched for drawing as a whole volume's axes are
/// (`display.rs`: `scale` as given, else the default rule): each piece
/// placed in the stretched world, in pieces of the same budget; and the
/// default rule's note. Unchanged where nothing is stretched.
pub fn stretched_pieces(
    chunked: &Chunked,
    streamed: Streamed,
    frames: &Frames<'_>,
    max_memory: u64,
    scale: Option<[f64; 3]>,
) -> (Streamed, Option<String>) {
    let grid = streamed.grid();
    let n = grid.dims.map(|n| n.saturating_sub(1) as f64);
    let extent = grid.spacing * volray_core::glam::DVec3::from(n);
    let Some(s) = crate::display::stretch(Some(chunked.info()), extent, scale) else {
        return (streamed, None);
    };
    // volray-lazy's budgets: a piece's, a third of it under `--log`
    // (`Chunked::plan`, `Chunked::log_pieces`).
    let budget = max_memory.min(volray_lazy::PIECE_BUDGET);
    let budget = if frames.log { budget / 3 } else { budget };
    let source = crate::display::Stretched::new(streamed.source().clone(), s.factors);
    let source: std::sync::Arc<dyn volray_core::VolumeSource> = std::sync::Arc::new(source);
    (Streamed::new(source, frames.non_finite, budget), s.note)
}

/// How `chunked`'s level (of the input `name`) is rendered for `frames`
/// under `max_memory`: volray-lazy's plan, whole or in pieces, or with
/// `log` its plan of the level's log10 (in pieces after a pass over the
/// level for its smallest positive value). `kept`: the front end renders
/// this level in pieces already (Python's `Renderer` keeps them from
/// frame to frame, with what it found in them): `None` where the plan is
/// pieces again, with no second pass over the level.
pub fn plan_level(
    chunked: &Chunked,
    name: &str,
    frames: &Frames<'_>,
    max_memory: u64,
    kept: bool,
) -> Result<Option<LazyPlan>, AppError> {
    let (settings, mode, extra) = (frames.settings, frames.non_finite, frames.extra);
    if !frames.log {
        let plan = chunked.plan(settings, mode, max_memory, extra);
        return Ok((!(kept && matches!(plan, LazyPlan::Pieces { .. }))).then_some(plan));
    }
    // `plan_log`'s rule, asked before its pass over the level.
    let whole = chunked.whole_log_bytes(settings, mode) + extra;
    if kept && whole > u128::from(max_memory.min(volray_lazy::PIECE_BUDGET)) {
        return Ok(None);
    }
    // A slab the system failed to read is a read's failure; bad data
    // (or no positive value) is --log's.
    let plan = chunked.plan_log(settings, mode, max_memory, extra);
    plan.map(Some).map_err(|error| match error.is_io_failure() {
        true => AppError::Stream {
            name: name.to_string(),
            error: StreamError::Read(error),
        },
        false => AppError::Log {
            name: name.to_string(),
            message: error.message,
        },
    })
}

/// Opens `request`'s file from its metadata where it is stored in
/// chunks, at the level `level N` names (0 for `auto`, which the caller
/// resolves); `None` for a file read whole or mapped. `level auto` on
/// such a file is refused: it has one level.
pub fn open_chunked(request: &Request, max_memory: u64) -> Result<Option<Chunked>, AppError> {
    let Spec::File(path) = &request.spec else {
        return Ok(None);
    };
    let numbered = Request {
        level: request.fixed_level().map(LevelChoice::Index),
        ..request.clone()
    };
    let opts = input::read_options(&numbered, max_memory, MapPolicy::IfLarger)?;
    let chunked = Chunked::open(path, &opts)?;
    if chunked.is_none() && request.level == Some(LevelChoice::Auto) {
        return Err(AppError::AutoLevelOneLevel {
            spec: request.spec.name(),
        });
    }
    Ok(chunked)
}

impl StreamedInput {
    /// `settings` with what the look options leave to the volume
    /// (`--labels`, in the colours the file gives them, `--tf auto`),
    /// found piece by piece (volray-lazy's [`Found`], which the Python
    /// module shares), within the file's display window where the options
    /// give no range.
    pub fn settings_from_volume(
        &mut self,
        look: &LookOptions,
        mut settings: RenderSettings,
    ) -> Result<RenderSettings, AppError> {
        let name = self.name.clone();
        volray_options::file_window(look, &mut settings.transfer_function, self.window);
        let look = crate::look::with_file_colours(look, self.label_colours.clone());
        let found = self
            .found
            .apply(&mut self.streamed, &look, &mut settings, &name);
        match found {
            Ok(()) => Ok(settings),
            Err(LookError::Stream(error)) => Err(AppError::Stream { name, error }),
            Err(LookError::Refused(e)) => Err(AppError::Option(e)),
        }
    }

    /// One frame.
    pub fn render(
        &mut self,
        settings: &RenderSettings,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<(Image, StreamTimes), AppError> {
        (self
            .streamed
            .render(FrameRequest::new(settings).reporting(progress)))
        .map(Rendered::image_and_times)
        .map_err(|error| AppError::Stream {
            name: self.name.clone(),
            error,
        })
    }

    /// Whether the level's frame went over one piece's budget beneath the
    /// limit ([`volray_lazy::Chunked::plan`]) rather than the limit itself.
    pub fn over_piece_budget(&self) -> bool {
        self.max_memory > volray_lazy::PIECE_BUDGET
    }
}
