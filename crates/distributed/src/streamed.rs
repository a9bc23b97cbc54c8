//! Out-of-core rendering: a volume larger than memory rendered piece by
//! piece, in one process, each piece read from its source when a frame
//! needs it and dropped after: sort-last rendering with the pieces taking
//! turns instead of ranks, as ParaView's streaming and VisIt's
//! "piece-by-piece" out-of-core modes do.
//!
//! A frame runs in this order:
//!
//! 1. **Pieces.** The grid is split by the same k-d split as the ranks'
//!    ([`crate::kd`]) into the fewest boxes whose frame, with its ghost
//!    layers, fits the memory budget by volray-core's own bound
//!    ([`MemoryBound`]), beside the two partial images being composited.
//!    The split only ever gets finer (a larger frame may need more
//!    pieces), so what is known of each piece stays true.
//! 2. **Statistics, when the frame needs them.** The whole volume's value
//!    range (the transfer function's domain when it names none, and a
//!    projection's colour map) and its largest gradient (iso-surfaces,
//!    gradient opacity) are exact: the pieces not yet seen are read once
//!    for them, in a pass that keeps nothing but each piece's range and
//!    largest gradient. A transfer function with its own domain (every
//!    preset, any JSON with a `domain`) needs neither, and the first frame
//!    reads each piece once.
//! 3. **Pieces in visibility order.** The pieces are taken front to back
//!    ([`Decomposition::front_to_back`]). A piece is not read at all when
//!    its value range, known from an earlier read, is transparent under
//!    the frame's classifier (the zero-opacity test of empty-space
//!    skipping, applied per piece), or when every pixel its box covers is
//!    already opaque (transmittance below the early ray termination's
//!    1/1024: what it adds is below what one ray drops when it stops).
//! 4. Each piece read is rendered as a rank's piece ([`Piece`]: the whole
//!    volume's camera, sample planes and statistics), and its partial
//!    image composited behind the ones before it. The frame is the same
//!    as one process would render, within early termination's 1/1024 per
//!    piece boundary, as across ranks.
//!
//! A volume that fits in one piece is read once and its renderer kept
//! across frames, exactly as rendering it whole.
//!
//! A frame is asked for as any renderer's ([`Render::render`]): its stop
//! flag is checked before each piece is read (for the statistics pass
//! too) and, passed on to each piece's frame, by volray-core's casters
//! before each tile (each brick on the bricked path), so a frame stops
//! within one brick's time, not one piece's; a partial frame is the
//! pieces' partial images combined, before the background.
//!
//! ```
//! use std::sync::Arc;
//! use volray_core::glam::DVec3;
//! use volray_core::{FrameRequest, NonFinite, Render, RenderSettings, Volume};
//! use volray_distributed::streamed::Streamed;
//!
//! let volume = Volume::from_fn([40; 3], DVec3::ONE, DVec3::ZERO, |p| p.x as f32).unwrap();
//! let settings = RenderSettings { width: 32, height: 32, ..RenderSettings::default() };
//! // A budget of 200 kB: the 40³ volume (256 kB) is rendered in several pieces.
//! let streamed = Streamed::new(Arc::new(volume), NonFinite::Refuse, 200_000);
//! let (image, times) = streamed.render(FrameRequest::new(&settings)).unwrap().image_and_times();
//! assert!(times.pieces > 1 && times.read_pieces <= times.pieces);
//! assert_eq!((image.width(), image.height()), (32, 32));
//! ```

use crate::frame::{blank, owned_max_gradient};
use crate::kd::{Decomposition, Viewpoint, VoxelBox};
use std::sync::Arc;
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};
use thiserror::Error;
use volray_core::camera::View;
use volray_core::kernels::composite::TERMINATION_TRANSMITTANCE;
use volray_core::sampling::grid::GridFrame;
use volray_core::transfer::classifier::Classifier;
use volray_core::transfer::labels::{LabelError, labels_of};
use volray_core::{
    Blend, DEFAULT_CACHE_BUDGET, FrameRequest, Histogram, MemoryBound, NonFinite, PartialImage,
    PartialPixels, Picture, Piece, Progress, Render, RenderError, RenderSettings, Rendered,
    Renderer, SourceError, Volume, VolumeSource,
};

/// Why a streamed frame failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StreamError {
    /// A piece could not be read: the source's one-line message, and
    /// whether the data or the system was at fault.
    #[error("{0}")]
    Read(SourceError),
    /// Even the smallest pieces do not fit the memory budget.
    #[error("{0}")]
    TooLarge(String),
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// Where a streamed frame's time went, and how much of the volume it read.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StreamTimes {
    /// Pieces the grid is split into.
    pub pieces: usize,
    /// Pieces read for this frame (the others were transparent, hidden,
    /// or kept from an earlier frame).
    pub read_pieces: usize,
    /// Voxels read for this frame (ghost layers included).
    pub read_voxels: u64,
    /// Pieces read beforehand for the statistics the frame needed.
    pub statistics_pieces: usize,
    pub read: Duration,
    pub render: Duration,
}

/// What is known of one piece from having read it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Known {
    /// `Some(None)`: read, and no finite value.
    range: Option<Option<(f32, f32)>>,
    max_gradient: Option<f32>,
}

/// A volume rendered piece by piece from its source (see the module
/// documentation).
pub struct Streamed {
    source: Arc<dyn VolumeSource>,
    grid: GridFrame,
    non_finite: NonFinite,
    budget: u64,
    /// What frames learn and keep: locked for a frame (frames of one
    /// `Streamed` are rendered one at a time, as a `Renderer`'s are).
    state: Mutex<Pieces>,
    /// Whether the pieces are read as labels.
    labels: bool,
}

/// The pieces of a [`Streamed`] volume and what is known of them.
struct Pieces {
    decomposition: Decomposition,
    known: Vec<Known>,
    /// The renderer of the one piece, when the whole volume fits in one.
    whole: Option<Renderer<'static>>,
}

impl Pieces {
    /// The number of pieces the grid is split into.
    fn count(&self) -> usize {
        self.decomposition.boxes.len()
    }

    /// The whole volume's value range over the pieces read so far.
    fn value_range(&self) -> Option<(f32, f32)> {
        if let Some(r) = &self.whole {
            return r.volume().value_range();
        }
        self.known
            .iter()
            .filter_map(|k| k.range.flatten())
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
    }

    fn max_gradient(&self) -> Option<f32> {
        if let Some(r) = &self.whole {
            return Some(r.max_gradient());
        }
        self.known
            .iter()
            .filter_map(|k| k.max_gradient)
            .reduce(f32::max)
    }
}

impl Streamed {
    /// Renders `source` in pieces that each fit `budget` bytes (the volume
    /// read, the renderer's structures and the frames); its non-finite
    /// values are handled as `non_finite` says. Reads nothing yet.
    pub fn new(source: Arc<dyn VolumeSource>, non_finite: NonFinite, budget: u64) -> Self {
        let grid = source.grid();
        let labels = source.is_labels();
        Streamed {
            state: Mutex::new(Pieces {
                decomposition: Decomposition::new(grid.dims, 1),
                known: vec![Known::default()],
                whole: None,
            }),
            source,
            grid,
            non_finite,
            budget,
            labels,
        }
    }

    /// The same, its values read as labels (a segmentation) or not.
    pub fn with_labels(mut self, labels: bool) -> Self {
        self.labels = labels;
        self.lock().whole = None;
        self
    }

    /// The whole volume's grid.
    pub fn grid(&self) -> GridFrame {
        self.grid
    }

    /// The source the pieces are read from.
    pub fn source(&self) -> &Arc<dyn VolumeSource> {
        &self.source
    }

    /// The number of pieces the grid is split into now.
    pub fn pieces(&self) -> usize {
        self.lock().count()
    }

    /// The pieces, locked (a frame that panicked left them as they were
    /// between two steps, each of which keeps them true).
    fn lock(&self) -> MutexGuard<'_, Pieces> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The whole volume's value range over the pieces read so far: exact
    /// once every piece has been read (the first frame that needed it).
    pub fn value_range(&self) -> Option<(f32, f32)> {
        self.lock().value_range()
    }

    /// The whole volume's histogram in `bins` bins over its value range
    /// (what `--tf auto` chooses from), counted piece by piece over each
    /// piece's owned voxels: the same counts as in one process. Reads every
    /// piece (twice the first time: once for the range). `None` for a
    /// volume with no finite value.
    /// The pieces are those of frames of `settings` (histograms come
    /// before the frame whose transfer function they choose).
    pub fn histogram(
        &self,
        settings: &RenderSettings,
        bins: usize,
    ) -> Result<Option<Histogram>, StreamError> {
        self.histogram_in(settings, None, bins)
    }

    /// [`Self::histogram`] over `window` (`None`: the value range), the
    /// values outside it counted in the end bins (volray-core's
    /// `auto::robust_histogram` passes: each reads every piece again).
    pub fn histogram_in(
        &self,
        settings: &RenderSettings,
        window: Option<(f32, f32)>,
        bins: usize,
    ) -> Result<Option<Histogram>, StreamError> {
        let pieces = &mut *self.lock();
        self.split_for(pieces, settings)?;
        self.keep_whole(pieces)?;
        if let Some(r) = &pieces.whole {
            let volume = r.volume();
            return Ok(match window {
                None => Histogram::of(volume, bins),
                Some(w) => volume
                    .value_range()
                    .map(|_| Histogram::of_box(volume, ([0; 3], volume.dims()), w, bins)),
            });
        }
        self.learn(pieces, true, false, &Progress::new(&|_| {}))?;
        let Some(range) = pieces.value_range() else {
            return Ok(None);
        };
        let range = window.unwrap_or(range);
        let mut whole: Option<Histogram> = None;
        for owned in pieces.decomposition.boxes.clone() {
            if owned.is_empty() {
                continue;
            }
            let volume = self.read(owned.lo, owned.hi)?;
            let part = Histogram::of_box(&volume, ([0; 3], volume.dims()), range, bins);
            match &mut whole {
                Some(h) => h.merge(&part),
                None => whole = Some(part),
            }
        }
        Ok(whole)
    }

    /// The distinct labels of the whole volume, sorted, as
    /// [`labels_of`] finds them in one volume: found piece by piece over
    /// each piece's owned voxels (the pieces tile the grid) and joined.
    /// `Ok(None)` for more than `max` distinct values.
    /// The pieces are those of frames of `settings`.
    pub fn labels(
        &self,
        settings: &RenderSettings,
        max: usize,
    ) -> Result<Result<Option<Vec<i64>>, LabelError>, StreamError> {
        let pieces = &mut *self.lock();
        self.split_for(pieces, settings)?;
        self.keep_whole(pieces)?;
        if let Some(r) = &pieces.whole {
            return Ok(labels_of(r.volume(), max));
        }
        let mut union = std::collections::BTreeSet::new();
        for owned in pieces.decomposition.boxes.clone() {
            if owned.is_empty() {
                continue;
            }
            let volume = self.read(owned.lo, owned.hi)?;
            match labels_of(&volume, max) {
                Ok(Some(found)) => union.extend(found),
                Ok(None) => return Ok(Ok(None)),
                Err(e) => return Ok(Err(e)),
            }
            if union.len() > max {
                return Ok(Ok(None));
            }
        }
        Ok(Ok(Some(union.into_iter().collect())))
    }

    /// With one piece, reads it (once) and keeps its renderer.
    fn keep_whole(&self, pieces: &mut Pieces) -> Result<(), StreamError> {
        if pieces.count() == 1 && pieces.whole.is_none() {
            let volume = self.read([0; 3], self.grid.dims)?;
            pieces.whole = Some(Renderer::owning(volume, self.non_finite)?);
        }
        Ok(())
    }

    /// The voxels `lo..hi` of the source, marked as labels when they are.
    fn read(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, StreamError> {
        let mut volume = self.source.read_box(lo, hi).map_err(StreamError::Read)?;
        volume.set_labels(self.labels);
        Ok(volume)
    }

    /// Reads the pieces whose value range (and largest gradient, if
    /// `gradient`) is not known yet, keeping only those: the number read.
    /// Stopped before a piece is read when `progress` says so.
    fn learn(
        &self,
        pieces: &mut Pieces,
        range: bool,
        gradient: bool,
        progress: &Progress,
    ) -> Result<usize, StreamError> {
        let mut read = 0;
        for (index, owned) in pieces.decomposition.boxes.clone().into_iter().enumerate() {
            let known = pieces.known[index];
            let missing =
                (range && known.range.is_none()) || (gradient && known.max_gradient.is_none());
            if owned.is_empty() || !missing {
                continue;
            }
            if progress.stopped() {
                return Err(StreamError::Render(RenderError::Stopped));
            }
            let (lo, hi) = Piece::held((owned.lo, owned.hi), self.grid.dims);
            let volume = self.read(lo, hi)?;
            read += 1;
            let renderer = Renderer::owning(volume, self.non_finite)?;
            let volume = renderer.volume();
            pieces.known[index].range = Some(volume.value_range());
            if gradient {
                pieces.known[index].max_gradient =
                    Some(owned_max_gradient(volume, lo, (owned.lo, owned.hi)));
            }
        }
        Ok(read)
    }

    /// A frame of the whole volume as one piece: read once, its renderer
    /// kept; `request` goes to it as it is.
    fn render_whole(
        &self,
        pieces: &mut Pieces,
        request: FrameRequest<'_>,
        cache: usize,
        mut times: StreamTimes,
    ) -> Result<Rendered<StreamTimes>, StreamError> {
        if pieces.whole.is_none() {
            let start = Instant::now();
            self.keep_whole(pieces)?;
            times.read_pieces = 1;
            times.read_voxels = self.grid.dims.iter().map(|&n| n as u64).product();
            times.read = start.elapsed();
        }
        let renderer = pieces
            .whole
            .take()
            .expect("read above")
            .with_cache_budget(cache);
        let start = Instant::now();
        let rendered = renderer.render(request);
        pieces.whole = Some(renderer);
        times.render = start.elapsed();
        let picture = rendered?.picture;
        Ok(Rendered { picture, times })
    }

    /// Splits the grid finely enough for a frame of `settings` to fit the
    /// budget, and gives the brick caches' budget: what is left, up to
    /// the renderer's default.
    fn split_for(
        &self,
        pieces: &mut Pieces,
        settings: &RenderSettings,
    ) -> Result<usize, StreamError> {
        let mut n = pieces.count();
        loop {
            let bound = self.bound(n, settings);
            if bound <= u128::from(self.budget) {
                if n != pieces.count() {
                    pieces.decomposition = Decomposition::new(self.grid.dims, n);
                    pieces.known = vec![Known::default(); n];
                    pieces.whole = None;
                }
                let room = u128::from(self.budget) - bound;
                return Ok(usize::try_from(room)
                    .map_or(DEFAULT_CACHE_BUDGET, |r| r.min(DEFAULT_CACHE_BUDGET)));
            }
            let largest = largest_held(&Decomposition::new(self.grid.dims, n), self.grid.dims);
            if largest.iter().all(|&s| s <= 16) {
                let [x, y, z] = self.grid.dims;
                return Err(StreamError::TooLarge(format!(
                    "a frame of {}x{} pixels of the {x}x{y}x{z} grid does not fit {} bytes even in pieces of 16³ voxels",
                    settings.width, settings.height, self.budget
                )));
            }
            n = (n * 2).max(2);
        }
    }

    /// The bound on a frame rendered in `n` pieces: the largest piece's
    /// frame (no brick cache), plus the partial image of the pieces before
    /// it when there are several.
    fn bound(&self, n: usize, settings: &RenderSettings) -> u128 {
        let held = largest_held(&Decomposition::new(self.grid.dims, n), self.grid.dims);
        let sample = self.source.sample_type();
        let piece = MemoryBound::new(
            held,
            self.grid.spacing,
            sample,
            settings,
            self.non_finite,
            0,
        );
        let front = if n > 1 { piece.frame } else { 0 };
        piece.total() + front
    }
}

impl Render for Streamed {
    type Settings = RenderSettings;
    type Times = StreamTimes;
    type Error = StreamError;

    /// One frame, piece by piece (see the module documentation): finished
    /// or partial, and where its time went; `progress` hears of pixels
    /// finished within each piece's frame. What was learnt of the pieces
    /// read is kept, for a stopped frame too.
    fn render(&self, request: FrameRequest<'_>) -> Result<Rendered<StreamTimes>, StreamError> {
        let pieces = &mut *self.lock();
        let (settings, progress) = (request.settings(), request.progress());
        let stopped = || -> Result<(), StreamError> {
            if progress.stopped() {
                Err(StreamError::Render(RenderError::Stopped))
            } else {
                Ok(())
            }
        };
        settings.validate().map_err(RenderError::from)?;
        let cache = self.split_for(pieces, settings)?;
        let mut times = StreamTimes {
            pieces: pieces.count(),
            ..StreamTimes::default()
        };
        if pieces.count() == 1 {
            return self.render_whole(pieces, request, cache, times);
        }
        let needs_range =
            settings.blend.is_projection() || settings.transfer_function.domain.is_none();
        let needs_gradient = settings.iso.is_some()
            || (settings.gradient_opacity.is_some() && settings.gradient_opacity_max.is_none());
        let start = Instant::now();
        if needs_range || needs_gradient {
            times.statistics_pieces = self.learn(pieces, needs_range, needs_gradient, &progress)?;
        }
        times.read += start.elapsed();
        let value_range = pieces.value_range().unwrap_or((0.0, 0.0));
        let max_gradient = pieces.max_gradient().unwrap_or(0.0);
        let voxel_size = self.grid.spacing.min_element() as f32;
        let classifier = Classifier::for_frame(settings, value_range, voxel_size, || max_gradient);

        let view = View::frame(
            &settings.camera,
            self.grid.bounds(),
            settings.width,
            settings.height,
        )
        .map_err(RenderError::from)?;
        let viewpoint = Viewpoint::of(&view);
        let mut image: Option<PartialImage> = None;
        for index in pieces.decomposition.front_to_back(&viewpoint, &self.grid) {
            let owned = pieces.decomposition.boxes[index];
            if owned.is_empty() {
                continue;
            }
            let composite = settings.blend == Blend::Composite;
            if let Some(Some((lo, hi))) = pieces.known[index].range
                && composite
                && classifier.is_transparent_between(lo, hi)
            {
                continue;
            }
            if composite
                && let Some(image) = &image
                && hidden(image, &view, &self.grid, owned)
            {
                continue;
            }
            stopped()?;
            let start = Instant::now();
            let (lo, hi) = Piece::held((owned.lo, owned.hi), self.grid.dims);
            let volume = self.read(lo, hi)?;
            times.read_pieces += 1;
            times.read_voxels += volume.len() as u64;
            let renderer = Renderer::owning(volume, self.non_finite)?.with_cache_budget(cache);
            pieces.known[index].range = Some(renderer.volume().value_range());
            times.read += start.elapsed();
            let start = Instant::now();
            let piece = RenderSettings {
                piece: Some(Piece {
                    whole: self.grid,
                    offset: lo,
                    owned: (owned.lo, owned.hi),
                    value_range,
                    max_gradient,
                }),
                ..settings.clone()
            };
            // The stop flag goes with it: a piece stops within a brick.
            let partial = renderer.render(request.for_part(&piece).partial())?;
            let partial = partial.partial();
            stopped()?;
            image = Some(match image {
                None => partial,
                Some(mut front) => {
                    front.combine(&partial);
                    front
                }
            });
            times.render += start.elapsed();
        }
        let image = image.unwrap_or_else(|| blank(settings));
        let picture = match request.wants_partial() {
            true => Picture::Partial(image),
            false => Picture::Image(
                image.finish(settings.background, |f| classifier.projection_colour(f)),
            ),
        };
        Ok(request.answer(Rendered { picture, times })?)
    }
}

/// The dimensions of the largest box held (with ghost layers) among the
/// boxes of `d`.
fn largest_held(d: &Decomposition, dims: [usize; 3]) -> [usize; 3] {
    d.boxes
        .iter()
        .filter(|b| !b.is_empty())
        .map(|b| {
            let (lo, hi) = Piece::held((b.lo, b.hi), dims);
            std::array::from_fn(|a| hi[a] - lo[a])
        })
        .max_by_key(|s: &[usize; 3]| s.iter().product::<usize>())
        .unwrap_or([2; 3])
}

/// Whether every pixel that `owned`'s box can cover is already opaque in
/// `image` (transmittance below early ray termination's): nothing of the
/// piece behind could show. The box's corners are projected, and the
/// rectangle around them widened by a pixel.
fn hidden(image: &PartialImage, view: &View, grid: &GridFrame, owned: VoxelBox) -> bool {
    let PartialPixels::Composite(pixels) = image.pixels() else {
        return false;
    };
    let (w, h) = (image.width(), image.height());
    let corner = |c: usize| {
        let p = std::array::from_fn::<f64, 3, _>(|a| {
            // The owned box reaches to its last voxel's cell's far side.
            let i = if c >> a & 1 == 0 {
                owned.lo[a]
            } else {
                owned.hi[a].min(grid.dims[a] - 1)
            };
            grid.origin[a] + i as f64 * grid.spacing[a]
        });
        view.project(p.into())
    };
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for c in 0..8 {
        // A corner behind a perspective eye: the box may cover anything.
        let Some((x, y)) = corner(c) else {
            return false;
        };
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    let clamp = |v: f64, n: usize| v.max(0.0).min(n as f64) as usize;
    let (c0, c1) = (clamp(x0.floor() - 1.0, w), clamp(x1.ceil() + 1.0, w));
    let (r0, r1) = (clamp(y0.floor() - 1.0, h), clamp(y1.ceil() + 1.0, h));
    (r0..r1).all(|r| (c0..c1).all(|c| pixels[r * w + c][3] < TERMINATION_TRANSMITTANCE))
}
