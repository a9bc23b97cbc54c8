//! `mpirun -np N volray render|bench …` (built with `--features mpi`): the
//! volume split among the ranks, each rendering its piece, the frame
//! composited on rank 0 (volray-distributed does the work; this is the
//! CLI's side: the input, `--max-memory` per rank, the output, the times).
//!
//! Files are read by range: every rank maps the file (raw, NRRD raw,
//! MetaImage raw, NIfTI `.nii`, `.npy`, MRC: volray-io's `MapPolicy`) and
//! copies out its box with its ghost layers, so that only those pages are
//! read. A file whose axes are stored in another order or sense (a CCP4
//! map with MAPC/MAPR/MAPS 2,1,3, a LAS NIfTI, an NRRD with a negative
//! direction) is mapped in its own axis order, and each rank copies the
//! file's box holding its piece and reorders just that
//! (`MapPolicy::AlwaysInFileOrder`, volray-io's `Reorientation`). A file
//! that cannot be mapped (compressed, DICOM, TIFF, HDF5, …) is read by
//! rank 0, which sends each rank its piece (a note on stderr says so);
//! the built-in fractal, a whole-grid process, is generated once by rank 0
//! and sent so. The other built-in sources generate only each rank's box.
//!
//! `--max-memory` is per rank and checked before anything of a piece's
//! size is allocated: each rank's piece with the copies it passes through
//! (the file's box before it is reordered, the piece before its log10, the
//! bytes received) and, on rank 0, the volume it reads whole with the
//! pieces it sends: agreed by every rank before any piece is read.
//!
//! `--labels`: each rank finds the labels of its piece, the sets are
//! joined, and every rank builds the one process's label transfer
//! function from them.

use crate::error::CliError;
use crate::flags::{BenchArgs, Channels, InputArgs, MixMode, RenderArgs, ViewArgs};
use crate::input::{self, Input};
use crate::render::{self, OutputKind};
use crate::session::render_failure;
use crate::settings::settings;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;
use volray_app::scene::{ChannelAxis, channel_axis};
use volray_core::SampleType;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::scene::{Look, Mix, SceneSettings};
use volray_core::{Camera, Image, NonFinite, RenderSettings, Volume};
use volray_distributed::frame::{Distributed, Failure, FrameError, RankTimes, Source, agree};
use volray_distributed::kd::Decomposition;
use volray_distributed::mpi::Mpi;
use volray_distributed::scene::DistributedScene;
use volray_distributed::transport::Transport;
use volray_io::{MapPolicy, Reorientation, format_bytes};

/// Whether this process runs under an MPI launcher, and so renders as one
/// rank of a distributed run.
pub fn launched() -> bool {
    volray_distributed::mpi::launched()
}

/// `volray render` under `mpirun`: one still image, written by rank 0.
pub fn render(args: &RenderArgs) -> Result<(), CliError> {
    ranked(|| render_rank(args))
}

/// [`render`] on this rank.
fn render_rank(args: &RenderArgs) -> Result<(), CliError> {
    if !args.scene.overlay.is_empty() || args.scene.frames.is_some() {
        return Err(CliError::input(
            "under mpirun, render writes one still image of one grid: --overlay (volumes on other grids) and --frames are rendered by one process",
        ));
    }
    if args.figure.any() {
        return Err(CliError::input(format!(
            "{}: under mpirun, render writes the bare frame: annotations are drawn by one process",
            args.figure.first_flag()
        )));
    }
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
    agree(&mpi, checked.map(|_| Vec::new()).map_err(|e| failed(&e)))
        .map_err(|e| failure(&args.view, "", e))?;
    if let Some(which) = &args.scene.channels {
        let image = channels(args, which, &mpi, settings)?;
        if let Some(image) = image {
            render::write_still(args, kind, &image)?;
        }
        return Ok(());
    }
    let source = CliSource::open(&mpi, &args.input, &args.view, &settings)?;
    let mode = source.non_finite;
    let name = source.name.clone();
    let fail = |e| failure(&args.view, &name, e);
    let mut d = Distributed::read(&mpi, &source, mode).map_err(fail)?;
    let settings = from_volume(&d, &args.view, (&name, source.window), settings)?;
    let (image, _) = d.render(&settings).map_err(fail)?;
    if let Some(image) = image {
        render::write_still(args, kind, &image)?;
    }
    Ok(())
}

/// `--channels` under `mpirun`: every channel split alike among the ranks
/// (the channels of one file share its grid), each rank reading its box
/// of each. The composite mix renders each rank's boxes as one scene of
/// pieces (volray-distributed's `DistributedScene`) and composites the
/// ranks' partial images; the additive mix renders each channel across
/// the ranks on its own and sums the colours on rank 0. Each channel's
/// look is one process's: its colour, its own value window (agreed by the
/// ranks), the opacity the look flags give or, by default, the one `--tf
/// auto` chooses from its own histogram (summed over the ranks). The
/// frame on rank 0.
fn channels(
    args: &RenderArgs,
    which: &Channels,
    mpi: &Mpi,
    settings: RenderSettings,
) -> Result<Option<Image>, CliError> {
    let view = &args.view;
    let look = &view.look;
    if look.labels || look.preset.is_some() || look.colormap.is_some() {
        return Err(CliError::input(
            "--channels colours each channel: --labels, --preset and --colormap do not apply",
        ));
    }
    let spec = args
        .input
        .input
        .as_deref()
        .unwrap_or(input::DEMO)
        .to_string();
    if volray_data::is_source_spec(&spec) || args.input.channel.is_some() {
        return Err(CliError::input(format!(
            "--channels: give a file holding several channels, without --channel ({spec})"
        )));
    }
    // How many channels, and which reader option picks one: rank 0 asks
    // the file (its metadata for a chunked store), every rank learns it.
    let probe = if mpi.rank() == 0 {
        channel_count(&args.input, &spec)
    } else {
        Ok((0, ChannelAxis::Channel))
    };
    let told = probe.map(|(n, axis)| {
        let mut bytes = (n as u32).to_le_bytes().to_vec();
        bytes.push(u8::from(axis == ChannelAxis::Channel));
        bytes
    });
    let all = agree(mpi, told.map_err(|e| failed(&e))).map_err(|e| failure(view, &spec, e))?;
    let word = |b: &[u8]| u32::from_le_bytes(b[..4].try_into().expect("four bytes")) as usize;
    let (count, axis) = (
        word(&all[0]),
        if all[0][4] == 1 {
            ChannelAxis::Channel
        } else {
            ChannelAxis::Time
        },
    );
    if axis == ChannelAxis::Time && args.input.frame.is_some() {
        return Err(CliError::input(format!(
            "--channels renders the time points of {spec} (one channel) together; --frame picks one: give one of them"
        )));
    }
    let (indices, colors) = crate::scene::picked(&args.scene, which, &spec, count)?;
    let sources = (indices.iter())
        .map(|&i| {
            CliSource::open(
                mpi,
                &crate::scene::pick(axis, &args.input, i),
                view,
                &settings,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mode = sources[0].non_finite;
    let fail = |e| failure(view, &spec, e);
    let projection = settings.blend.is_projection();
    let additive = match args.scene.mix {
        Some(MixMode::Composite) => false,
        Some(MixMode::Additive) | None => true,
    };
    if projection {
        return Err(CliError::input(
            "--channels under mpirun: the projections (--blend mip, ...) are rendered by one process",
        ));
    }
    // Each channel's settings: its colour; the opacity chosen from its
    // histogram where the look flags leave it.
    let channel_settings = |d: &Distributed<'_, Mpi>, i: usize, source: &CliSource| {
        let mut s = settings.clone();
        s.transfer_function.color = Some(volray_core::PiecewiseLinear::constant(colors[i]));
        let name = format!("{spec} (channel {})", indices[i]);
        from_volume(d, view, (&name, source.window), s)
    };
    if additive {
        // Each channel across the ranks on its own, over black; rank 0
        // sums the colours and puts the background behind what lets it
        // through.
        let mut sum: Option<Vec<[f32; 4]>> = None;
        for (i, source) in sources.iter().enumerate() {
            let mut d = Distributed::read(mpi, source, mode).map_err(fail)?;
            let mut s = channel_settings(&d, i, source)?;
            s.background = [0.0; 3];
            let (image, _) = d.render(&s).map_err(fail)?;
            if let Some(image) = image {
                let acc =
                    sum.get_or_insert_with(|| vec![[0.0, 0.0, 0.0, 1.0]; image.pixels().len()]);
                for (a, p) in acc.iter_mut().zip(image.pixels()) {
                    // The image's alpha is 1 − T: T multiplies.
                    *a = [a[0] + p[0], a[1] + p[1], a[2] + p[2], a[3] * (1.0 - p[3])];
                }
            }
        }
        let bg = settings.background;
        return Ok(sum.map(|acc| {
            let pixels = (acc.into_iter())
                .map(|[r, g, b, t]| {
                    [
                        (r + t * bg[0]).min(1.0),
                        (g + t * bg[1]).min(1.0),
                        (b + t * bg[2]).min(1.0),
                        1.0 - t,
                    ]
                })
                .collect();
            Image::from_pixels(settings.width, settings.height, pixels).expect("the frame's size")
        }));
    }
    // Each channel read, and its look from its statistics (agreed across
    // the ranks), before the scene takes its renderer.
    let mut volumes = Vec::with_capacity(sources.len());
    let mut looks = Vec::with_capacity(sources.len());
    for (i, source) in sources.iter().enumerate() {
        let d = Distributed::read(mpi, source, mode).map_err(fail)?;
        looks.push(Look::of(&channel_settings(&d, i, source)?));
        volumes.push(d);
    }
    let mut d = DistributedScene::of(volumes).map_err(fail)?;
    let request = SceneSettings {
        settings: settings.clone(),
        looks,
        mix: Mix::Composite,
    };
    let (image, _) = d.render(&request).map_err(fail)?;
    Ok(image)
}

/// INPUT's channels, as rank 0 finds them: how many, and along which
/// axis (`scene::channel_axis`).
fn channel_count(args: &InputArgs, spec: &str) -> Result<(usize, ChannelAxis), CliError> {
    let path = std::path::PathBuf::from(spec);
    let max_memory = args
        .max_memory
        .unwrap_or_else(volray_io::default_max_memory);
    let opts = input::read_options(args, spec, &path, max_memory, MapPolicy::IfLarger)?;
    if let Some(lazy) = volray_io::open_lazy(&path, &opts)? {
        return Ok(channel_axis(&lazy.info));
    }
    let input = input::load_with(args, MapPolicy::AlwaysInFileOrder)?;
    Ok(input
        .file
        .map_or((1, ChannelAxis::Channel), |(_, info)| channel_axis(&info)))
}

/// `volray bench` under `mpirun`: per-rank times of each stage, medians
/// over the frames (each turned half a degree further, as `bench` does),
/// printed by rank 0.
pub fn bench(args: &BenchArgs) -> Result<(), CliError> {
    ranked(|| bench_rank(args))
}

/// [`bench`] on this rank.
fn bench_rank(args: &BenchArgs) -> Result<(), CliError> {
    if args.peers.is_some() {
        return Err(CliError::input(
            "under mpirun, bench renders INPUT: --peers runs in one process",
        ));
    }
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
        let base = from_volume(&d, &args.view, (&name, source.window), base.clone())?;
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

/// Whether [`initialize`] has started MPI in this process.
static STARTED: AtomicBool = AtomicBool::new(false);

/// MPI, started.
fn initialize() -> Result<Mpi, CliError> {
    let mpi = Mpi::initialize().ok_or_else(|| CliError::io("MPI could not be initialised"))?;
    STARTED.store(true, Ordering::SeqCst);
    Ok(mpi)
}

/// Runs one rank's command, with a panic that nothing caught ending every
/// rank (`MPI_Abort`) once MPI has started: else the panicking rank would
/// wait in `MPI_Finalize` and the others for it. The abort comes after
/// unwinding, not in the panic hook: a hook runs before unwinding, when a
/// decoder's panic that its reader catches ([`volray_io::panics`]) cannot
/// be told from a bug, and aborting there ended the whole job for a
/// corrupt file that every rank would have reported on one line.
fn ranked(run: impl FnOnce() -> Result<(), CliError>) -> Result<(), CliError> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(result) => result,
        Err(_) if STARTED.load(Ordering::SeqCst) => volray_distributed::mpi::abort_world(101),
        Err(payload) => std::panic::resume_unwind(payload),
    }
}

/// `settings` with what the flags leave to the volume, as one process
/// takes it ([`crate::settings::from_input`]): with `--labels`, the label
/// transfer function of the labels every rank found, joined; otherwise
/// `--tf auto` (the default) chosen from the whole volume's histogram,
/// summed over the ranks' owned voxels, within the file's display window
/// where it gives one.
fn from_volume(
    d: &Distributed<'_, Mpi>,
    view: &ViewArgs,
    (name, window): (&str, Option<(f64, f64)>),
    mut settings: RenderSettings,
) -> Result<RenderSettings, CliError> {
    let fail = |e| failure(view, name, e);
    crate::settings::file_window(&view.look, &mut settings.transfer_function, window);
    let look = crate::settings::look(&view.look);
    if view.look.labels {
        let found = d
            .labels(volray_core::transfer::labels::MAX_LABELS)
            .map_err(fail)?;
        let found = volray_options::labels_found(found, name).map_err(crate::settings::refused)?;
        crate::settings::label_transfer_function(
            &view.look,
            &mut settings.transfer_function,
            &found,
            name,
        )?;
        return Ok(settings);
    }
    if look.auto_tf()
        && let Some(histogram) = d
            .histogram(volray_core::transfer::auto::BINS)
            .map_err(fail)?
    {
        volray_options::apply_auto(&look, &mut settings.transfer_function, &histogram);
    }
    Ok(settings)
}

/// A failed distributed step as the CLI's error: the same line on every
/// rank.
fn failure(view: &ViewArgs, name: &str, e: FrameError) -> CliError {
    match e {
        FrameError::Render(e) => render_failure(view, name, e),
        FrameError::Rank {
            rank,
            message,
            bad_input: true,
        } => CliError::input(format!("rank {rank}: {message}")),
        FrameError::Rank { rank, message, .. } => CliError::io(format!("rank {rank}: {message}")),
        e => CliError::io(e.to_string()),
    }
}

/// A rank's error as the ranks agree on it, its exit code kept: a
/// corrupt file is bad input (1) on every rank, as in one process.
fn failed(e: &CliError) -> Failure {
    Failure {
        message: e.to_string(),
        bad_input: e.code == 1,
    }
}

/// This rank's view of INPUT: the whole volume mapped (in the file's own
/// axis order where `reorientation` says so), a built-in source's spec,
/// or the piece rank 0 sent it.
struct CliSource {
    name: String,
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
    window: Option<(f64, f64)>,
    /// `--log` and `--labels` as given.
    log: bool,
    labels: bool,
    max_memory: u64,
    settings: RenderSettings,
    non_finite: NonFinite,
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
        let mut source = CliSource {
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
            log: view.look.log,
            labels: view.look.labels,
            max_memory,
            settings: settings.clone(),
            non_finite: requested,
        };
        if volray_data::is_source_spec(&spec) && !generated_whole(&spec) {
            source.generate_boxes(mpi, args, view)?;
            return Ok(source);
        }
        // A chunked store: every rank opens it from its metadata and
        // decodes the chunks of its own box, and nothing else.
        if !volray_data::is_source_spec(&spec) {
            let path = std::path::PathBuf::from(&spec);
            let opened = input::read_options(args, &spec, &path, max_memory, MapPolicy::IfLarger)
                .and_then(|opts| volray_io::open_lazy(&path, &opts).map_err(CliError::from));
            let status = opened
                .as_ref()
                .map(|lazy| vec![u8::from(lazy.is_some())])
                .map_err(failed);
            let all = agree(mpi, status).map_err(|e| failure(view, &spec, e))?;
            if all.iter().all(|m| m.first() == Some(&1)) {
                let lazy = opened.ok().flatten().expect("agreed");
                source.grid = lazy.source.grid();
                source.window = lazy.info.display_window();
                let stored = lazy.source.sample_type();
                source.chunked = Some(lazy.source);
                let fits = source.check_piece(mpi, Route::Chunked { stored });
                agree(mpi, fits.map(|_| Vec::new()).map_err(Failure::bad_input))
                    .map_err(|e| failure(view, &spec, e))?;
                source.agree_log_floor(mpi, view)?;
                return Ok(source);
            }
        }
        // A file mapped wherever it can be, in its own axis order if need
        // be; else read whole by rank 0 (a fractal generated whole).
        let load = || input::load_with(args, MapPolicy::AlwaysInFileOrder);
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
        let all = agree(mpi, header.map_err(failed)).map_err(|e| failure(view, &spec, e))?;
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
        agree(mpi, fits.map(|_| Vec::new()).map_err(Failure::bad_input))
            .map_err(|e| failure(view, &spec, e))?;
        if header.local {
            // Every rank maps the file itself.
            let input = match first {
                Ok(Some(input)) => Ok(input),
                _ => load(),
            };
            let status = input.as_ref().map(|_| Vec::new()).map_err(failed);
            agree(mpi, status).map_err(|e| failure(view, &spec, e))?;
            let input = input.expect("agreed");
            source.reorientation = input.file.and_then(|(_, info)| info.reorientation);
            source.whole = Some(input.volume);
            source.agree_log_floor(mpi, view)?;
            return Ok(source);
        }
        // Rank 0 sends each rank its piece.
        let decomposition = Decomposition::new(source.grid.dims, mpi.size());
        if mpi.rank() == 0 {
            let input: Input = first.ok().flatten().expect("rank 0 read the file");
            if volray_data::is_source_spec(&spec) {
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

    /// A built-in source sampled box by box: every rank generates its own
    /// box (the grid from a 2³ box of it, the same on every rank).
    fn generate_boxes(
        &mut self,
        mpi: &Mpi,
        args: &InputArgs,
        view: &ViewArgs,
    ) -> Result<(), CliError> {
        let spec = self.name.clone();
        let probe = input::source_grid(args, &spec).and_then(|n| {
            volray_data::generate_box(&spec, [0; 3], [2; 3])
                .map(|v| (n, v))
                .map_err(CliError::from)
        });
        let status = probe.as_ref().map(|_| Vec::new()).map_err(failed);
        agree(mpi, status).map_err(|e| failure(view, &spec, e))?;
        let (n, corner) = probe.expect("agreed");
        self.grid = GridFrame {
            dims: [n; 3],
            origin: corner.origin(),
            spacing: corner.spacing(),
        };
        self.generate = Some(spec.clone());
        let fits = self.check_piece(mpi, Route::Generated);
        agree(mpi, fits.map(|_| Vec::new()).map_err(Failure::bad_input))
            .map_err(|e| failure(view, &spec, e))?;
        self.agree_log_floor(mpi, view)
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
    fn check_piece(&self, mpi: &Mpi, route: Route) -> Result<(), String> {
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
            let [x, y, z] = dims;
            return Err(format!(
                "{}: this rank's piece, {x}x{y}x{z} voxels with its ghost layers, needs {} to read and render, over --max-memory {}: run on more ranks",
                self.name,
                format_bytes(need),
                format_bytes(u128::from(self.max_memory)),
            ));
        }
        Ok(())
    }

    /// On rank 0, which holds `whole` (read or generated whole) to send
    /// the pieces: whether the volume, rank 0's own piece and the largest
    /// piece on its way out (its samples and their bytes) fit
    /// `--max-memory`, before any piece is cut.
    fn check_scatter(&self, mpi: &Mpi, whole: &Volume) -> Result<(), String> {
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
            let how = if volray_data::is_source_spec(&self.name) {
                "generates the fractal whole"
            } else {
                "reads the file whole (its format cannot be read by range)"
            };
            return Err(format!(
                "{}: rank 0 {how} to send each rank its piece: the volume ({}) with the pieces it cuts needs {}, over --max-memory {}",
                self.name,
                format_bytes(volume),
                format_bytes(need),
                format_bytes(u128::from(self.max_memory)),
            ));
        }
        Ok(())
    }

    /// For `--log`: the smallest positive value over every rank's piece
    /// (the pieces cover the volume), as one process takes it over the
    /// whole volume.
    fn agree_log_floor(&mut self, mpi: &Mpi, view: &ViewArgs) -> Result<(), CliError> {
        if !self.log {
            return Ok(());
        }
        let smallest = match self.held_box(mpi) {
            None => Ok(None),
            Some((lo, hi)) => self.raw_piece(lo, hi).map(|p| p.smallest_positive()),
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

    /// The voxels `lo..hi` as read or generated, before `--log` (their
    /// size checked by [`CliSource::check_piece`] when the source was
    /// opened).
    fn raw_piece(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
        if let Some(spec) = &self.generate {
            return volray_data::generate_box(spec, lo, hi).map_err(|e| e.to_string());
        }
        if let Some(chunked) = &self.chunked {
            return chunked.read_box(lo, hi);
        }
        match (&self.whole, &self.reorientation, &self.sent) {
            (Some(file), Some(r), _) => {
                (r.sub_box(file, lo, hi)).map_err(|e| format!("{}: its piece: {e}", self.name))
            }
            (Some(whole), None, _) => Ok(whole.sub_box(lo, hi)),
            (None, _, Some(sent)) => Ok(sent.clone()),
            (None, _, None) => Err(format!("{}: rank 0 sent no piece", self.name)),
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

fn grid_of(v: &Volume) -> GridFrame {
    GridFrame {
        dims: v.dims(),
        origin: v.origin(),
        spacing: v.spacing(),
    }
}

/// A grid on the wire: dims (3 × `u64`), origin and spacing (6 × `f64`),
/// little-endian: 72 bytes.
fn grid_bytes(g: &GridFrame) -> Vec<u8> {
    let mut out = Vec::with_capacity(72);
    for d in g.dims {
        out.extend_from_slice(&(d as u64).to_le_bytes());
    }
    for x in g.origin.to_array().into_iter().chain(g.spacing.to_array()) {
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

/// A piece on the wire: its grid ([`grid_bytes`]), the labels flag, then
/// its samples as little-endian `f32`, written straight from its own
/// type (no `f32` copy of the piece on the way).
fn encode_piece(v: &Volume) -> Vec<u8> {
    let mut out = grid_bytes(&grid_of(v));
    out.reserve(1 + 4 * v.len());
    out.push(v.is_labels() as u8);
    volray_core::with_samples!(v.samples(), |data| {
        for x in data.iter() {
            out.extend_from_slice(&volray_core::Sample::to_f32(*x).to_le_bytes());
        }
    });
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

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, String> {
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
