//! A chunked, multiscale volume (an OME-Zarr pyramid) served level by
//! level, never read whole unless a level fits:
//!
//! - **While the view moves** (draft frames) a coarse level is rendered,
//!   held in memory whole: the level `--level auto` picks for the draft's
//!   size (volray-options' `auto_level`), no finer than the still's, and
//!   coarser still until rendering it whole takes at most
//!   1/[`DRAFT_SHARE`] of the memory limit. The levels read whole are
//!   kept, the last [`CACHED_LEVELS`] of them, shared by every tab, so a
//!   drag reads nothing after its first frame.
//! - **When the view stops** (full frames, saves) the level the still
//!   needs is rendered: `--level N`, or `auto` for the full-size frame.
//!   Whole when its frame fits what the memory limit has left (the same
//!   bound as volray-lazy's `Chunked::plan`); else piece by piece
//!   (volray-distributed's `Streamed`, pieces of at most
//!   [`volray_lazy::PIECE_BUDGET`]), stopped between pieces by a newer
//!   request.
//!
//! The levels read whole are held by `levels.rs` ([`crate::levels::Levels`]).
//!
//! Every frame of a pyramid, draft or still, is framed on the box of the
//! still's level ([`Pyramid::framed`]), whichever level it shows: a
//! level's box is its first and last grid points', which sit half a
//! voxel of that level inside the finer level's (OME-Zarr's translation,
//! `zarr/write.rs`), so that a coarse level framed on its own box is
//! drawn 1–3 % larger, and the picture would jump when the still
//! replaces the drafts.

use std::sync::Arc;
use volray_core::camera::CameraError;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{MemoryBound, NonFinite, RenderSettings, VolumeSource};

/// A level read whole for the frames while the view moves may take, with
/// its frame, at most this fraction (1/4) of the memory limit.
pub const DRAFT_SHARE: u128 = 4;

/// How many levels read whole the server keeps (the drafts' and the
/// still's).
pub const CACHED_LEVELS: usize = 2;

/// A multiscale volume: each level a source of boxes, finest first.
pub struct Pyramid {
    levels: Vec<Arc<dyn VolumeSource>>,
    still: Option<usize>,
    labels: bool,
}

/// A pyramid that cannot be served.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PyramidError {
    #[error("the image has no level")]
    Empty,
    #[error("--level {0}: the image has {1} levels, 0 the finest")]
    NoSuchLevel(usize, usize),
}

impl Pyramid {
    /// The levels `levels` (finest first), the still frames showing
    /// `still` (`None`: the level each still needs, `--level auto`).
    pub fn new(
        levels: Vec<Arc<dyn VolumeSource>>,
        still: Option<usize>,
    ) -> Result<Pyramid, PyramidError> {
        if levels.is_empty() {
            return Err(PyramidError::Empty);
        }
        if let Some(n) = still.filter(|&n| n >= levels.len()) {
            return Err(PyramidError::NoSuchLevel(n, levels.len()));
        }
        Ok(Pyramid {
            levels,
            still,
            labels: false,
        })
    }

    /// The same, its values read as labels (a segmentation) or not.
    pub fn with_labels(mut self, labels: bool) -> Pyramid {
        self.labels = labels;
        self
    }

    /// Whether the values are read as labels.
    pub fn labels(&self) -> bool {
        self.labels
    }

    /// The number of levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Never: a pyramid has a level (for clippy's sake).
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }

    /// Level `level`'s source.
    pub fn source(&self, level: usize) -> &Arc<dyn VolumeSource> {
        &self.levels[level]
    }

    /// Level `level`'s grid.
    pub fn grid(&self, level: usize) -> GridFrame {
        self.levels[level].grid()
    }

    /// `--level N` as given, `None` for `auto`.
    pub fn fixed(&self) -> Option<usize> {
        self.still
    }

    /// The coarsest level whose voxels are no larger than a pixel's
    /// footprint in a frame of `settings`, framed on the finest level's
    /// box (volray-options' `auto_level`, as `volray render --level auto`
    /// and volray-lazy's `Chunked::auto_level` choose).
    pub fn auto_level(&self, settings: &RenderSettings) -> Result<usize, CameraError> {
        let spacings: Vec<DVec3> = self.levels.iter().map(|l| l.grid().spacing).collect();
        volray_options::level::auto_level(&spacings, self.grid(0).bounds(), settings)
    }

    /// The level a still frame of `settings` shows: `--level N`, or auto.
    pub fn still_level(&self, settings: &RenderSettings) -> Result<usize, CameraError> {
        match self.still {
            Some(n) => Ok(n),
            None => self.auto_level(settings),
        }
    }

    /// `settings` framed on the box of level `still` (the camera's own
    /// box where it names one), for a frame of any level: drafts of a
    /// coarser level then put the volume's edges where the still puts
    /// them (within half a voxel of the coarser level), and the still is
    /// the frame `volray render --level N` renders of its level.
    pub fn framed(&self, settings: &RenderSettings, still: usize) -> RenderSettings {
        let mut framed = settings.clone();
        framed.camera.bounds = Some(framed.camera.framed_bounds(self.grid(still).bounds()));
        framed
    }

    /// The level a draft frame of `draft` shows, when the still shows
    /// `still`: the auto level of the draft, no finer than `still`, and
    /// coarser until rendering it whole takes at most `limit` /
    /// [`DRAFT_SHARE`]; `None` when even the coarsest does not.
    pub fn draft_level(
        &self,
        draft: &RenderSettings,
        still: usize,
        non_finite: NonFinite,
        limit: u128,
    ) -> Result<Option<usize>, CameraError> {
        let first = self.auto_level(draft)?.max(still);
        Ok((first..self.len())
            .find(|&level| self.whole_bytes(level, draft, non_finite) <= limit / DRAFT_SHARE))
    }

    /// The level the first drafts of a view starting at `settings` show
    /// (read whole before the viewer starts, for the page's first
    /// message): [`Pyramid::draft_level`] of the draft-sized settings
    /// under the still's level; `None` when even the coarsest level's
    /// draft frame takes more than 1/[`DRAFT_SHARE`] of `limit`.
    pub fn first_draft_level(
        &self,
        settings: &RenderSettings,
        non_finite: NonFinite,
        limit: u128,
    ) -> Result<Option<usize>, CameraError> {
        let still = self.still_level(settings)?;
        let draft = RenderSettings {
            width: crate::protocol::draft_side(settings.width),
            height: crate::protocol::draft_side(settings.height),
            ..settings.clone()
        };
        self.draft_level(&draft, still, non_finite, limit)
    }

    /// Names in the page's first message the finest level's grid and
    /// every level's dims (the page's level read-out).
    pub fn describe(&self, hello: &mut crate::Hello) {
        let finest = self.grid(0);
        hello.dims = finest.dims;
        hello.spacing = finest.spacing.to_array();
        hello.levels = Some((0..self.len()).map(|l| self.grid(l).dims).collect());
    }

    /// The most bytes a frame of `settings` may take with level `level`
    /// read whole, the volume included, no brick cache (volray-core's
    /// bound, as volray-lazy's `Chunked::whole_bytes`).
    pub fn whole_bytes(&self, level: usize, settings: &RenderSettings, nf: NonFinite) -> u128 {
        self.bound(level, settings, nf, 0).total()
    }

    /// volray-core's bound on a frame of `settings` of level `level` read
    /// whole, with `cache_budget` bytes of brick caches.
    pub fn bound(
        &self,
        level: usize,
        settings: &RenderSettings,
        non_finite: NonFinite,
        cache_budget: usize,
    ) -> MemoryBound {
        let source = &self.levels[level];
        let grid = source.grid();
        MemoryBound::new(
            grid.dims,
            grid.spacing,
            source.sample_type(),
            settings,
            non_finite,
            cache_budget,
        )
    }

    /// The bytes level `level`'s samples take once read.
    pub fn volume_bytes(&self, level: usize) -> u128 {
        let source = &self.levels[level];
        let voxels: u128 = source.grid().dims.iter().map(|&n| n as u128).product();
        voxels * source.voxel_bytes() as u128
    }
}
