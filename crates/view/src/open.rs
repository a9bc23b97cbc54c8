//! A chunked file (Zarr, OME-Zarr) opened for the viewer level by level
//! (volray-lazy's `Chunked`), each level a source of boxes that the
//! viewer reads as its frames need them ([`Pyramid`]): while the view
//! moves, a coarse level held whole; when it stops, the level the still
//! needs (a fixed level, or `auto`), whole where it fits what the memory
//! limit has left, else piece by piece. Only the level the first drafts
//! show is read before the server starts: the page's first message (the
//! histogram, `tf auto`, `labels`) is made from it.
//!
//! `volray view` and the Python module's `volray.view` open a chunked file
//! here and each words the refusals ([`OpenError`]) in its own syntax.

use crate::{Pyramid, PyramidError, draft_side};
use std::sync::Arc;
use volray_app::display::Stretched;
use volray_core::glam::DVec3;
use volray_core::{
    CameraError, NonFinite, RenderSettings, SampleType, SourceError, Volume, VolumeSource,
};
use volray_io::IoError;
use volray_lazy::Chunked;

/// A chunked file opened for the viewer.
pub struct Opened {
    pub pyramid: Pyramid,
    /// How axes in different units were stretched for drawing, where the
    /// default rule stretched them (volray-app's `display`): the note the
    /// front end says.
    pub display_note: Option<String>,
    /// The level the starting view's drafts show, read for the page's
    /// first message.
    pub start: usize,
    /// The level the starting view's still shows.
    pub still: usize,
}

/// Why a chunked file could not be served level by level.
#[derive(Debug, thiserror::Error)]
pub enum OpenError {
    /// A level's metadata could not be read.
    #[error(transparent)]
    Read(#[from] IoError),
    /// The level asked for is not there.
    #[error(transparent)]
    Pyramid(#[from] PyramidError),
    /// The starting view could not be framed.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// Even the coarsest level's draft frame is over its share of the
    /// memory limit (1/[`crate::DRAFT_SHARE`]).
    #[error("its coarsest level takes more than the viewer's share of the memory limit")]
    CoarsestTooLarge {
        /// The coarsest level's grid points.
        dims: [usize; 3],
        /// What its draft frame may take, and the limit.
        need: u128,
        limit: u128,
    },
}

/// Opens every level of `chunked` as the viewer's pyramid, the stills
/// showing `fixed` (`None`: the level each still needs) and the drafts
/// of the starting view (`settings`) a level whose frames fit their
/// share of `limit`; its axes stretched for drawing as `scale` (`--scale`)
/// or, for axes in different units, volray-app's default rule says, every
/// level alike, as `render` stretches the level it reads.
pub fn open_levels(
    chunked: &Chunked,
    fixed: Option<usize>,
    settings: &RenderSettings,
    non_finite: NonFinite,
    limit: u128,
    scale: Option<[f64; 3]>,
) -> Result<Opened, OpenError> {
    let count = chunked.levels().len();
    let mut sources: Vec<Arc<dyn VolumeSource>> = Vec::with_capacity(count);
    for level in 0..count {
        sources.push(Arc::clone(chunked.open_level(level)?.source()));
    }
    // The stretch of the finest level's box (`render` reads the file's
    // first level's metadata for it too).
    let finest = sources[0].grid();
    let n = finest.dims.map(|n| n.saturating_sub(1) as f64);
    let extent = finest.spacing * DVec3::from(n);
    let stretch = volray_app::display::stretch(Some(chunked.info()), extent, scale);
    if let Some(s) = &stretch {
        sources = (sources.into_iter())
            .map(|source| Arc::new(Stretched::new(source, s.factors)) as Arc<dyn VolumeSource>)
            .collect();
    }
    let pyramid = Pyramid::new(sources, fixed)?;
    let still = pyramid.still_level(settings)?;
    let Some(start) = pyramid.first_draft_level(settings, non_finite, limit)? else {
        let last = count - 1;
        let draft = RenderSettings {
            width: draft_side(settings.width),
            height: draft_side(settings.height),
            ..settings.clone()
        };
        return Err(OpenError::CoarsestTooLarge {
            dims: pyramid.grid(last).dims,
            need: pyramid.whole_bytes(last, &draft, non_finite),
            limit,
        });
    };
    Ok(Opened {
        pyramid,
        display_note: stretch.and_then(|s| s.note),
        start,
        still,
    })
}

impl Opened {
    /// The level the first drafts show, read whole: the volume the page's
    /// first message and the starting checks are made from.
    pub fn start_volume(&self) -> Result<Volume, SourceError> {
        let dims = self.pyramid.grid(self.start).dims;
        self.pyramid.source(self.start).read_box([0; 3], dims)
    }

    /// The coarsest level's grid: a frame that does not fit beside it
    /// fits beside no level.
    pub fn coarsest_grid(&self) -> ([usize; 3], DVec3, SampleType) {
        let last = self.pyramid.len() - 1;
        let grid = self.pyramid.grid(last);
        let sample = self.pyramid.source(last).sample_type();
        (grid.dims, grid.spacing, sample)
    }

    /// The pyramid (its values labels or not) and the level read first:
    /// the viewer's `levels`.
    pub fn into_levels(self, labels: bool) -> (Pyramid, usize) {
        (self.pyramid.with_labels(labels), self.start)
    }
}
