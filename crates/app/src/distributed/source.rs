//! One rank's view of the input of a distributed render ([`RankSource`]):
//! how it has its piece (mapped, decoded from chunks, generated, or sent
//! by rank 0), the `--max-memory` checks before any piece is read, and
//! the `--log` floor the ranks agree on.

use super::job::{Job, Words, frame};
use super::wire::{decode_piece, encode_piece, grid_bytes, grid_of, held_piece, parse_grid};
use crate::error::AppError;
use crate::input::{self, Input, Request, Spec};
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{NonFinite, RenderSettings, SampleType, SourceError, Volume};
use volray_distributed::frame::{Source, agree};
use volray_distributed::kd::Decomposition;
use volray_distributed::mpi::Mpi;
use volray_distributed::transport::Transport;
use volray_io::{MapPolicy, Reorientation};

/// This rank's view of INPUT: the whole volume mapped (in the file's own
/// axis order where `reorientation` says so), a built-in source's spec,
/// or the piece rank 0 sent it.
pub(super) struct RankSource {
    pub(super) name: String,
    grid: GridFrame,
    /// The file mapped: the world-aligned volume, or the file's grid when
    /// `reorientation` is given.
    whole: Option<Volume>,
    reorientation: Option<Reorientation>,
    /// The piece rank 0 read (or generated) and sent.
    sent: Option<Volume>,
    /// A chunked store (Zarr, OME-Zarr) opened from its metadata: every
    /// rank reads the chunks of its own box.
    chunked: Option<std::sync::Arc<dyn Source>>,
    /// `--log`: the whole volume's smallest positive value, which values
    /// `<= 0` take on the log scale (agreed by the ranks).
    log_floor: Option<f32>,
    /// A built-in source's spec: each rank generates its box.
    generate: Option<String>,
    /// The file's display window (OME-Zarr `omero`), the default `--range`.
    pub(super) window: Option<(f64, f64)>,
    /// `--log` and `--labels` as given.
    log: bool,
    labels: bool,
    max_memory: u64,
    settings: RenderSettings,
    pub(super) non_finite: NonFinite,
}

/// How a rank has its piece, for the copies it passes through.
#[derive(Debug, Clone, Copy)]
enum Route {
    /// Copied out of the mapped file in its stored type, and reordered
    /// into a second copy where the file's axes are not x, y, z.
    Mapped { stored: SampleType, reordered: bool },
    /// Decoded from the chunks of a chunked store in its stored type.
    Chunked { stored: SampleType },
    /// Generated, as `f32`.
    Generated,
    /// Received from rank 0 as `f32` bytes, then decoded.
    Sent,
}

/// What rank 0 tells every rank of INPUT once it has opened it.
struct Header {
    /// The world-aligned volume's grid.
    grid: GridFrame,
    /// Whether every rank maps the file and reads its own box.
    local: bool,
    /// Whether NaN marks space the file does not cover.
    nan_is_empty: bool,
    stored: SampleType,
    /// Whether the file's axes must be reordered box by box.
    reordered: bool,
}

/// The sample types on the wire, by their index here.
const SAMPLE_TYPES: [SampleType; 5] = [
    SampleType::U8,
    SampleType::I8,
    SampleType::U16,
    SampleType::I16,
    SampleType::F32,
];

impl Header {
    fn of(input: &Input) -> Header {
        let v = &input.volume;
        let reorientation = (input.file.as_ref()).and_then(|(_, info)| info.reorientation.as_ref());
        let grid = match reorientation {
            Some(r) => GridFrame {
                dims: r.dims(),
                origin: r.origin,
                spacing: r.spacing,
            },
            None => grid_of(v),
        };
        Header {
            grid,
            local: v.samples().is_external(),
            nan_is_empty: input.non_finite(NonFinite::Refuse) == NonFinite::Transparent,
            stored: v.sample_type(),
            reordered: reorientation.is_some(),
        }
    }

    /// The grid ([`grid_bytes`]), then a byte each: local, NaN is empty,
    /// the stored type, reordered.
    fn to_bytes(&self) -> Vec<u8> {
        let mut out = grid_bytes(&self.grid);
        let stored = SAMPLE_TYPES.iter().position(|&t| t == self.stored);
        out.extend([
            self.local as u8,
            self.nan_is_empty as u8,
            stored.unwrap_or(4) as u8,
            self.reordered as u8,
        ]);
        out
    }

    fn parse(b: &[u8]) -> Header {
        Header {
            grid: parse_grid(b),
            local: b[72] != 0,
            nan_is_empty: b[73] != 0,
            stored: SAMPLE_TYPES[(b[74] as usize).min(4)],
            reordered: b[75] != 0,
        }
    }
}

/// Whether built-in source `spec` is generated whole, whatever box is
/// asked for (the fractal: midpoint displacement over the whole grid).
fn generated_whole(spec: &str) -> bool {
    volray_data::SourceSpec::parse(spec).is_ok_and(|s| s.name == "fractal")
}

impl RankSource {
    /// Opens `job`'s input on this rank, agreeing with the others on how
    /// (`words` tells them this rank's failure).
    pub(super) fn open(mpi: &Mpi, job: &Job, words: Words<'_>) -> Result<RankSource, AppError> {
        let (args, settings) = (&job.request, &job.settings);
        let requested = job.non_finite;
        let spec = args.spec.name();
        let max_memory = args.max_memory();
        let mut source = RankSource {
            name: spec.clone(),
            grid: GridFrame {
                dims: [0; 3],
                origin: DVec3::ZERO,
                spacing: DVec3::ONE,
            },
            whole: None,
            reorientation: None,
            sent: None,
            chunked: None,
            log_floor: None,
            generate: None,
            window: None,
            log: job.look.log,
            labels: job.look.labels,
            max_memory,
            settings: settings.clone(),
            non_finite: requested,
        };
        let is_source = matches!(args.spec, Spec::Source(_));
        if is_source && !generated_whole(&spec) {
            source.generate_boxes(mpi, args, words)?;
            return Ok(source);
        }
        // A chunked store: every rank opens it from its metadata and
        // decodes the chunks of its own box, and nothing else.
        if let Spec::File(path) = &args.spec {
            let opened = input::read_options(args, max_memory, MapPolicy::IfLarger)
                .and_then(|opts| volray_io::open_lazy(path, &opts).map_err(AppError::from));
            let status = opened
                .as_ref()
                .map(|lazy| vec![u8::from(lazy.is_some())])
                .map_err(words);
            let all = agree(mpi, status).map_err(|e| frame(&spec, e))?;
            if all.iter().all(|m| m.first() == Some(&1)) {
                let lazy = opened.ok().flatten().expect("agreed");
                source.grid = lazy.source.grid();
                source.window = lazy.info.display_window();
                let stored = lazy.source.sample_type();
                source.chunked = Some(lazy.source);
                let fits = source.check_piece(mpi, Route::Chunked { stored });
                agree(mpi, fits.map(|_| Vec::new()).map_err(|e| words(&e)))
                    .map_err(|e| frame(&spec, e))?;
                source.agree_log_floor(mpi)?;
                return Ok(source);
            }
        }
        // A file mapped wherever it can be, in its own axis order if need
        // be; else read whole by rank 0 (a fractal generated whole).
        // Stretched for drawing as a whole render's (display.rs).
        let load = || {
            input::load_with(args, MapPolicy::AlwaysInFileOrder)
                .and_then(|i| crate::input::displayed(i, args.scale))
        };
        // Rank 0 first: whether the file maps, and the grid.
        let first = if mpi.rank() == 0 {
            load().map(Some)
        } else {
            Ok(None)
        };
        let header = (first.as_ref()).map(|input| {
            input
                .as_ref()
                .map_or_else(Vec::new, |i| Header::of(i).to_bytes())
        });
        let all = agree(mpi, header.map_err(words)).map_err(|e| frame(&spec, e))?;
        let header = Header::parse(&all[0]);
        source.grid = header.grid;
        if header.nan_is_empty {
            source.non_finite = NonFinite::Transparent;
        }
        let route = if header.local {
            Route::Mapped {
                stored: header.stored,
                reordered: header.reordered,
            }
        } else {
            Route::Sent
        };
        // Every rank's piece, and what rank 0 holds while it sends the
        // pieces, checked against --max-memory before any is read.
        let mut fits = source.check_piece(mpi, route);
        if let (true, Ok(Some(input))) = (fits.is_ok() && !header.local, &first) {
            fits = source.check_scatter(mpi, &input.volume);
        }
        agree(mpi, fits.map(|_| Vec::new()).map_err(|e| words(&e))).map_err(|e| frame(&spec, e))?;
        if header.local {
            // Every rank maps the file itself.
            let input = match first {
                Ok(Some(input)) => Ok(input),
                _ => load(),
            };
            let status = input.as_ref().map(|_| Vec::new()).map_err(words);
            agree(mpi, status).map_err(|e| frame(&spec, e))?;
            let input = input.expect("agreed");
            source.reorientation = input.file.and_then(|(_, info)| info.reorientation);
            source.whole = Some(input.volume);
            source.agree_log_floor(mpi)?;
            return Ok(source);
        }
        // Rank 0 sends each rank its piece.
        let decomposition = Decomposition::new(source.grid.dims, mpi.size());
        if mpi.rank() == 0 {
            let input: Input = first.ok().flatten().expect("rank 0 read the file");
            if is_source {
                eprintln!(
                    "volray: note: {spec}: the fractal is generated whole (midpoint displacement over the grid); rank 0 generates it and sends each rank its piece"
                );
            } else {
                eprintln!(
                    "volray: note: {spec}: this format cannot be read by range; rank 0 reads it and sends each rank its piece"
                );
            }
            for (rank, b) in decomposition.boxes.iter().enumerate() {
                let piece = held_piece(&input.volume, b.lo, b.hi, source.grid.dims);
                if rank == 0 {
                    source.sent = piece;
                } else {
                    let bytes = piece.as_ref().map_or_else(Vec::new, encode_piece);
                    drop(piece);
                    mpi.send(rank, &bytes).map_err(|e| frame(&spec, e.into()))?;
                }
            }
        } else {
            let bytes = mpi.receive(0).map_err(|e| frame(&spec, e.into()))?;
            source.sent = decode_piece(&bytes);
        }
        source.agree_log_floor(mpi)?;
        Ok(source)
    }

    /// A built-in source sampled box by box: every rank generates its own
    /// box (the grid from a 2³ box of it, the same on every rank).
    fn generate_boxes(
        &mut self,
        mpi: &Mpi,
        args: &Request,
        words: Words<'_>,
    ) -> Result<(), AppError> {
        let spec = self.name.clone();
        let probe = input::source_grid(args).and_then(|n| {
            volray_data::generate_box(&spec, [0; 3], [2; 3])
                .map(|v| (n, v))
                .map_err(AppError::from)
        });
        let status = probe.as_ref().map(|_| Vec::new()).map_err(words);
        agree(mpi, status).map_err(|e| frame(&spec, e))?;
        let (n, corner) = probe.expect("agreed");
        self.grid = GridFrame {
            dims: [n; 3],
            origin: corner.origin(),
            spacing: corner.spacing(),
        };
        self.generate = Some(spec.clone());
        let fits = self.check_piece(mpi, Route::Generated);
        agree(mpi, fits.map(|_| Vec::new()).map_err(|e| words(&e))).map_err(|e| frame(&spec, e))?;
        self.agree_log_floor(mpi)
    }

    /// This rank's held box (its owned box with its ghost layers), or
    /// `None` if it owns nothing.
    fn held_box(&self, mpi: &Mpi) -> Option<([usize; 3], [usize; 3])> {
        let b = Decomposition::new(self.grid.dims, mpi.size()).boxes[mpi.rank()];
        (!b.is_empty()).then(|| volray_core::Piece::held((b.lo, b.hi), self.grid.dims))
    }

    /// Whether this rank's piece, had by `route`, fits its `--max-memory`:
    /// the most of rendering it and of the copies it passes through on
    /// its way (two at a time: the file's box and its reordering, the
    /// piece and its log10, the bytes received and the samples decoded),
    /// decided from the grid alone, before any of it is allocated.
    fn check_piece(&self, mpi: &Mpi, route: Route) -> Result<(), AppError> {
        let Some((lo, hi)) = self.held_box(mpi) else {
            return Ok(());
        };
        let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
        let voxels = dims.iter().map(|&n| n as u128).product::<u128>();
        let bytes = |t: SampleType| voxels * t.bytes() as u128;
        let first = match route {
            Route::Mapped { stored, .. } | Route::Chunked { stored } => stored,
            Route::Generated | Route::Sent => SampleType::F32,
        };
        let last = if self.log { SampleType::F32 } else { first };
        let mut copies = 0;
        if let Route::Mapped {
            reordered: true, ..
        } = route
        {
            copies = copies.max(2 * bytes(first));
        }
        if self.log {
            copies = copies.max(bytes(first) + bytes(SampleType::F32));
        }
        if let Route::Sent = route {
            copies = copies.max(73 + 2 * bytes(SampleType::F32));
        }
        let render = crate::memory::render_bytes(
            (dims, self.grid.spacing, last),
            &self.settings,
            self.non_finite,
            0,
        );
        let need = render.max(copies);
        if need > u128::from(self.max_memory) {
            return Err(AppError::PieceOverBudget {
                name: self.name.clone(),
                dims,
                need,
                limit: self.max_memory,
            });
        }
        Ok(())
    }

    /// On rank 0, which holds `whole` (read or generated whole) to send
    /// the pieces: whether the volume, rank 0's own piece and the largest
    /// piece on its way out (its samples and their bytes) fit
    /// `--max-memory`, before any piece is cut.
    fn check_scatter(&self, mpi: &Mpi, whole: &Volume) -> Result<(), AppError> {
        let sample = whole.sample_type().bytes() as u128;
        let held = |(lo, hi): ([usize; 3], [usize; 3])| {
            (0..3).map(|a| (hi[a] - lo[a]) as u128).product::<u128>()
        };
        let d = Decomposition::new(self.grid.dims, mpi.size());
        let pieces: Vec<u128> = (d.boxes.iter())
            .map(|b| {
                if b.is_empty() {
                    0
                } else {
                    held(volray_core::Piece::held((b.lo, b.hi), self.grid.dims))
                }
            })
            .collect();
        let own = pieces[0] * sample;
        let largest_out = (pieces[1..].iter())
            .map(|&n| n * sample + 73 + 4 * n)
            .max()
            .unwrap_or(0);
        let volume = whole.len() as u128 * sample;
        let need = volume + own + largest_out;
        if need > u128::from(self.max_memory) {
            return Err(AppError::ScatterOverBudget {
                name: self.name.clone(),
                generated: volray_data::is_source_spec(&self.name),
                volume,
                need,
                limit: self.max_memory,
            });
        }
        Ok(())
    }

    /// For `--log`: the smallest positive value over every rank's piece
    /// (the pieces cover the volume), as one process takes it over the
    /// whole volume.
    fn agree_log_floor(&mut self, mpi: &Mpi) -> Result<(), AppError> {
        if !self.log {
            return Ok(());
        }
        let smallest = match self.held_box(mpi) {
            None => Ok(None),
            Some((lo, hi)) => self.raw_piece(lo, hi).map(|p| p.smallest_positive()),
        };
        let local = smallest.map(|s| s.unwrap_or(f32::INFINITY).to_le_bytes().to_vec());
        let all = agree(mpi, local).map_err(|e| frame(&self.name, e))?;
        let floor = (all.iter())
            .filter_map(|m| m.as_slice().try_into().ok().map(f32::from_le_bytes))
            .fold(f32::INFINITY, f32::min);
        if floor == f32::INFINITY {
            return Err(AppError::Log {
                name: self.name.clone(),
                message: "a log scale needs a positive value, and the volume has none".to_string(),
            });
        }
        self.log_floor = Some(floor);
        Ok(())
    }

    /// The voxels `lo..hi` as read or generated, before `--log` (their
    /// size checked by [`RankSource::check_piece`] when the source was
    /// opened).
    fn raw_piece(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        if let Some(spec) = &self.generate {
            return volray_data::generate_box(spec, lo, hi)
                .map_err(|e| SourceError::bad_data(e.to_string()));
        }
        if let Some(chunked) = &self.chunked {
            return chunked.read_box(lo, hi);
        }
        match (&self.whole, &self.reorientation, &self.sent) {
            (Some(file), Some(r), _) => (r.sub_box(file, lo, hi))
                .map_err(|e| SourceError::bad_data(format!("{}: its piece: {e}", self.name))),
            (Some(whole), None, _) => Ok(whole.sub_box(lo, hi)),
            (None, _, Some(sent)) => Ok(sent.clone()),
            (None, _, None) => Err(SourceError::io(format!(
                "{}: rank 0 sent no piece",
                self.name
            ))),
        }
    }
}

impl Source for RankSource {
    fn grid(&self) -> GridFrame {
        self.grid
    }

    /// The mapped file's type; generated and sent pieces, and values on
    /// the log scale, are `f32`.
    fn sample_type(&self) -> SampleType {
        if let (Some(chunked), false) = (&self.chunked, self.log) {
            return chunked.sample_type();
        }
        match (&self.whole, self.log) {
            (Some(whole), false) => whole.sample_type(),
            _ => SampleType::F32,
        }
    }

    fn is_labels(&self) -> bool {
        self.labels
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        let piece = self.raw_piece(lo, hi)?;
        let mut piece = match self.log_floor {
            Some(smallest) => piece.to_log10_above(smallest),
            None => piece,
        };
        if self.labels {
            piece.set_labels(true);
        }
        Ok(piece)
    }
}
