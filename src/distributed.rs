//! `mpirun -np N volray render|bench …` (built with `--features mpi`): the
//! volume split among the ranks, each rendering its piece, the frame
//! composited on rank 0 (volray-distributed does the work; this is the
//! CLI's side: the input, `--max-memory` per rank, the output, the times).
//!
//! Files are read by range: every rank maps the file (raw, NRRD raw,
//! MetaImage raw, NIfTI `.nii`, `.npy`, MRC: volray-io's `MapPolicy`) and
//! copies out its box with its ghost layers, so that only those pages are
//! read. A file that cannot be mapped (compressed, DICOM, TIFF, HDF5, …)
//! is read by rank 0, which sends each rank its piece (a note on stderr
//! says so). Built-in sources generate only each rank's box (the
//! fractal, a whole-grid process, is generated whole and cut).

use crate::error::CliError;
use crate::flags::{BenchArgs, InputArgs, RenderArgs, ViewArgs};
use crate::input::{self, Input};
use crate::render::{self, OutputKind};
use crate::session::render_failure;
use crate::settings::settings;
use std::time::Duration;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{Camera, NonFinite, RenderSettings, Volume};
use volray_distributed::frame::{Distributed, FrameError, RankTimes, Source, agree};
use volray_distributed::kd::Decomposition;
use volray_distributed::mpi::Mpi;
use volray_distributed::transport::Transport;
use volray_io::{MapPolicy, format_bytes};

/// Whether this process runs under an MPI launcher, and so renders as one
/// rank of a distributed run.
pub fn launched() -> bool {
    volray_distributed::mpi::launched()
}

/// `volray render` under `mpirun`: one still image, written by rank 0.
pub fn render(args: &RenderArgs) -> Result<(), CliError> {
    refuse_unsupported(&args.input, &args.view.look)?;
    if args.animation.turntable.is_some() || !args.animation.series.is_empty() {
        return Err(CliError::input(
            "under mpirun, render writes one still image: --turntable and series are rendered by one process",
        ));
    }
    let kind = render::output_kind(&args.out.output, args.out.bit_depth, None)?;
    if matches!(kind, OutputKind::Gif) {
        return Err(CliError::input(format!(
            "{}: under mpirun, write .png or .exr",
            args.out.output.display()
        )));
    }
    let settings = settings(&args.view)?;
    threads(args.view.threads)?;
    let mpi = initialize()?;
    // Rank 0 writes the file: it alone checks where.
    let checked = if mpi.rank() == 0 {
        render::check_output(&args.out.output).and_then(|_| {
            let spec = args.input.input.as_deref().unwrap_or(input::DEMO);
            crate::overwrite::refuse_overwriting_inputs(
                &render::output_files(args, kind, 1),
                &[spec.to_string()],
                &args.view.look.tf_file().into_iter().collect::<Vec<_>>(),
            )
        })
    } else {
        Ok(())
    };
    agree(&mpi, checked.map(|_| Vec::new()).map_err(|e| e.to_string()))
        .map_err(|e| failure(&args.view, "", e))?;
    let source = CliSource::open(&mpi, &args.input, &args.view, &settings)?;
    let mode = source.non_finite;
    let name = source.name.clone();
    let fail = |e| failure(&args.view, &name, e);
    let mut d = Distributed::read(&mpi, &source, mode).map_err(fail)?;
    let settings = auto_tf(&d, &args.view, settings).map_err(fail)?;
    let (image, _) = d.render(&settings).map_err(fail)?;
    if let Some(image) = image {
        render::write_still(args, kind, &image)?;
    }
    Ok(())
}

/// `volray bench` under `mpirun`: per-rank times of each stage, medians
/// over the frames (each turned half a degree further, as `bench` does),
/// printed by rank 0.
pub fn bench(args: &BenchArgs) -> Result<(), CliError> {
    if args.peers.is_some() {
        return Err(CliError::input(
            "under mpirun, bench renders INPUT: --peers runs in one process",
        ));
    }
    refuse_unsupported(&args.input, &args.view.look)?;
    let base = settings(&args.view)?;
    threads(args.view.threads)?;
    let mpi = initialize()?;
    let source = CliSource::open(&mpi, &args.input, &args.view, &base)?;
    let (mode, name) = (source.non_finite, source.name.clone());
    let fail = |e| failure(&args.view, &name, e);
    let frames = args.frames as usize;
    let (d, per_frame, walls) = {
        let start = mpi.time();
        let mut d = Distributed::read(&mpi, &source, mode).map_err(fail)?;
        let base = auto_tf(&d, &args.view, base.clone()).map_err(fail)?;
        let read_wall = mpi.time() - start;
        let mut per_frame: Vec<Vec<RankTimes>> = Vec::new();
        let mut walls = Vec::new();
        // One warm-up frame (classification, caches), then the timed ones.
        for frame in 0..=frames {
            let s = RenderSettings {
                camera: Camera {
                    azimuth: base.camera.azimuth + 0.5 * frame as f64,
                    ..base.camera
                },
                ..base.clone()
            };
            let start = mpi.time();
            let (_, times) = d.render(&s).map_err(fail)?;
            walls.push(mpi.time() - start);
            per_frame.push(d.gather_times(times).map_err(fail)?);
        }
        walls[0] = read_wall;
        (d, per_frame, walls)
    };
    if mpi.rank() == 0 {
        print_bench(
            &name,
            &base,
            &d,
            &per_frame,
            &walls,
            rayon::current_num_threads(),
        );
    }
    Ok(())
}

/// Rayon's global pool of `threads` workers (default: one per core): MPI
/// is called from the main thread only, the rendering within a rank runs
/// on the pool.
fn threads(threads: Option<u16>) -> Result<(), CliError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n as usize);
    }
    builder
        .build_global()
        .map_err(|e| CliError::io(format!("cannot start worker threads: {e}")))
}

/// MPI, with a panic on this rank ending every rank (`MPI_Abort`): else
/// the panicking rank would wait in `MPI_Finalize` and the others for it.
fn initialize() -> Result<Mpi, CliError> {
    let mpi = Mpi::initialize().ok_or_else(|| CliError::io("MPI could not be initialised"))?;
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        default_hook(info);
        volray_distributed::mpi::abort_world(101);
    }));
    Ok(mpi)
}

/// `settings` with `--tf auto` (the default) applied: the transfer
/// function chosen from the whole volume's histogram, summed over the
/// ranks' owned voxels, exactly as one process chooses it.
fn auto_tf(
    d: &Distributed<'_, Mpi>,
    view: &ViewArgs,
    mut settings: RenderSettings,
) -> Result<RenderSettings, FrameError> {
    let look = crate::settings::look(&view.look);
    if look.auto_tf()
        && let Some(histogram) = d.histogram(volray_core::transfer::auto::BINS)?
    {
        volray_options::apply_auto(&look, &mut settings.transfer_function, &histogram);
    }
    Ok(settings)
}

/// What a distributed run cannot do yet, refused in words.
fn refuse_unsupported(input: &InputArgs, look: &crate::flags::LookArgs) -> Result<(), CliError> {
    let _ = input;
    if look.labels {
        return Err(CliError::input(
            "--labels: label volumes are rendered by one process (the labels found must be agreed by every rank)",
        ));
    }
    Ok(())
}

/// A failed distributed step as the CLI's error: the same line on every
/// rank.
fn failure(view: &ViewArgs, name: &str, e: FrameError) -> CliError {
    match e {
        FrameError::Render(e) => render_failure(view, name, e),
        FrameError::Rank { rank, message } => CliError::io(format!("rank {rank}: {message}")),
        e => CliError::io(e.to_string()),
    }
}

/// This rank's view of INPUT: the whole volume mapped (or generated), or
/// the piece rank 0 sent it.
struct CliSource {
    name: String,
    grid: GridFrame,
    whole: Option<Volume>,
    /// The piece rank 0 read and sent, for a file that cannot be mapped.
    sent: Option<Volume>,
    /// `--log`: the whole volume's smallest positive value, which values
    /// `<= 0` take on the log scale (agreed by the ranks).
    log_floor: Option<f32>,
    /// A built-in source's spec: each rank generates its box.
    generate: Option<String>,
    max_memory: u64,
    settings: RenderSettings,
    non_finite: NonFinite,
}

impl CliSource {
    fn open(
        mpi: &Mpi,
        args: &InputArgs,
        view: &ViewArgs,
        settings: &RenderSettings,
    ) -> Result<CliSource, CliError> {
        let requested: NonFinite = view.sampling.nonfinite.into();
        let spec = args.input.as_deref().unwrap_or(input::DEMO).to_string();
        let max_memory = args
            .max_memory
            .unwrap_or_else(volray_io::default_max_memory);
        if volray_data::is_source_spec(&spec) {
            return CliSource::generated(mpi, args, view, settings, spec, max_memory, requested);
        }
        let load = || input::load_with(args, MapPolicy::Always);
        // Rank 0 first: whether the file maps, and the grid.
        let first = if mpi.rank() == 0 {
            load().map(Some)
        } else {
            Ok(None)
        };
        let header = first.as_ref().map(|input| match input {
            Some(input) => {
                let local = input.file.is_none() || input.volume.samples().is_external();
                describe(input, local)
            }
            None => Vec::new(),
        });
        let all =
            agree(mpi, header.map_err(|e| e.to_string())).map_err(|e| failure(view, &spec, e))?;
        let (grid, local, non_finite_empty) = parse_header(&all[0]);
        let non_finite = if non_finite_empty {
            NonFinite::Transparent
        } else {
            requested
        };
        let max_memory = args
            .max_memory
            .unwrap_or_else(volray_io::default_max_memory);
        let mut source = CliSource {
            name: spec.clone(),
            grid,
            whole: None,
            sent: None,
            log_floor: None,
            max_memory,
            settings: settings.clone(),
            non_finite,
            generate: None,
        };
        if local {
            // Every rank maps the file (or generates the source) itself.
            let input = match first {
                Ok(Some(input)) => Ok(input),
                _ => load(),
            };
            let status = input
                .as_ref()
                .map(|_| Vec::new())
                .map_err(|e| e.to_string());
            agree(mpi, status).map_err(|e| failure(view, &spec, e))?;
            source.whole = Some(input.expect("agreed").volume);
            source.agree_log_floor(mpi, view)?;
            return Ok(source);
        }
        // Rank 0 sends each rank its piece.
        let decomposition = Decomposition::new(grid.dims, mpi.size());
        if mpi.rank() == 0 {
            let input: Input = first.ok().flatten().expect("rank 0 read the file");
            eprintln!(
                "volray: note: {spec}: this format cannot be read by range; rank 0 reads it and sends each rank its piece"
            );
            for (rank, b) in decomposition.boxes.iter().enumerate() {
                let piece = held_piece(&input.volume, b.lo, b.hi, grid.dims);
                let bytes = piece.as_ref().map_or_else(Vec::new, encode_piece);
                if rank == 0 {
                    source.sent = piece;
                } else {
                    mpi.send(rank, &bytes)
                        .map_err(|e| CliError::io(e.to_string()))?;
                }
            }
        } else {
            let bytes = mpi.receive(0).map_err(|e| CliError::io(e.to_string()))?;
            source.sent = decode_piece(&bytes);
        }
        source.agree_log_floor(mpi, view)?;
        Ok(source)
    }

    /// A built-in source: every rank generates its own box (the grid from a
    /// 2³ box of it, the same on every rank).
    fn generated(
        mpi: &Mpi,
        args: &InputArgs,
        view: &ViewArgs,
        settings: &RenderSettings,
        spec: String,
        max_memory: u64,
        non_finite: NonFinite,
    ) -> Result<CliSource, CliError> {
        let probe = input::source_grid(args, &spec).and_then(|n| {
            volray_data::generate_box(&spec, [0; 3], [2; 3])
                .map(|v| (n, v))
                .map_err(CliError::from)
        });
        let status = probe
            .as_ref()
            .map(|_| Vec::new())
            .map_err(|e| e.to_string());
        agree(mpi, status).map_err(|e| failure(view, &spec, e))?;
        let (n, corner) = probe.expect("agreed");
        let mut source = CliSource {
            name: spec.clone(),
            grid: GridFrame {
                dims: [n; 3],
                origin: corner.origin(),
                spacing: corner.spacing(),
            },
            whole: None,
            sent: None,
            log_floor: None,
            max_memory,
            settings: settings.clone(),
            non_finite,
            generate: Some(spec),
        };
        source.agree_log_floor(mpi, view)?;
        Ok(source)
    }

    /// For `--log`: the smallest positive value over every rank's piece
    /// (the pieces cover the volume), as one process takes it over the
    /// whole volume.
    fn agree_log_floor(&mut self, mpi: &Mpi, view: &ViewArgs) -> Result<(), CliError> {
        if !view.look.log {
            return Ok(());
        }
        let b = Decomposition::new(self.grid.dims, mpi.size()).boxes[mpi.rank()];
        let smallest = if b.is_empty() {
            Ok(None)
        } else {
            let (lo, hi) = volray_core::Piece::held((b.lo, b.hi), self.grid.dims);
            self.raw_piece(lo, hi).map(|p| p.smallest_positive())
        };
        let local = smallest.map(|s| s.unwrap_or(f32::INFINITY).to_le_bytes().to_vec());
        let all = agree(mpi, local).map_err(|e| failure(view, &self.name, e))?;
        let floor = (all.iter())
            .filter_map(|m| m.as_slice().try_into().ok().map(f32::from_le_bytes))
            .fold(f32::INFINITY, f32::min);
        if floor == f32::INFINITY {
            return Err(CliError::input(format!(
                "--log: {}: a log scale needs a positive value, and the volume has none",
                self.name
            )));
        }
        self.log_floor = Some(floor);
        Ok(())
    }

    /// The voxels `lo..hi` as read or generated, before `--log`.
    fn raw_piece(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
        if let Some(spec) = &self.generate {
            // Checked before it is made: a box over the limit is refused
            // without allocating it.
            let dims: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
            let grid = (dims, self.grid.spacing, volray_core::SampleType::F32);
            self.fits(grid)?;
            return volray_data::generate_box(spec, lo, hi).map_err(|e| e.to_string());
        }
        match (&self.whole, &self.sent) {
            (Some(whole), _) => Ok(whole.sub_box(lo, hi)),
            (None, Some(sent)) => Ok(sent.clone()),
            (None, None) => Err(format!("{}: rank 0 sent no piece", self.name)),
        }
    }
}

/// The held piece (with ghosts) of the box `lo..hi`, or `None` if empty.
fn held_piece(volume: &Volume, lo: [usize; 3], hi: [usize; 3], dims: [usize; 3]) -> Option<Volume> {
    if (0..3).any(|a| lo[a] >= hi[a]) {
        return None;
    }
    let (lo, hi) = volray_core::Piece::held((lo, hi), dims);
    Some(volume.sub_box(lo, hi))
}

/// The grid, whether every rank reads its own box, and whether NaN marks
/// empty space, as rank 0 tells the others.
fn describe(input: &Input, local: bool) -> Vec<u8> {
    let v = &input.volume;
    let nan_is_empty = input.non_finite(NonFinite::Refuse) == NonFinite::Transparent;
    let mut out = grid_bytes(v);
    out.push(local as u8);
    out.push(nan_is_empty as u8);
    out
}

/// A volume's grid on the wire: dims (3 × `u64`), origin and spacing
/// (6 × `f64`), little-endian: 72 bytes.
fn grid_bytes(v: &Volume) -> Vec<u8> {
    let mut out = Vec::with_capacity(72);
    for d in v.dims() {
        out.extend_from_slice(&(d as u64).to_le_bytes());
    }
    for x in v
        .origin()
        .to_array()
        .into_iter()
        .chain(v.spacing().to_array())
    {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

/// The grid of [`grid_bytes`] (`b` at least 72 bytes).
fn parse_grid(b: &[u8]) -> GridFrame {
    let u = |i: usize| u64::from_le_bytes(b[8 * i..8 * i + 8].try_into().unwrap()) as usize;
    let f = |i: usize| f64::from_le_bytes(b[8 * i..8 * i + 8].try_into().unwrap());
    GridFrame {
        dims: [u(0), u(1), u(2)],
        origin: DVec3::new(f(3), f(4), f(5)),
        spacing: DVec3::new(f(6), f(7), f(8)),
    }
}

fn parse_header(b: &[u8]) -> (GridFrame, bool, bool) {
    (parse_grid(b), b[72] != 0, b[73] != 0)
}

/// A piece on the wire: dims (3 × u64), origin and spacing (6 × f64), the
/// labels flag, then its samples as little-endian `f32`.
fn encode_piece(v: &Volume) -> Vec<u8> {
    let mut out = grid_bytes(v);
    out.reserve(1 + 4 * v.len());
    out.push(v.is_labels() as u8);
    for x in v.samples().to_f32_vec() {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

fn decode_piece(b: &[u8]) -> Option<Volume> {
    if b.len() < 73 {
        return None;
    }
    let (grid, labels) = (parse_grid(b), b[72] != 0);
    let data: Vec<f32> = (b[73..].chunks_exact(4))
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let mut v = Volume::new(grid.dims, data)
        .ok()?
        .with_spacing(grid.spacing)
        .ok()?
        .with_origin(grid.origin)
        .ok()?;
    v.set_labels(labels);
    Some(v)
}

impl Source for CliSource {
    fn grid(&self) -> GridFrame {
        self.grid
    }

    fn read(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
        let piece = self.raw_piece(lo, hi)?;
        let piece = match self.log_floor {
            Some(smallest) => piece.to_log10_above(smallest),
            None => piece,
        };
        self.fits((piece.dims(), piece.spacing(), piece.sample_type()))?;
        Ok(piece)
    }
}

impl CliSource {
    /// Whether a piece of this grid fits this rank's `--max-memory`.
    fn fits(&self, grid: ([usize; 3], DVec3, volray_core::SampleType)) -> Result<(), String> {
        let need = crate::memory::render_bytes(grid, &self.settings, self.non_finite, 0);
        if need > u128::from(self.max_memory) {
            let [x, y, z] = grid.0;
            return Err(format!(
                "{}: this rank's piece, {x}x{y}x{z} voxels with its ghost layers, needs {} to render, over --max-memory {}: run on more ranks",
                self.name,
                format_bytes(need),
                format_bytes(u128::from(self.max_memory)),
            ));
        }
        Ok(())
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return 0.0;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn print_bench(
    name: &str,
    s: &RenderSettings,
    d: &Distributed<'_, Mpi>,
    per_frame: &[Vec<RankTimes>],
    walls: &[f64],
    threads: usize,
) {
    let ranks = d.decomposition().boxes.len();
    let timed = &per_frame[1..];
    println!(
        "volray bench (distributed): {name}, {}x{}, {ranks} ranks x {threads} threads, {} frames after a warm-up; medians",
        s.width,
        s.height,
        timed.len()
    );
    println!(
        "{:>4} {:>12} {:>12} {:>9} {:>9} {:>9} {:>10} {:>9} {:>11}",
        "rank",
        "owned",
        "held",
        "read ms",
        "class ms",
        "cast ms",
        "compose ms",
        "gather ms",
        "sent bytes"
    );
    for r in 0..ranks {
        let col = |f: &dyn Fn(&RankTimes) -> f64| median(timed.iter().map(|t| f(&t[r])).collect());
        let t0 = &per_frame[0][r];
        println!(
            "{:>4} {:>12} {:>12} {:>9.1} {:>9.2} {:>9.2} {:>10.2} {:>9.2} {:>11.0}",
            r,
            t0.owned_voxels,
            t0.held_voxels,
            ms(t0.read),
            col(&|t| ms(t.classify)),
            col(&|t| ms(t.cast)),
            col(&|t| ms(t.compose.composite)),
            col(&|t| ms(t.compose.gather)),
            col(&|t| t.compose.bytes_sent as f64),
        );
    }
    let compose = median(
        (timed.iter())
            .map(|t| {
                (t.iter())
                    .map(|r| ms(r.compose.composite) + ms(r.compose.gather))
                    .fold(0.0, f64::max)
            })
            .collect(),
    );
    println!(
        "frame (rank 0, wall): {:.2} ms; compositing and gather (slowest rank): {:.2} ms; read and agree: {:.1} ms",
        median(walls[1..].iter().map(|w| w * 1e3).collect()),
        compose,
        walls[0] * 1e3,
    );
}
