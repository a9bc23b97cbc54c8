//! `mpirun -np N volray render|bench …` (built with `--features mpi`): the
//! volume split among the ranks, each rendering its piece, the frame
//! composited on rank 0 (volray-distributed does the work; this is the
//! front end's side above it: the input, `--max-memory` per rank, the
//! channels, the times; the front end checks its flags and writes the
//! output). Behind volray-app's `mpi` feature.
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

//!
//! Files: `mod.rs` (a still, its channels; MPI started, a panic ending
//! every rank), `job.rs` (what a job reads and looks like, the failures
//! the ranks agree on), `source.rs` (each rank's piece),
//! `wire.rs` (grids and pieces as bytes), `bench.rs` (the times' table).

mod bench;
mod job;
mod source;
mod wire;

pub use bench::bench;
pub use job::{Job, Words};

use crate::error::AppError;
use crate::input::{Request, Spec};
use job::{frame, from_volume};
use source::RankSource;
use std::sync::atomic::{AtomicBool, Ordering};
use volray_core::Image;
use volray_core::scene::{Look, Mix, SceneSettings};
use volray_distributed::frame::{Distributed, agree};
pub use volray_distributed::mpi::Mpi;
use volray_distributed::scene::DistributedScene;
use volray_distributed::transport::Transport;
use volray_io::MapPolicy;

/// Whether this process runs under an MPI launcher, and so renders as one
/// rank of a distributed run.
pub fn launched() -> bool {
    volray_distributed::mpi::launched()
}

/// Rank 0's `checked` (where it writes the frame, say), agreed by every
/// rank before any reads: the same failure on each.
pub fn agree_on(
    mpi: &Mpi,
    checked: Result<(), AppError>,
    words: Words<'_>,
) -> Result<(), AppError> {
    agree(mpi, checked.map(|_| Vec::new()).map_err(|e| words(&e)))
        .map(|_| ())
        .map_err(|e| frame("", e))
}

/// One still image of `job`'s input, split among the ranks: the frame on
/// rank 0, `None` on the others.
pub fn render(mpi: &Mpi, job: &Job, words: Words<'_>) -> Result<Option<Image>, AppError> {
    let source = RankSource::open(mpi, job, words)?;
    let mode = source.non_finite;
    let name = source.name.clone();
    let fail = |e| frame(&name, e);
    let mut d = Distributed::read(mpi, &source, mode).map_err(fail)?;
    let settings = from_volume(&d, &job.look, (&name, source.window), job.settings.clone())?;
    let (image, _) = d.render(&settings).map_err(fail)?;
    Ok(image)
}

/// The channels of a distributed `--channels` render: how many a file
/// holds and along which axis (`along_channels`: its channels, else its
/// time points), as rank 0 finds them from the file's [`volray_io::FileInfo`].
pub type AxisOf<'a> = &'a dyn Fn(&volray_io::FileInfo) -> (usize, bool);

/// Which channels, and their colours, given how many the file holds.
pub type Pick<'a> = &'a dyn Fn(usize) -> Result<(Vec<usize>, Vec<[f32; 3]>), AppError>;

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
pub fn channels(
    mpi: &Mpi,
    job: &Job,
    (axis_of, pick): (AxisOf<'_>, Pick<'_>),
    additive: bool,
    words: Words<'_>,
) -> Result<Option<Image>, AppError> {
    let settings = &job.settings;
    let spec = job.request.spec.name();
    // How many channels, and which reader option picks one: rank 0 asks
    // the file (its metadata for a chunked store), every rank learns it.
    let probe = if mpi.rank() == 0 {
        channel_count(&job.request, axis_of)
    } else {
        Ok((0, true))
    };
    let told = probe.map(|(n, along_channels)| {
        let mut bytes = (n as u32).to_le_bytes().to_vec();
        bytes.push(u8::from(along_channels));
        bytes
    });
    let all = agree(mpi, told.map_err(|e| words(&e))).map_err(|e| frame(&spec, e))?;
    let word = |b: &[u8]| u32::from_le_bytes(b[..4].try_into().expect("four bytes")) as usize;
    let (count, along_channels) = (word(&all[0]), all[0][4] == 1);
    if !along_channels && job.request.frame.is_some() {
        return Err(AppError::ChannelsAndFrame { spec });
    }
    let (indices, colors) = pick(count)?;
    let pick_one = |i: usize| Job {
        request: Request {
            channel: along_channels.then_some(i).or(job.request.channel),
            frame: (!along_channels).then_some(i).or(job.request.frame),
            ..job.request.clone()
        },
        settings: settings.clone(),
        look: job.look.clone(),
        non_finite: job.non_finite,
    };
    let sources = (indices.iter())
        .map(|&i| RankSource::open(mpi, &pick_one(i), words))
        .collect::<Result<Vec<_>, _>>()?;
    let mode = sources[0].non_finite;
    let fail = |e| frame(&spec, e);
    // Each channel's settings: its colour; the opacity chosen from its
    // histogram where the look flags leave it.
    let channel_settings = |d: &Distributed<'_, Mpi>, i: usize, source: &RankSource| {
        let mut s = settings.clone();
        s.transfer_function.color = Some(volray_core::PiecewiseLinear::constant(colors[i]));
        let name = format!("{spec} (channel {})", indices[i]);
        from_volume(d, &job.look, (&name, source.window), s)
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

/// INPUT's channels, as rank 0 finds them: how many, and whether along
/// its channels (`axis_of`).
fn channel_count(request: &Request, axis_of: AxisOf<'_>) -> Result<(usize, bool), AppError> {
    let max_memory = request.max_memory();
    let opts = crate::input::read_options(request, max_memory, MapPolicy::IfLarger)?;
    if let Spec::File(path) = &request.spec
        && let Some(lazy) = volray_io::open_lazy(path, &opts)?
    {
        return Ok(axis_of(&lazy.info));
    }
    let input = crate::input::load_with(request, MapPolicy::AlwaysInFileOrder)?;
    Ok(input.file.map_or((1, true), |(_, info)| axis_of(&info)))
}

/// Rayon's global pool of `threads` workers (default: one per core): MPI
/// is called from the main thread only, the rendering within a rank runs
/// on the pool.
pub fn threads(threads: Option<u16>) -> Result<(), rayon::ThreadPoolBuildError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n as usize);
    }
    builder.build_global()
}

/// Whether [`initialize`] has started MPI in this process.
static STARTED: AtomicBool = AtomicBool::new(false);

/// MPI, started; `None` if it could not be initialised.
pub fn initialize() -> Option<Mpi> {
    let mpi = Mpi::initialize()?;
    STARTED.store(true, Ordering::SeqCst);
    Some(mpi)
}

/// Runs one rank's command, with a panic that nothing caught ending every
/// rank (`MPI_Abort`) once MPI has started: else the panicking rank would
/// wait in `MPI_Finalize` and the others for it. The abort comes after
/// unwinding, not in the panic hook: a hook runs before unwinding, when a
/// decoder's panic that its reader catches ([`volray_io::panics`]) cannot
/// be told from a bug, and aborting there ended the whole job for a
/// corrupt file that every rank would have reported on one line.
pub fn ranked<T>(run: impl FnOnce() -> T) -> T {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(result) => result,
        Err(_) if STARTED.load(Ordering::SeqCst) => volray_distributed::mpi::abort_world(101),
        Err(payload) => std::panic::resume_unwind(payload),
    }
}
