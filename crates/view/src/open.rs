//! `volray view` of a chunked file (Zarr, OME-Zarr): opened from its
//! metadata (volray-lazy's `Chunked`), each level a source of boxes that
//! the viewer reads as its frames need them (volray-view's `Pyramid`):
//! while the view moves, a coarse level held whole; when it stops, the
//! level the still needs (`--level N`, or `auto`, the default for a
//! multiscale image), whole where it fits what `--max-memory` has left,
//! else piece by piece. Only the level the first drafts show is read
//! before the server starts: the page's first message (the histogram,
//! `--tf auto`, `--labels`) is made from it.
//!
//! Under `--log` or `--spacing` a chunked file is read whole at its level
//! as before (`volray_view`'s levels are not taken to log10 or respaced
//! yet).

use crate::error::CliError;
use crate::flags::ViewerArgs;
use std::path::Path;
use std::sync::Arc;
use volray_app::input::{self, Input};
use volray_core::glam::DVec3;
use volray_core::{NonFinite, RenderSettings, SampleType};
use volray_io::format_bytes;
use volray_options::level::LevelChoice;
use volray_view::{DRAFT_SHARE, Hello, Pyramid, draft_side};

/// A chunked file opened for the viewer.
pub struct Opened {
    spec: String,
    pyramid: Pyramid,
    /// The level the starting view's drafts show, read for the page's
    /// first message.
    start: usize,
}

/// Opens INPUT level by level when it is a chunked file (and neither
/// `--log` nor `--spacing` is given); `None` for any other input, read
/// whole as before. `settings` are the starting view's.
pub fn open(args: &ViewerArgs, settings: &RenderSettings) -> Result<Option<Opened>, CliError> {
    let inp = &args.input;
    let spec = inp.input.as_deref().unwrap_or(input::DEMO);
    if volray_data::is_source_spec(spec) {
        return Ok(None);
    }
    let auto = inp.level == Some(LevelChoice::Auto);
    if args.view.look.log || inp.spacing.is_some() {
        if auto {
            return Err(CliError::input(format!(
                "{spec}: --level auto: the viewer reads a multiscale image's levels as its frames need them, but not yet with --log or --spacing: give a level number, 0 the finest"
            )));
        }
        return Ok(None);
    }
    let request = inp.request();
    let max_memory = request.max_memory();
    let fixed = request.fixed_level();
    let Some(chunked) = volray_app::plan::open_chunked(&request, max_memory)? else {
        return Ok(None);
    };
    let count = chunked.levels().len();
    let mut sources = Vec::with_capacity(count);
    for level in 0..count {
        sources.push(Arc::clone(chunked.open_level(level)?.source()));
    }
    let pyramid =
        Pyramid::new(sources, fixed).map_err(|e| CliError::input(format!("{spec}: {e}")))?;
    let camera = |e| CliError::input(format!("{spec}: {e}"));
    let still = pyramid.still_level(settings).map_err(camera)?;
    let non_finite: NonFinite = args.view.sampling.nonfinite.into();
    let limit = u128::from(max_memory);
    let Some(start) = pyramid
        .first_draft_level(settings, non_finite, limit)
        .map_err(camera)?
    else {
        let last = count - 1;
        let draft = RenderSettings {
            width: draft_side(settings.width),
            height: draft_side(settings.height),
            ..settings.clone()
        };
        let [x, y, z] = pyramid.grid(last).dims;
        return Err(CliError::input(format!(
            "{spec}: its coarsest level ({x}x{y}x{z}) may take up to {} to render whole, more than the 1/{DRAFT_SHARE} of --max-memory {} the viewer gives the frames while the view moves: raise --max-memory",
            format_bytes(pyramid.whole_bytes(last, &draft, non_finite)),
            format_bytes(limit)
        )));
    };
    let [x, y, z] = pyramid.grid(start).dims;
    let when_still = match fixed {
        Some(n) => format!("level {n}"),
        None => format!("the level each still needs (--level auto; {still} for the start)"),
    };
    eprintln!(
        "volray: {}: {count} level{}; the view shows level {start} ({x}x{y}x{z}) while it moves, {when_still} when still",
        Path::new(spec).display(),
        if count == 1 { "" } else { "s" }
    );
    Ok(Some(Opened {
        spec: spec.to_string(),
        pyramid,
        start,
    }))
}

/// The `--level` word of the commands the page shows: the level the
/// stills show (`auto` for a multiscale image opened level by level
/// without `--level`), or the `--level N` given.
pub fn level_word(args: &ViewerArgs, opened: Option<&Opened>) -> Option<String> {
    match (args.input.level, opened) {
        (Some(LevelChoice::Index(n)), _) => Some(n.to_string()),
        (_, Some(o)) if o.pyramid.len() > 1 => Some("auto".to_string()),
        _ => None,
    }
}

impl Opened {
    /// The level the first drafts show, read whole, as the input the
    /// page's first message and the starting checks are made from.
    pub fn start_input(&self, args: &ViewerArgs) -> Result<Input, CliError> {
        let dims = self.pyramid.grid(self.start).dims;
        let volume = (self.pyramid.source(self.start))
            .read_box([0; 3], dims)
            .map_err(CliError::from)?;
        Ok(Input {
            volume,
            name: self.spec.clone(),
            file: None,
            max_memory: args
                .input
                .max_memory
                .unwrap_or_else(volray_io::default_max_memory),
        })
    }

    /// The coarsest level's grid: a frame that does not fit beside it
    /// fits beside no level.
    pub fn coarsest_grid(&self) -> ([usize; 3], DVec3, SampleType) {
        let last = self.pyramid.len() - 1;
        let grid = self.pyramid.grid(last);
        let sample = self.pyramid.source(last).sample_type();
        (grid.dims, grid.spacing, sample)
    }

    /// The page's first message names the finest level's grid and every
    /// level.
    pub fn describe(&self, hello: &mut Hello) {
        self.pyramid.describe(hello);
    }

    /// The pyramid (its values labels or not) and the level read first.
    pub fn into_levels(self, labels: bool) -> (Pyramid, usize) {
        (self.pyramid.with_labels(labels), self.start)
    }
}
