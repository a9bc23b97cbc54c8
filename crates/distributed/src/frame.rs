//! One distributed frame, as every rank runs it: split, read the piece,
//! agree on the whole volume's statistics, render the piece, composite.
//!
//! Every step that can fail on one rank (reading, rendering) ends with
//! every rank learning every rank's outcome ([`Transport::all_gather`]),
//! so that a failure on one rank stops them all with the same error,
//! and none waits forever on a rank that has given up.

use crate::compose::{ComposeError, ComposeStats, composite};
use crate::kd::{Decomposition, Viewpoint};
use crate::schedule::Plan;
use crate::transport::{Transport, TransportError};
use std::time::{Duration, Instant};
use thiserror::Error;
use volray_core::camera::View;
use volray_core::kernels::gradient::{Differences, magnitude};
use volray_core::sampling::grid::GridFrame;
use volray_core::transfer::labels::{LabelError, labels_of};
use volray_core::{
    FrameRequest, Histogram, Image, NonFinite, PartialImage, Piece, Render, RenderError,
    RenderSettings, Renderer, SourceError, Volume, with_samples,
};

/// Where a rank's piece comes from: volray-core's one interface to
/// voxels, box by box (a volume in memory, a mapped file, a chunked
/// store).
pub use volray_core::VolumeSource as Source;

/// Why a distributed frame failed: the same on every rank.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FrameError {
    /// A rank failed (the lowest-numbered rank that did), with its
    /// message, and whether its input was at fault ([`Failure`]).
    #[error("rank {rank}: {message}")]
    Rank {
        rank: usize,
        message: String,
        bad_input: bool,
    },
    /// Rendering refused the settings (every rank refuses alike).
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error(transparent)]
    Transport(#[from] TransportError),
    #[error(transparent)]
    Compose(#[from] ComposeError),
}

/// Where one rank's time went, and what it held.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RankTimes {
    pub read: Duration,
    /// Agreeing on the value range (and largest gradient).
    pub agree: Duration,
    pub classify: Duration,
    pub cast: Duration,
    pub compose: ComposeStats,
    /// Voxels this rank owns and holds (its box with its ghost layers).
    pub owned_voxels: usize,
    pub held_voxels: usize,
}

impl RankTimes {
    const FIELDS: usize = 10;

    fn to_bytes(self) -> Vec<u8> {
        let c = self.compose;
        [
            self.read.as_secs_f64(),
            self.agree.as_secs_f64(),
            self.classify.as_secs_f64(),
            self.cast.as_secs_f64(),
            c.composite.as_secs_f64(),
            c.gather.as_secs_f64(),
            c.bytes_sent as f64,
            c.rounds as f64,
            self.owned_voxels as f64,
            self.held_voxels as f64,
        ]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
    }

    fn from_bytes(b: &[u8]) -> Option<RankTimes> {
        if b.len() != 8 * Self::FIELDS {
            return None;
        }
        let v = |i: usize| f64::from_le_bytes(b[8 * i..8 * i + 8].try_into().unwrap());
        let d = |i: usize| Duration::from_secs_f64(v(i).max(0.0));
        Some(RankTimes {
            read: d(0),
            agree: d(1),
            classify: d(2),
            cast: d(3),
            compose: ComposeStats {
                composite: d(4),
                gather: d(5),
                bytes_sent: v(6) as usize,
                messages: 0,
                rounds: v(7) as usize,
            },
            owned_voxels: v(8) as usize,
            held_voxels: v(9) as usize,
        })
    }
}

/// A rank's piece, read: what it renders with.
pub struct Held {
    pub renderer: Option<Renderer<'static>>,
    pub piece_owned: ([usize; 3], [usize; 3]),
    pub offset: [usize; 3],
    /// Value range and largest gradient over what this rank holds.
    value_range: Option<(f32, f32)>,
    max_gradient: f32,
    pub times: RankTimes,
}

/// One rank's part of distributed rendering of one volume: reads its piece
/// once, then renders frames.
pub struct Distributed<'t, T: Transport + ?Sized> {
    transport: &'t T,
    grid: GridFrame,
    decomposition: Decomposition,
    plan: Plan,
    held: Held,
    /// The whole volume's value range and largest gradient, agreed.
    value_range: (f32, f32),
    /// Whether any rank found a finite value.
    values_found: bool,
    max_gradient: Option<f32>,
}

/// A rank's failed step, as every rank learns it: what it says, and
/// whether the input was at fault (a corrupt or lying file, refused
/// settings: the command line's exit 1) rather than the system (a read
/// that failed: exit 2). A bare message is the latter.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub message: String,
    pub bad_input: bool,
}

impl Failure {
    /// The input was at fault.
    pub fn bad_input(message: impl Into<String>) -> Self {
        Failure {
            message: message.into(),
            bad_input: true,
        }
    }
}

impl From<String> for Failure {
    fn from(message: String) -> Self {
        Failure {
            message,
            bad_input: false,
        }
    }
}

/// A piece that could not be read: bad input unless the system failed
/// to read it.
impl From<SourceError> for Failure {
    fn from(e: SourceError) -> Self {
        Failure {
            bad_input: !e.is_io_failure(),
            message: e.message,
        }
    }
}

/// The first byte of a rank's status in [`agree`].
const OK: u8 = 0;
const FAILED: u8 = 1;
const BAD_INPUT: u8 = 2;

/// Every rank's outcome of a step (its bytes), or the first failure, on
/// every rank: what each rank does after a step that may fail on one.
pub fn agree<T: Transport + ?Sized, E: Into<Failure>>(
    transport: &T,
    outcome: Result<Vec<u8>, E>,
) -> Result<Vec<Vec<u8>>, FrameError> {
    let message = match outcome.map_err(Into::into) {
        Ok(bytes) => [&[OK][..], &bytes].concat(),
        Err(f) => {
            let status = if f.bad_input { BAD_INPUT } else { FAILED };
            [&[status][..], f.message.as_bytes()].concat()
        }
    };
    let all = transport.all_gather(&message)?;
    let mut out = Vec::with_capacity(all.len());
    for (rank, m) in all.into_iter().enumerate() {
        match m.split_first() {
            Some((&OK, body)) => out.push(body.to_vec()),
            Some((&status, body)) => {
                return Err(FrameError::Rank {
                    rank,
                    message: String::from_utf8_lossy(body).into_owned(),
                    bad_input: status == BAD_INPUT,
                });
            }
            None => {
                return Err(FrameError::Rank {
                    rank,
                    message: "sent an empty status".into(),
                    bad_input: false,
                });
            }
        }
    }
    Ok(out)
}

impl<'t, T: Transport + ?Sized> Distributed<'t, T> {
    /// Splits `source`'s grid among the ranks, reads this rank's piece
    /// (with its ghost layers), and agrees on the value range. Fails on
    /// every rank if any rank's read fails.
    pub fn read(
        transport: &'t T,
        source: &dyn Source,
        non_finite: NonFinite,
    ) -> Result<Self, FrameError> {
        let grid = source.grid();
        let decomposition = Decomposition::new(grid.dims, transport.size());
        let rank = transport.rank();
        let plan = Plan::new(&decomposition, rank);
        let owned_box = decomposition.boxes[rank];
        let owned = (owned_box.lo, owned_box.hi);
        let (lo, hi) = Piece::held(owned, grid.dims);
        let start = Instant::now();
        let read = if owned_box.is_empty() {
            Ok(None)
        } else {
            (source.read_box(lo, hi))
                .map_err(Failure::from)
                .and_then(|v| {
                    (Renderer::owning(v, non_finite))
                        .map_err(|e| Failure::from(format!("its piece: {e}")))
                })
                .map(Some)
        };
        let read_time = start.elapsed();
        let start = Instant::now();
        let local = read.as_ref().map(|r| {
            let range = r.as_ref().and_then(|r| r.volume().value_range());
            match range {
                Some((a, b)) => [1.0, a as f64, b as f64],
                None => [0.0, 0.0, 0.0],
            }
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<u8>>()
        });
        let all = agree(transport, local.map_err(|e| e.clone()))?;
        let renderer = read.expect("agreed: every read succeeded");
        let mut range: Option<(f32, f32)> = None;
        for m in &all {
            let v = |i: usize| f64::from_le_bytes(m[8 * i..8 * i + 8].try_into().unwrap());
            if m.len() == 24 && v(0) == 1.0 {
                let (a, b) = (v(1) as f32, v(2) as f32);
                range = Some(range.map_or((a, b), |(x, y)| (x.min(a), y.max(b))));
            }
        }
        let times = RankTimes {
            read: read_time,
            agree: start.elapsed(),
            owned_voxels: owned_box.voxels(),
            held_voxels: renderer.as_ref().map_or(0, |r| r.volume().len()),
            ..RankTimes::default()
        };
        Ok(Distributed {
            transport,
            grid,
            decomposition,
            plan,
            held: Held {
                value_range: range,
                renderer,
                piece_owned: owned,
                offset: lo,
                max_gradient: 0.0,
                times,
            },
            value_range: range.unwrap_or((0.0, 0.0)),
            values_found: range.is_some(),
            max_gradient: None,
        })
    }

    /// The whole volume's grid.
    pub fn grid(&self) -> GridFrame {
        self.grid
    }

    /// This rank's renderer (none if its box is empty).
    pub fn renderer(&self) -> Option<&Renderer<'static>> {
        self.held.renderer.as_ref()
    }

    /// The whole volume's value range, agreed by the ranks.
    pub fn value_range(&self) -> (f32, f32) {
        self.value_range
    }

    /// The whole volume's largest gradient magnitude: the largest over
    /// every rank's owned voxels (not its ghosts, whose outermost layer
    /// has one-sided differences), found the first time a frame needs it.
    /// This rank's piece is `held` (the volume its renderer holds,
    /// wherever that renderer is now: its own, or a scene's).
    fn max_gradient_of(&mut self, held: Option<&Volume>) -> Result<f32, FrameError> {
        if let Some(g) = self.max_gradient {
            return Ok(g);
        }
        let local = held.map_or(0.0, |v| {
            owned_max_gradient(v, self.held.offset, self.held.piece_owned)
        });
        self.held.max_gradient = local;
        let all = agree(
            self.transport,
            Ok::<_, Failure>(local.to_le_bytes().to_vec()),
        )?;
        let g = (all.iter())
            .filter_map(|m| m.as_slice().try_into().ok().map(f32::from_le_bytes))
            .fold(0.0f32, f32::max);
        self.max_gradient = Some(g);
        Ok(g)
    }

    /// The settings this rank renders its piece with.
    pub fn piece_settings(
        &mut self,
        settings: &RenderSettings,
    ) -> Result<RenderSettings, FrameError> {
        let needs_gradient = settings.iso.is_some() || settings.gradient_opacity.is_some();
        Ok(RenderSettings {
            piece: Some(self.piece(needs_gradient)?),
            ..settings.clone()
        })
    }

    /// This rank's piece of the whole volume, with the whole volume's
    /// largest gradient if `needs_gradient` (agreed across the ranks the
    /// first time: every rank must ask alike).
    pub fn piece(&mut self, needs_gradient: bool) -> Result<Piece, FrameError> {
        let renderer = self.held.renderer.take();
        let piece = self.piece_of(needs_gradient, renderer.as_ref().map(Renderer::volume));
        self.held.renderer = renderer;
        piece
    }

    /// [`Self::piece`], this rank's piece being `held` (the volume its
    /// renderer holds, wherever that renderer is now: a scene's).
    pub(crate) fn piece_of(
        &mut self,
        needs_gradient: bool,
        held: Option<&Volume>,
    ) -> Result<Piece, FrameError> {
        let max_gradient = if needs_gradient {
            self.max_gradient_of(held)?
        } else {
            0.0
        };
        Ok(Piece {
            whole: self.grid,
            offset: self.held.offset,
            owned: self.held.piece_owned,
            value_range: self.value_range,
            max_gradient,
        })
    }

    /// Takes this rank's renderer (none if its box is empty), for a
    /// scene of several volumes' pieces ([`crate::scene`]).
    pub(crate) fn take_renderer(&mut self) -> Option<Renderer<'static>> {
        self.held.renderer.take()
    }

    /// The transport and this rank's compositing plan.
    pub(crate) fn plan(&self) -> (&'t T, &Plan) {
        (self.transport, &self.plan)
    }

    /// The times of reading and agreeing.
    pub(crate) fn read_times(&self) -> RankTimes {
        self.held.times
    }

    /// Renders one frame of `settings` across the ranks: the finished
    /// frame on rank 0, `None` on the others; and this rank's times.
    pub fn render(
        &mut self,
        settings: &RenderSettings,
    ) -> Result<(Option<Image>, RankTimes), FrameError> {
        let settings = self.piece_settings(settings)?;
        let view = View::frame(
            &settings.camera,
            self.grid.bounds(),
            settings.width,
            settings.height,
        )
        .map_err(RenderError::from)?;
        let viewpoint = Viewpoint::of(&view);
        let rendered = match &self.held.renderer {
            Some(r) => (r.render(FrameRequest::new(&settings).partial()))
                .map(|r| Some(r.partial_and_times())),
            None => settings.validate().map(|_| None).map_err(RenderError::from),
        };
        // Every rank refuses the same settings alike; anything else (one
        // rank out of memory, say) must not leave the others waiting.
        let status = rendered
            .as_ref()
            .map(|_| Vec::new())
            .map_err(|e| e.to_string());
        if let Err(e @ FrameError::Rank { .. }) = agree(self.transport, status) {
            return Err(match rendered {
                Err(e) => FrameError::Render(e),
                Ok(_) => e,
            });
        }
        let mut times = self.held.times;
        let partial = match rendered.expect("agreed") {
            Some((partial, t)) => {
                times.classify = t.classify;
                times.cast = t.cast + t.bin;
                partial
            }
            None => blank(&settings),
        };
        let (image, stats) =
            composite(self.transport, &self.plan, &viewpoint, &self.grid, partial)?;
        times.compose = stats;
        let image = image.map(|partial| self.finish(&settings, partial));
        Ok((image, times))
    }

    /// Every rank's times, on every rank.
    pub fn gather_times(&self, times: RankTimes) -> Result<Vec<RankTimes>, FrameError> {
        let all = self.transport.all_gather(&times.to_bytes())?;
        Ok(all
            .iter()
            .map(|b| RankTimes::from_bytes(b).unwrap_or_default())
            .collect())
    }

    /// The frame of the whole volume's `partial` image.
    fn finish(&self, settings: &RenderSettings, partial: PartialImage) -> Image {
        match &self.held.renderer {
            Some(r) => r.finish(settings, partial),
            // Rank 0 always owns voxels; a frame of nothing otherwise.
            None => partial.finish(settings.background, |_| settings.background),
        }
    }

    /// The whole volume's histogram in `bins` bins over its value range
    /// (what `--tf auto` chooses from): each rank counts its owned voxels,
    /// and the counts are summed on every rank. `None` for a volume with
    /// no finite value.
    pub fn histogram(&self, bins: usize) -> Result<Option<Histogram>, FrameError> {
        self.histogram_in(None, bins)
    }

    /// [`Self::histogram`] over `window` (`None`: the value range), the
    /// values outside it counted in the end bins (volray-core's
    /// `auto::robust_histogram` passes). Every rank must call it together.
    pub fn histogram_in(
        &self,
        window: Option<(f32, f32)>,
        bins: usize,
    ) -> Result<Option<Histogram>, FrameError> {
        let range = window.unwrap_or(self.value_range);
        let local = self.held.renderer.as_ref().map(|r| {
            let (lo, hi) = self.held.piece_owned;
            let o = self.held.offset;
            let owned = (
                std::array::from_fn(|a| lo[a] - o[a]),
                std::array::from_fn(|a| hi[a] - o[a]),
            );
            Histogram::of_box(r.volume(), owned, range, bins)
        });
        // The mean, the non-finite count, the values within the window
        // (two f32, +∞ and −∞ for none) and the counts.
        let bytes = local.map_or_else(Vec::new, |h| {
            let mut out: Vec<u8> = h.mean.to_le_bytes().to_vec();
            out.extend_from_slice(&h.non_finite.to_le_bytes());
            let (lo, hi) = h.within.unwrap_or((f32::INFINITY, f32::NEG_INFINITY));
            out.extend_from_slice(&lo.to_le_bytes());
            out.extend_from_slice(&hi.to_le_bytes());
            for c in &h.counts {
                out.extend_from_slice(&c.to_le_bytes());
            }
            out
        });
        let all = agree(self.transport, Ok::<_, Failure>(bytes))?;
        let mut whole: Option<Histogram> = None;
        for m in all.iter().filter(|m| m.len() == 24 + 8 * bins.max(1)) {
            let word = |i: usize| m[8 * i..8 * i + 8].try_into().unwrap();
            let half = |i: usize| f32::from_le_bytes(m[i..i + 4].try_into().unwrap());
            let part = Histogram {
                min: range.0,
                max: range.1,
                mean: f64::from_le_bytes(word(0)),
                non_finite: u64::from_le_bytes(word(1)),
                within: Some((half(16), half(20))).filter(|(lo, hi)| lo <= hi),
                counts: (0..bins.max(1))
                    .map(|b| u64::from_le_bytes(word(3 + b)))
                    .collect(),
            };
            match &mut whole {
                Some(h) => h.merge(&part),
                None => whole = Some(part),
            }
        }
        Ok(whole.filter(|_| self.values_found))
    }

    /// The distinct labels of the whole volume, sorted, as
    /// [`labels_of`] finds them in one process: each rank finds those of
    /// the piece it holds (the pieces cover the volume, and hold nothing
    /// else), and the sets are joined on every rank. `Ok(None)` for more
    /// than `max` distinct values; the error of the lowest rank whose
    /// piece holds a value that is not an integer.
    pub fn labels(&self, max: usize) -> Result<Result<Option<Vec<i64>>, LabelError>, FrameError> {
        // On the wire: 0 and the labels (i64 each), 1 for too many, 2 and
        // the value that is not an integer (f32).
        let local = self
            .held
            .renderer
            .as_ref()
            .map_or(Ok(Some(Vec::new())), |r| labels_of(r.volume(), max));
        let bytes = match &local {
            Ok(Some(found)) => std::iter::once(0u8)
                .chain(found.iter().flat_map(|l| l.to_le_bytes()))
                .collect(),
            Ok(None) => vec![1u8],
            Err(LabelError::NotInteger(v)) => [&[2u8][..], &v.to_le_bytes()].concat(),
            Err(_) => vec![1u8],
        };
        let all = agree(self.transport, Ok::<_, Failure>(bytes))?;
        let mut union = std::collections::BTreeSet::new();
        let mut too_many = false;
        for m in &all {
            match m.split_first() {
                Some((0, list)) => union.extend(
                    list.chunks_exact(8)
                        .map(|c| i64::from_le_bytes(c.try_into().unwrap())),
                ),
                Some((2, v)) if v.len() == 4 => {
                    let v = f32::from_le_bytes(v.try_into().unwrap());
                    return Ok(Err(LabelError::NotInteger(v)));
                }
                _ => too_many = true,
            }
        }
        if too_many || union.len() > max {
            return Ok(Ok(None));
        }
        Ok(Ok(Some(union.into_iter().collect())))
    }

    /// The decomposition of the grid among the ranks.
    pub fn decomposition(&self) -> &Decomposition {
        &self.decomposition
    }

    /// Whether this rank holds a piece's value range (not an empty box).
    pub fn holds_values(&self) -> bool {
        self.held.value_range.is_some()
    }
}

/// A partial image with nothing in it, for a rank with an empty box.
pub(crate) fn blank(settings: &RenderSettings) -> PartialImage {
    let (w, h) = (settings.width, settings.height);
    if settings.blend.is_projection() {
        PartialImage::projection(w, h, settings.blend)
    } else {
        PartialImage::composite(w, h)
    }
}

/// The largest gradient magnitude at the owned voxels of a piece held
/// from whole-grid voxel `offset`.
pub(crate) fn owned_max_gradient(
    volume: &Volume,
    offset: [usize; 3],
    (lo, hi): ([usize; 3], [usize; 3]),
) -> f32 {
    let local = |a: usize, i: usize| i - offset[a];
    with_samples!(volume.samples(), |data| {
        let d = Differences::new(data, volume);
        let mut max = 0.0f32;
        for k in lo[2]..hi[2] {
            for j in lo[1]..hi[1] {
                for i in lo[0]..hi[0] {
                    let g = d.at(local(0, i), local(1, j), local(2, k));
                    max = max.max(magnitude(g));
                }
            }
        }
        max
    })
}
