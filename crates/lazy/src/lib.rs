//! Volumes that stay in their files until a frame needs them: a chunked,
//! multiscale file (Zarr, OME-Zarr) opened from its metadata alone, the
//! level of detail a frame needs (`--level auto`), and the choice between
//! reading that level whole and rendering it piece by piece from its
//! chunks under a memory limit. The command line, the Python module and
//! the viewer all decide through this crate, so the same file and options
//! read the same level and take the same path in each.
//!
//! The order of use:
//! 1. [`Chunked::open`]: `Ok(None)` for a file that is not stored in
//!    chunks (read it whole or map it, as `volray_io::read` does);
//! 2. [`Chunked::auto_level`] for `--level auto`, then [`Chunked::at_level`];
//! 3. [`Chunked::plan`]: [`Plan::Whole`] when the level's frame fits the
//!    memory limit (read it with `volray_io::read` at that level: the same
//!    pixels as any file), else [`Plan::Pieces`], a
//!    [`Streamed`] render that reads at most [`PIECE_BUDGET`] at a time;
//! 4. for [`Plan::Pieces`], [`Found::apply`]: what the look leaves to the
//!    volume (`--labels`' list, `--tf auto`'s histogram), found piece by
//!    piece once and kept for the frames after.
//!
//! [`Chunked::stoppable`] makes a frame in pieces stop at its next piece
//! once a flag is set (Ctrl-C in Python, a newer view in the viewer).
//!
//! ```
//! use volray_core::{RenderSettings, NonFinite, Volume};
//! use volray_io::{OmeZarrOptions, ReadOptions, write_ome_zarr};
//! use volray_lazy::{Chunked, Plan};
//!
//! // A 64³ ramp written as an OME-Zarr pyramid of 16³ chunks: levels
//! // 64³, 32³ and 16³.
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("ramp.ome.zarr");
//! let values: Vec<f32> = (0..64 * 64 * 64).map(|i| (i % 64) as f32).collect();
//! let volume = Volume::new([64; 3], values).unwrap();
//! let options = OmeZarrOptions { chunk: 16, shard: 32, ..OmeZarrOptions::default() };
//! write_ome_zarr(&path, &volume, &options).unwrap();
//!
//! let chunked = Chunked::open(&path, &ReadOptions::default()).unwrap().unwrap();
//! assert_eq!(chunked.levels().len(), 3);
//! // A 32² picture resolves no more than level 1.
//! let settings = RenderSettings { width: 32, height: 32, ..RenderSettings::default() };
//! let level = chunked.auto_level(&settings).unwrap();
//! assert_eq!(level, 1);
//! let chunked = chunked.at_level(level).unwrap();
//! assert_eq!(chunked.source().grid().dims, [32; 3]);
//! // 1 MiB holds the 32³ level's frame: read it whole.
//! match chunked.plan(&settings, NonFinite::default(), 1 << 20, 0) {
//!     Plan::Whole { level: 1, .. } => {}
//!     _ => panic!("a 32³ level is read whole"),
//! }
//! ```

mod log;

pub use log::Log10Source;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use volray_core::camera::CameraError;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::transfer::auto::{self, Robust};
use volray_core::transfer::labels::MAX_LABELS;
use volray_core::{
    Histogram, MemoryBound, NonFinite, RenderSettings, SampleType, SourceError, SourceErrorKind,
    Volume, VolumeSource,
};
use volray_distributed::streamed::{StreamError, Streamed};
use volray_io::{FileInfo, IoError, Lazy, LevelInfo, ReadOptions, VolumeFormat};
use volray_options::{LookOptions, OptionError};

/// The most one piece's frame may take (volray-core's bound: the piece
/// read, the renderer's structures for a dense piece, its frame), however
/// much the memory limit allows: larger pieces cut fewer ghost layers and
/// take fewer reads, but past a few hundred megabytes of samples a piece
/// costs memory and buys nothing. A 1 GiB bound holds a 2 byte piece of
/// about 300³ voxels.
pub const PIECE_BUDGET: u64 = 1 << 30;

/// A chunked file, opened at one level (and time point and channel)
/// without reading a sample.
pub struct Chunked {
    path: PathBuf,
    opts: ReadOptions,
    lazy: Lazy,
}

/// How a level is rendered for frames of given settings.
pub enum Plan {
    /// Its frame fits the memory limit: read the level whole (`need`
    /// bytes at most, the volume included), as any file is.
    Whole { level: usize, need: u128 },
    /// Its frame would take `need` bytes whole, over the limit: rendered
    /// piece by piece, never read whole.
    Pieces {
        level: usize,
        need: u128,
        streamed: Box<Streamed>,
    },
}

impl Chunked {
    /// Opens `path` from its metadata at the level, time point and channel
    /// `opts` names (level 0 unless `opts.level` says). `Ok(None)` for a
    /// file not stored in chunks, which `volray_io::read` reads whole or
    /// maps.
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Option<Chunked>, IoError> {
        Ok(volray_io::open_lazy(path, opts)?.map(|lazy| Chunked {
            path: path.to_path_buf(),
            opts: opts.clone(),
            lazy,
        }))
    }

    /// Every level of the image, finest first (one for a bare array).
    pub fn levels(&self) -> &[LevelInfo] {
        &self.lazy.info.levels
    }

    /// The level open, 0 the finest.
    pub fn level(&self) -> usize {
        self.lazy.info.level
    }

    /// What the metadata says of the level open.
    pub fn info(&self) -> &FileInfo {
        &self.lazy.info
    }

    /// The level open, as a source of boxes.
    pub fn source(&self) -> &Arc<dyn VolumeSource> {
        &self.lazy.source
    }

    /// The read options that open this level: `volray_io::read` with them
    /// reads it whole.
    pub fn read_options(&self) -> ReadOptions {
        ReadOptions {
            level: Some(self.level()),
            ..self.opts.clone()
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's format.
    pub fn format(&self) -> VolumeFormat {
        self.lazy.format
    }

    /// The same file opened again at level `level` (the same time point
    /// and channel), from its metadata; `self` stays open.
    pub fn open_level(&self, level: usize) -> Result<Chunked, IoError> {
        let opts = ReadOptions {
            level: Some(level),
            ..self.opts.clone()
        };
        Chunked::open(&self.path, &opts)?
            .ok_or_else(|| IoError::invalid(&self.path, "the store changed while it was open"))
    }

    /// The same level, its boxes refused with [`STOPPED`] once `stop` is
    /// set: a [`Streamed`] frame of it stops before its next piece, the
    /// pieces already read kept. A frame's own stop flag
    /// ([`FrameRequest::stopped_by`](volray_core::FrameRequest::stopped_by))
    /// stops it too, within a brick; this also stops the passes over the
    /// pieces outside a frame (histograms, labels), a piece being the
    /// unit they read.
    pub fn stoppable(mut self, stop: Arc<AtomicBool>) -> Chunked {
        let inner = Arc::clone(&self.lazy.source);
        self.lazy.source = Arc::new(Stoppable { inner, stop });
        self
    }

    /// The level open, its source and metadata.
    pub fn into_lazy(self) -> Lazy {
        self.lazy
    }

    /// The level a frame of `settings` needs (volray-options'
    /// [`auto_level`](volray_options::level::auto_level): the coarsest
    /// whose voxels are no larger than a pixel's footprint), the view
    /// framed on the finest level's box. An error only where the camera
    /// cannot frame that box.
    pub fn auto_level(&self, settings: &RenderSettings) -> Result<usize, CameraError> {
        let levels = self.levels();
        let Some(finest) = levels.first() else {
            return Ok(0);
        };
        let spacings: Vec<DVec3> = levels.iter().map(|l| DVec3::from(l.spacing)).collect();
        let origin = DVec3::from(finest.origin);
        let span = DVec3::from(finest.dims.map(|n| n.saturating_sub(1) as f64));
        let bounds = (origin, origin + span * DVec3::from(finest.spacing));
        volray_options::level::auto_level(&spacings, bounds, settings)
    }

    /// The same file at level `level`: itself if that level is open,
    /// else reopened from the metadata.
    pub fn at_level(self, level: usize) -> Result<Chunked, IoError> {
        if level == self.level() {
            return Ok(self);
        }
        self.open_level(level)
    }

    /// The most bytes a frame of `settings` may take with the level read
    /// whole, the volume included (volray-core's [`MemoryBound`], no
    /// brick cache).
    pub fn whole_bytes(&self, settings: &RenderSettings, non_finite: NonFinite) -> u128 {
        let grid = self.source().grid();
        MemoryBound::new(
            grid.dims,
            grid.spacing,
            self.source().sample_type(),
            settings,
            non_finite,
            0,
        )
        .total()
    }

    /// How frames of `settings` render the level under `max_memory`:
    /// whole when [`whole_bytes`](Self::whole_bytes) plus the front end's
    /// `extra` (say, a 16-bit PNG's buffer) fits in one piece's budget,
    /// min(`max_memory`, [`PIECE_BUDGET`]), else in pieces of at most that.
    ///
    /// Not "whole whenever it fits `max_memory`": a level that takes more
    /// than a piece is lighter in pieces (their frames never take more
    /// than a piece's budget), and was faster too. The 2048³ OME-Zarr
    /// pyramid's 1024² image at `--level auto` took 37.3 s and 3.27 GiB
    /// read whole under the default limit, and 8.3 s and 0.62 GiB in
    /// pieces of this same budget when `--max-memory 1.5G` forced them
    /// (issue 41's measurement, before this rule made pieces the default
    /// there; not measured again since).
    pub fn plan(
        &self,
        settings: &RenderSettings,
        non_finite: NonFinite,
        max_memory: u64,
        extra: u128,
    ) -> Plan {
        let level = self.level();
        let need = self.whole_bytes(settings, non_finite) + extra;
        if need <= u128::from(max_memory.min(PIECE_BUDGET)) {
            return Plan::Whole { level, need };
        }
        let budget = max_memory.min(PIECE_BUDGET);
        let streamed = Streamed::new(Arc::clone(self.source()), non_finite, budget);
        Plan::Pieces {
            level,
            need,
            streamed: Box::new(streamed),
        }
    }

    /// [`plan`](Self::plan) for the log10 of the level's values (`--log`):
    /// whole when [`whole_log_bytes`](Self::whole_log_bytes) plus `extra`
    /// fits, else [`log_pieces`](Self::log_pieces).
    pub fn plan_log(
        &self,
        settings: &RenderSettings,
        non_finite: NonFinite,
        max_memory: u64,
        extra: u128,
    ) -> Result<Plan, SourceError> {
        let level = self.level();
        let need = self.whole_log_bytes(settings, non_finite) + extra;
        if need <= u128::from(max_memory.min(PIECE_BUDGET)) {
            return Ok(Plan::Whole { level, need });
        }
        Ok(Plan::Pieces {
            level,
            need,
            streamed: Box::new(self.log_pieces(non_finite, max_memory)?),
        })
    }

    /// [`whole_bytes`](Self::whole_bytes) for the log10 of the level read
    /// whole: its `f32` log, and its samples beside it while it converts.
    pub fn whole_log_bytes(&self, settings: &RenderSettings, non_finite: NonFinite) -> u128 {
        let grid = self.source().grid();
        let voxels: u128 = grid.dims.iter().map(|&n| n as u128).product();
        let log = MemoryBound::new(
            grid.dims,
            grid.spacing,
            SampleType::F32,
            settings,
            non_finite,
            0,
        );
        log.total() + voxels * self.source().voxel_bytes() as u128
    }

    /// The level's log10 rendered in pieces: a pass over the level for
    /// its smallest positive value (in slabs of at most min(`max_memory`,
    /// [`PIECE_BUDGET`])), then each piece read through [`Log10Source`],
    /// which holds a piece's samples, their `f32` copy and their log at
    /// once: at most 2.5 times the `f32` piece the pieces' bound counts,
    /// so the pieces get a third of the budget.
    pub fn log_pieces(
        &self,
        non_finite: NonFinite,
        max_memory: u64,
    ) -> Result<Streamed, SourceError> {
        let budget = max_memory.min(PIECE_BUDGET);
        let source = Log10Source::over(Arc::clone(self.source()), budget)?;
        Ok(Streamed::new(Arc::new(source), non_finite, budget / 3))
    }
}

/// The message of a box read once the stop flag of [`Chunked::stoppable`]
/// is set (a [`StreamError::Read`] of kind
/// [`SourceErrorKind::Stopped`]).
pub const STOPPED: &str = "stopped";

/// A source whose reads fail with [`STOPPED`] once `stop` is set.
struct Stoppable {
    inner: Arc<dyn VolumeSource>,
    stop: Arc<AtomicBool>,
}

impl VolumeSource for Stoppable {
    fn grid(&self) -> GridFrame {
        self.inner.grid()
    }

    fn sample_type(&self) -> SampleType {
        self.inner.sample_type()
    }

    fn is_labels(&self) -> bool {
        self.inner.is_labels()
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        if self.stop.load(Ordering::Relaxed) {
            return Err(SourceError::new(SourceErrorKind::Stopped, STOPPED));
        }
        self.inner.read_box(lo, hi)
    }

    fn voxel_bytes(&self) -> usize {
        self.inner.voxel_bytes()
    }
}

/// Why the look of a frame in pieces could not be completed.
#[derive(Debug)]
pub enum LookError {
    /// A piece could not be read, or the pieces do not fit.
    Stream(StreamError),
    /// The options refuse what was found (`--labels` on a volume of more
    /// than [`MAX_LABELS`] values, `--tf auto` with labels, ...).
    Refused(OptionError),
}

/// What the look of a frame leaves to the volume, found piece by piece
/// over a [`Streamed`] level and kept for the frames after: the distinct
/// labels (`--labels`) or the histogram `--tf auto` chooses from. Both
/// are the whole level's, the same as one process finds in the level read
/// whole (volray-distributed's `Streamed::labels` and
/// `Streamed::histogram`); keep one per `Streamed`.
#[derive(Debug, Default, Clone)]
pub struct Found {
    labels: Option<Vec<i64>>,
    histogram: Option<Option<Histogram>>,
    robust: Option<Option<Robust>>,
}

impl Found {
    /// The level's histogram in [`auto::BINS`] bins over its finite
    /// values, found once (every piece read); `None` for a level with no
    /// finite value. The pieces are those of frames of `settings`.
    pub fn histogram(
        &mut self,
        streamed: &mut Streamed,
        settings: &RenderSettings,
    ) -> Result<Option<&Histogram>, StreamError> {
        if self.histogram.is_none() {
            self.histogram = Some(streamed.histogram(settings, auto::BINS)?);
        }
        Ok(self.histogram.as_ref().and_then(Option::as_ref))
    }

    /// The level's histogram made robust to outliers (volray-core's
    /// [`auto::robust_histogram`]), found once: each refining pass reads
    /// every piece again. `None` for a level with no finite value.
    pub fn robust(
        &mut self,
        streamed: &mut Streamed,
        settings: &RenderSettings,
    ) -> Result<Option<&Robust>, StreamError> {
        if self.robust.is_none() {
            let robust = match self.histogram(streamed, settings)? {
                None => None,
                Some(first) => Some(auto::robust_histogram(first.clone(), |window| {
                    streamed.histogram_in(settings, Some(window), auto::BINS)
                })?),
            };
            self.robust = Some(robust);
        }
        Ok(self.robust.as_ref().and_then(Option::as_ref))
    }

    /// The level's distinct labels, sorted, found once; refused (naming
    /// the volume `name`) where it holds more than [`MAX_LABELS`].
    pub fn labels(
        &mut self,
        streamed: &mut Streamed,
        settings: &RenderSettings,
        name: &str,
    ) -> Result<&[i64], LookError> {
        if self.labels.is_none() {
            let found = streamed
                .labels(settings, MAX_LABELS)
                .map_err(LookError::Stream)?;
            let found = volray_options::labels_found(found, name).map_err(LookError::Refused)?;
            self.labels = Some(found);
        }
        Ok(self.labels.as_deref().unwrap_or_default())
    }

    /// `settings` completed as `look` leaves to the volume `name`, as
    /// volray-options' `from_volume` completes them for a volume in
    /// memory: the label transfer function from the labels found
    /// (`look.labels`), or the automatic one from the histogram
    /// (`look.auto_tf()`).
    pub fn apply(
        &mut self,
        streamed: &mut Streamed,
        look: &LookOptions,
        settings: &mut RenderSettings,
        name: &str,
    ) -> Result<(), LookError> {
        if look.labels {
            let found = self.labels(streamed, settings, name)?;
            return volray_options::label_transfer_function(
                look,
                &mut settings.transfer_function,
                found,
                name,
            )
            .map_err(LookError::Refused);
        }
        if look.auto_tf()
            && let Some(robust) = self.robust(streamed, settings).map_err(LookError::Stream)?
        {
            volray_options::apply_auto(look, &mut settings.transfer_function, robust);
        }
        Ok(())
    }
}
