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
//! A level read whole is held behind an `Arc` (its samples as outside
//! bytes, so that each tab's renderer of it shares them) together with
//! its reservation in the server's ledger: the bytes are given back when
//! the last renderer of the level and the cache have let go of it.

use crate::ledger::{Ledger, Overdrawn, Reservation};
use bytemuck::cast_slice;
use std::sync::{Arc, Mutex, MutexGuard};
use volray_core::camera::CameraError;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{
    External, ExternalBytes, MemoryBound, NonFinite, RenderSettings, Sample, Samples, Store,
    Volume, VolumeSource,
};

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

/// Why a level could not be read whole.
#[derive(Debug, thiserror::Error)]
pub enum LevelError {
    #[error("{0}")]
    Memory(#[from] Overdrawn),
    /// The source's one-line message.
    #[error("{0}")]
    Read(String),
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
            width: crate::session::draft_side(settings.width),
            height: crate::session::draft_side(settings.height),
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

/// The levels read whole, shared by every tab: the last
/// [`CACHED_LEVELS`] used.
pub struct Levels {
    pub pyramid: Pyramid,
    /// Level and volume, the most recently used last.
    cache: Mutex<Vec<(usize, Volume)>>,
}

impl Levels {
    pub fn new(pyramid: Pyramid) -> Levels {
        Levels {
            pyramid,
            cache: Mutex::new(Vec::new()),
        }
    }

    fn lock(&self) -> MutexGuard<'_, Vec<(usize, Volume)>> {
        self.cache.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Whether level `level` is held whole now.
    pub fn is_held(&self, level: usize) -> bool {
        self.lock().iter().any(|(l, _)| *l == level)
    }

    /// Keeps `volume` as level `level`, its bytes held by `reserved`.
    pub fn keep(&self, level: usize, volume: Volume, reserved: Reservation) -> Volume {
        let volume = shared(volume, reserved);
        let mut cache = self.lock();
        cache.retain(|(l, _)| *l != level);
        cache.push((level, volume.clone()));
        let over = cache.len().saturating_sub(CACHED_LEVELS);
        cache.drain(..over);
        volume
    }

    /// Level `level` whole: from the cache, or read (its bytes reserved
    /// from `ledger` first, the least recently used levels let go of
    /// where they do not fit). Tabs reading at once wait for each other.
    pub fn whole(&self, level: usize, ledger: &Arc<Ledger>) -> Result<Volume, LevelError> {
        let mut cache = self.lock();
        if let Some(i) = cache.iter().position(|(l, _)| *l == level) {
            let entry = cache.remove(i);
            let volume = entry.1.clone();
            cache.push(entry);
            return Ok(volume);
        }
        let pyramid = &self.pyramid;
        let [x, y, z] = pyramid.grid(level).dims;
        let what = format!("level {level} ({x}x{y}x{z}) read whole");
        let bytes = pyramid.volume_bytes(level);
        let reserved = loop {
            match ledger.reserve(&what, bytes) {
                Ok(r) => break r,
                // Let go of the least recently used level, and try again
                // (its bytes come back once no tab renders it either).
                Err(e) if cache.is_empty() => return Err(e.into()),
                Err(_) => {
                    cache.remove(0);
                }
            }
        };
        let dims = pyramid.grid(level).dims;
        let mut volume = pyramid
            .source(level)
            .read_box([0; 3], dims)
            .map_err(LevelError::Read)?;
        volume.set_labels(pyramid.labels);
        let volume = shared(volume, reserved);
        cache.push((level, volume.clone()));
        let over = cache.len().saturating_sub(CACHED_LEVELS);
        cache.drain(..over);
        Ok(volume)
    }
}

/// Samples read whole, and their bytes' reservation: given back when the
/// last volume sharing them is dropped.
#[derive(Debug)]
struct Held {
    samples: Owned,
    _reserved: Reservation,
}

#[derive(Debug)]
enum Owned {
    U8(Vec<u8>),
    I8(Vec<i8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    F32(Vec<f32>),
}

impl ExternalBytes for Held {
    fn bytes(&self) -> &[u8] {
        match &self.samples {
            Owned::U8(v) => v,
            Owned::I8(v) => cast_slice(v),
            Owned::U16(v) => cast_slice(v),
            Owned::I16(v) => cast_slice(v),
            Owned::F32(v) => cast_slice(v),
        }
    }

    fn verify(&self) -> Result<(), String> {
        // Memory of our own: nothing can change it underneath.
        Ok(())
    }
}

/// `volume` with its samples behind an `Arc`, held with `reserved`:
/// clones share them. A volume whose samples are already outside bytes
/// is returned as it is (and `reserved` given back).
pub fn shared(volume: Volume, reserved: Reservation) -> Volume {
    let (dims, spacing, origin, labels) = (
        volume.dims(),
        volume.spacing(),
        volume.origin(),
        volume.is_labels(),
    );
    let samples = match volume.into_samples() {
        Samples::U8(Store::Owned(v)) => Samples::U8(held(v, Owned::U8, reserved)),
        Samples::I8(Store::Owned(v)) => Samples::I8(held(v, Owned::I8, reserved)),
        Samples::U16(Store::Owned(v)) => Samples::U16(held(v, Owned::U16, reserved)),
        Samples::I16(Store::Owned(v)) => Samples::I16(held(v, Owned::I16, reserved)),
        Samples::F32(Store::Owned(v)) => Samples::F32(held(v, Owned::F32, reserved)),
        external => external,
    };
    let mut volume = Volume::from_samples(dims, samples)
        .and_then(|v| v.with_spacing(spacing))
        .and_then(|v| v.with_origin(origin))
        .expect("the grid of a volume that was valid");
    volume.set_labels(labels);
    volume
}

/// The samples `v` behind an `Arc` with `reserved`, as outside bytes.
fn held<T: Sample>(v: Vec<T>, wrap: fn(Vec<T>) -> Owned, reserved: Reservation) -> Store<T> {
    let len = v.len();
    let held: Arc<dyn ExternalBytes> = Arc::new(Held {
        samples: wrap(v),
        _reserved: reserved,
    });
    // A vector of the samples' own type: aligned, and `len` of them.
    Store::External(External::new(held, 0, len).expect("a vector's own samples"))
}
