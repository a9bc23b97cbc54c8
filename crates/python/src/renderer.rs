//! `Renderer` (a volume prepared once, rendered frame after frame at
//! `volray bench` speed) and `render` (one frame), with the GIL released
//! while rendering and Ctrl-C honoured: the frame renders on a worker
//! thread while the calling thread waits for it, asking Python for
//! pending signals every 20 ms of the wait (a finished frame returns at
//! once); on KeyboardInterrupt it stops the frame (volray-core's
//! `FrameRequest::stopped_by`: the work left is skipped) and raises.
//!
//! A lazy volume (`volume.rs`: a chunked file read from its metadata)
//! takes volray-lazy's road, as `volray render` does (volray-app's `plan`):
//! each frame picks its level (`level="auto"`: the coarsest whose voxels
//! are no larger than a pixel's footprint; else the level asked for, or
//! the volume's), then reads that level whole when its frame fits
//! `max_memory` (prepared as any volume, kept while frames need that
//! level: the same pixels as `read(path, level=N)` rendered) or renders
//! it piece by piece (volray-distributed's `Streamed`, kept likewise, the
//! labels and `tf="auto"` histogram found piece by piece once). A frame
//! in pieces stops at its next piece on Ctrl-C: `Streamed` has no stop
//! flag within a piece, so the piece being rendered finishes first.
//!
//! Files: this one (the renderer, its frames, Ctrl-C), `recipe.rs` (the
//! volume and its keywords, prepared within `max_memory`), `lazy.rs` (a
//! lazy volume's frames).

mod lazy;
mod recipe;

use crate::array::{self, ArrayBytes, Order};
use crate::errors::{
    app_error, io_error, option_error, render_error, settings_error, source_error, value_error,
};
use crate::figure::{self, FIGURE};
use crate::frame::Frame;
use crate::keywords::{self, CAMERA, FRAME, Keywords, VOLUME};
use crate::volume::{LazyFile, Volume};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use volray_annotate::figure::Annotations;
use volray_app::AppError;
use volray_app::memory::Budget;
use volray_app::plan::{self, Frames};
use volray_core::transfer::auto;
use volray_core::{
    FrameRequest, Image, NonFinite, Render, RenderError, RenderSettings, Rendered,
    Renderer as CoreRenderer, Volume as CoreVolume,
};
use volray_distributed::streamed::{StreamError, Streamed};
use volray_io::format_bytes;
use volray_lazy::{Chunked, Found, LookError, Plan};
use volray_options::level::LevelChoice;
use volray_options::{CameraOptions, LookOptions, Options};

/// How often the calling thread looks for Ctrl-C while a frame renders.
const SIGNAL_POLL: Duration = Duration::from_millis(20);

/// A volume prepared for rendering: its value range, bricks, and the
/// classified and lit bricks of earlier frames are kept, so that a loop
/// over views pays for them once. Over a numpy array the caller may
/// change, the samples are digested before each frame and the volume
/// prepared again when they changed (`digest.rs`).
#[pyclass(frozen, module = "volray")]
pub struct Renderer {
    recipe: Recipe,
    road: Road,
}

/// How frames reach the samples.
enum Road {
    /// The samples in memory (an array, a volume read whole), prepared
    /// once: the volume as last prepared. Frames take a reference and
    /// render from it; a frame that finds the samples changed prepares
    /// them again and puts its result here.
    Memory(Mutex<Arc<Prepared>>),
    /// A lazy volume: the level and the way each frame needs.
    Lazy(Box<LazyRoad>),
}

/// A lazy volume's frames (see the module documentation).
struct LazyRoad {
    volume: Py<Volume>,
    choice: LevelChoice,
    /// Set on Ctrl-C: the pieces' reads fail from then on
    /// (`Chunked::stoppable`), so a frame in pieces stops at its next one.
    stop: Arc<AtomicBool>,
    /// Locked only while detached from Python (never while waiting for
    /// the GIL), so frames of one renderer from several threads queue.
    state: Mutex<LazyState>,
}

#[derive(Default)]
struct LazyState {
    /// The level open now (stoppable by `stop`).
    chunked: Option<Chunked>,
    way: Way,
    /// The settings of the last frame, which `value_range` splits by.
    settings: Option<RenderSettings>,
}

/// How the level of the last frame is rendered, kept for the next.
#[derive(Default)]
enum Way {
    #[default]
    None,
    /// Read whole and prepared as any volume.
    Whole {
        level: usize,
        prepared: Arc<Prepared>,
    },
    /// Rendered piece by piece; what the look left to the volume, found
    /// once.
    Pieces {
        level: usize,
        streamed: Box<Streamed>,
        found: Found,
    },
}

impl Way {
    fn level(&self) -> Option<usize> {
        match self {
            Way::None => None,
            Way::Whole { level, .. } | Way::Pieces { level, .. } => Some(*level),
        }
    }
}

/// What a lazy frame renders after its way is settled.
enum Next {
    Whole(Arc<Prepared>),
    Pieces,
}

/// The volume and the volume-level options: what a renderer is prepared
/// from, again whenever the samples change.
pub(crate) struct Recipe {
    source: Source,
    /// Spacing and origin given with a `Volume` (an array's are in its
    /// `Source`).
    spacing: Option<[f64; 3]>,
    origin: Option<[f64; 3]>,
    /// Each world axis stretched for drawing (`scale=`), else `None` for
    /// the default rule (volray-app's `display`): its file's axis units
    /// (`display`) and modality (a CT's look, volray-app's `look`).
    scale: Option<[f64; 3]>,
    display: Option<volray_io::FileInfo>,
    /// What the volume-level options fixed.
    pub labels: bool,
    log: bool,
    pub nonfinite: NonFinite,
    pub max_memory: u64,
    pub name: String,
    /// The file's display window (an OME-Zarr `omero` window), the
    /// default `range`.
    window: Option<(f64, f64)>,
    /// The colours the file gives its labels (a DICOM Segmentation's
    /// segments), which `labels=True` draws them in.
    label_colours: Vec<(i64, [f32; 3])>,
}

/// Where the samples come from.
enum Source {
    /// A `Volume`: its samples, watched unless read-only (`read`'s).
    Volume(Py<Volume>),
    /// An array, or anything numpy takes: the caller's, watched, and read
    /// as a `Volume` again (copied again where it was copied) whenever it
    /// changes.
    Array {
        object: Py<PyAny>,
        order: Order,
        spacing: Option<[f64; 3]>,
        origin: Option<[f64; 3]>,
    },
}

/// What is found once per volume's samples.
pub(crate) struct Prepared {
    pub inner: CoreRenderer<'static>,
    pub known: Known,
    /// The digest of the samples this was prepared from, where watched.
    pub digest: Option<u64>,
}

/// What the options may leave to the volume, found once: the labels
/// present (with `labels=True`), or the histogram the automatic transfer
/// function is chosen from (else).
pub(crate) struct Known {
    pub labels: Option<Vec<i64>>,
    pub histogram: Option<auto::Robust>,
}

impl Renderer {
    /// The renderer of `volume` (an array or a `Volume`) with the
    /// volume-level keywords of `k`.
    fn build(py: Python<'_>, volume: &Bound<'_, PyAny>, k: &Keywords<'_>) -> PyResult<Self> {
        let level = level_choice(k)?;
        let recipe = Recipe::build(volume, k)?;
        let lazy = match &recipe.source {
            Source::Volume(v) if v.get().lazy.is_some() => Some(v.clone_ref(py)),
            _ => None,
        };
        if let Some(volume) = lazy {
            let own = volume.get().level().unwrap_or(0);
            let choice = level.unwrap_or(LevelChoice::Index(own));
            if let LevelChoice::Index(n) = choice {
                let levels = volume
                    .get()
                    .lazy
                    .as_ref()
                    // A file read box by box without levels (an HDF5 or
                    // NetCDF-4 dataset) is its one level.
                    .map_or(1, |l| l.chunked.levels().len().max(1));
                check_level(&recipe.name, n, levels)?;
            }
            return Ok(Renderer {
                recipe,
                road: Road::Lazy(Box::new(LazyRoad {
                    volume,
                    choice,
                    stop: Arc::new(AtomicBool::new(false)),
                    state: Mutex::new(LazyState::default()),
                })),
            });
        }
        if level.is_some() {
            return Err(level_in_memory(&recipe.name));
        }
        let digest = recipe.digest(py, None)?;
        // The caches' budget for the frame `k` asks (`render`), or a
        // default one (`Renderer`): a later frame that leaves less room
        // prepares the volume again (`current`).
        let (_, first) = recipe.settings_of(k)?;
        let prepared = recipe.prepare(py, digest, &first)?;
        Ok(Renderer {
            recipe,
            road: Road::Memory(Mutex::new(Arc::new(prepared))),
        })
    }

    /// The volume prepared from the samples as they are now, for a frame
    /// of `settings` (if one is to be rendered): the last one, or (the
    /// samples changed since, or its brick caches may take more than the
    /// frame leaves them under `max_memory`) a new one.
    fn current(
        &self,
        py: Python<'_>,
        memory: &Mutex<Arc<Prepared>>,
        pool: Option<&rayon::ThreadPool>,
        settings: Option<&RenderSettings>,
    ) -> PyResult<Arc<Prepared>> {
        // The lock is held only to clone or replace the `Arc`, never
        // across a call that waits for the GIL or another thread.
        let last = Arc::clone(&memory.lock().unwrap_or_else(|e| e.into_inner()));
        let digest = self.recipe.digest(py, pool)?;
        let (mode, max_memory) = (self.recipe.nonfinite, self.recipe.max_memory);
        let fits = settings.is_none_or(|s| last.fits(s, mode, max_memory));
        if digest == last.digest && fits {
            return Ok(last);
        }
        let settings = match settings {
            Some(settings) => settings,
            None => {
                &self
                    .recipe
                    .settings_of(&Keywords::new(None, &[], "Renderer")?)?
                    .1
            }
        };
        // The last one's caches go before the new one is made, unless a
        // frame of another thread still holds it.
        drop(last);
        let fresh = Arc::new(self.recipe.prepare(py, digest, settings)?);
        *memory.lock().unwrap_or_else(|e| e.into_inner()) = Arc::clone(&fresh);
        Ok(fresh)
    }

    /// The options and settings of a frame with the frame keywords of
    /// `k`, and its pool of workers (`threads=`).
    fn settings_of(
        &self,
        k: &Keywords<'_>,
    ) -> PyResult<(Options, RenderSettings, Option<rayon::ThreadPool>)> {
        let (options, settings) = self.recipe.settings_of(k)?;
        let pool = keywords::threads(k)?.map(pool).transpose()?;
        Ok((options, settings, pool))
    }

    /// One frame with the frame keywords of `k`; `fresh`: the renderer
    /// was prepared just now, so its samples need no second digest.
    fn frame(&self, py: Python<'_>, k: &Keywords<'_>, fresh: bool) -> PyResult<Frame> {
        let (options, settings, pool) = self.settings_of(k)?;
        let what = figure::annotations(k)?;
        let memory = match &self.road {
            Road::Memory(memory) => memory,
            Road::Lazy(lazy) => return self.lazy_frame(py, lazy, &options, settings, pool, &what),
        };
        let prepared = match fresh {
            true => Arc::clone(&memory.lock().unwrap_or_else(|e| e.into_inner())),
            false => self.current(py, memory, pool.as_ref(), Some(&settings))?,
        };
        self.render_prepared(py, &prepared, &options, settings, pool.as_ref(), &what)
    }

    /// A frame of a prepared volume, with what the options leave to it,
    /// annotated as `what` asks.
    fn render_prepared(
        &self,
        py: Python<'_>,
        prepared: &Prepared,
        options: &Options,
        mut settings: RenderSettings,
        pool: Option<&rayon::ThreadPool>,
        what: &Annotations,
    ) -> PyResult<Frame> {
        let name = &self.recipe.name;
        (self.recipe).leave_to_volume(&prepared.known, options, &mut settings)?;
        self.recipe.check_memory(&prepared.inner, &settings)?;
        let stop = AtomicBool::new(false);
        let inner = &prepared.inner;
        let settings = &settings;
        let (rendered, interrupt) = py.detach(|| {
            interruptible(pool, &stop, |report| {
                let request = FrameRequest::new(settings).reporting(report);
                inner.render(request.stopped_by(&stop)).map(Rendered::image)
            })
        });
        if let Some(e) = interrupt {
            return Err(e);
        }
        let mut image = rendered
            .map_err(|panic| internal_error(name, &panic))?
            .map_err(|e| render_error(e, &options.camera, name))?;
        if what.any() {
            let bounds = inner.volume().bounds();
            let facts = self.recipe.facts(py);
            figure::draw(
                &mut image,
                what,
                inner,
                settings,
                options,
                &facts,
                &[bounds],
                bounds,
            )?;
        }
        Ok(Frame { image })
    }
}

/// What rendering a frame of `settings` may take beyond the samples
/// (a numpy array's are the caller's) with no brick cache (volray-app's
/// `memory`, as the command line counts it).
pub(crate) fn need(
    renderer: &CoreRenderer<'_>,
    settings: &RenderSettings,
    mode: NonFinite,
) -> u128 {
    volray_app::memory::frame_bytes(renderer.volume(), settings, mode, &budget(0))
}

/// What Python's frames are held to: `max_memory`; the frame is handed
/// over (no PNG), and the samples are the caller's.
fn budget(max_memory: u64) -> Budget {
    Budget {
        limit: max_memory,
        extra: 0,
        samples_count: false,
    }
}

/// The budget of the brick caches for frames of `settings`: the
/// library's default, or what is left under `max_memory` after such a
/// frame when that is less, 0 where even that is over (volray-app's
/// `memory::cache_budget`, as the command line budgets its frame). The
/// budget changes speed, never pixels.
///
/// Core fixes a renderer's budget when it is built, and a Python
/// renderer is built before its frames are asked for: with the first
/// frame's settings for `render`, the defaults for `Renderer`. A frame
/// that leaves the caches less than that budget (a larger image,
/// `post_classification`, shadows: [`Prepared::fits`]) has the volume
/// prepared again with the smaller one, which the frames after keep (it
/// never grows back: each frame stays within `max_memory`, and the
/// volume is prepared again at most once per smaller budget).
pub(crate) fn cache_budget(
    renderer: &CoreRenderer<'_>,
    settings: &RenderSettings,
    mode: NonFinite,
    max_memory: u64,
) -> usize {
    let volume = renderer.volume();
    volray_app::memory::cache_budget(volume, "", settings, mode, budget(max_memory)).unwrap_or(0)
}

impl Prepared {
    /// Whether a frame of `settings` leaves this volume's brick caches
    /// their budget under `max_memory` (see [`cache_budget`]); a frame
    /// over the limit whatever the caches is refused, not prepared for.
    pub(crate) fn fits(&self, settings: &RenderSettings, mode: NonFinite, max_memory: u64) -> bool {
        let volume = self.inner.volume();
        let room = volray_app::memory::cache_budget(volume, "", settings, mode, budget(max_memory));
        room.ok()
            .is_none_or(|room| room >= self.inner.cache_budget())
    }
}

/// A pool of `threads` workers.
pub(crate) fn pool(threads: usize) -> PyResult<rayon::ThreadPool> {
    let builder = rayon::ThreadPoolBuilder::new().num_threads(threads);
    builder.build().map_err(|e| {
        pyo3::exceptions::PyOSError::new_err(format!("cannot start worker threads: {e}"))
    })
}

#[pymethods]
impl Renderer {
    /// `Renderer(volume, *, spacing=None, origin=None, order="xyz",
    /// labels=None, log=False, nonfinite="refuse", max_memory=None,
    /// level=None)`: `level` ("auto" or a number) picks the level of a
    /// lazy volume's file each frame renders.
    #[new]
    #[pyo3(signature = (volume, **kwargs))]
    fn new(
        py: Python<'_>,
        volume: &Bound<'_, PyAny>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let k = Keywords::new(kwargs, &[VOLUME], "Renderer")?;
        Renderer::build(py, volume, &k)
    }

    /// One frame: the keywords of `render` but the volume's own.
    #[pyo3(signature = (**kwargs))]
    fn render(&self, py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Frame> {
        let k = Keywords::new(kwargs, &[CAMERA, FRAME, FIGURE], "render")?;
        self.frame(py, &k, false)
    }

    /// The volume's finite value range `(min, max)`, as rendered: of the
    /// samples as they are now.
    #[getter]
    fn value_range(&self, py: Python<'_>) -> PyResult<(f32, f32)> {
        match &self.road {
            Road::Memory(memory) => Ok(self.current(py, memory, None, None)?.inner.value_range()),
            Road::Lazy(lazy) => self.lazy_value_range(py, lazy),
        }
    }

    /// The level the last frame rendered (of a lazy volume's file: with
    /// `level="auto"`, the one its view needed); `None` before the first
    /// frame, and for a volume in memory.
    #[getter]
    fn level(&self, py: Python<'_>) -> Option<usize> {
        let Road::Lazy(lazy) = &self.road else {
            return None;
        };
        py.detach(|| {
            lazy.state
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .way
                .level()
        })
    }

    /// How many pieces the last frame was cut into: 1 where the level was
    /// read whole (always, for a volume in memory); more where it would
    /// not fit `max_memory` whole and was rendered piece by piece, read
    /// from its file; `None` before a lazy volume's first frame.
    #[getter]
    fn pieces(&self, py: Python<'_>) -> Option<usize> {
        let Road::Lazy(lazy) = &self.road else {
            return Some(1);
        };
        py.detach(
            || match &lazy.state.lock().unwrap_or_else(|e| e.into_inner()).way {
                Way::None => None,
                Way::Whole { .. } => Some(1),
                Way::Pieces { streamed, .. } => Some(streamed.pieces()),
            },
        )
    }

    /// For tests: the byte budget of the brick caches the last frame
    /// rendered with (of the volume as prepared now; `None` for a lazy
    /// volume before its first frame or rendered in pieces).
    #[getter]
    fn _cache_budget(&self, py: Python<'_>) -> Option<usize> {
        let prepared = match &self.road {
            Road::Memory(memory) => Arc::clone(&memory.lock().unwrap_or_else(|e| e.into_inner())),
            Road::Lazy(lazy) => {
                py.detach(
                    || match &lazy.state.lock().unwrap_or_else(|e| e.into_inner()).way {
                        Way::Whole { prepared, .. } => Some(Arc::clone(prepared)),
                        Way::None | Way::Pieces { .. } => None,
                    },
                )?
            }
        };
        Some(prepared.inner.cache_budget())
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let name = &self.recipe.name;
        match &self.road {
            Road::Memory(memory) => {
                let prepared = Arc::clone(&memory.lock().unwrap_or_else(|e| e.into_inner()));
                let [x, y, z] = prepared.inner.volume().dims();
                format!("Renderer({name}: {x}x{y}x{z})")
            }
            Road::Lazy(lazy) => {
                let (x, y, z) = lazy.volume.get().dims(py);
                let level = match lazy.choice {
                    LevelChoice::Auto => "auto".to_string(),
                    LevelChoice::Index(n) => n.to_string(),
                };
                format!("Renderer({name}: {x}x{y}x{z}, lazy, level {level})")
            }
        }
    }
}

/// Runs `work` (a frame, given the progress callback) on a worker thread,
/// on `pool` or the global pool, while the calling thread (detached from
/// Python) asks Python for pending signals every [`SIGNAL_POLL`] of the
/// wait; on KeyboardInterrupt it sets `stop` and waits for the work to
/// end. The work's result (or the message of its panic), and the
/// interrupt if one came.
pub(crate) fn interruptible<T: Send>(
    pool: Option<&rayon::ThreadPool>,
    stop: &AtomicBool,
    work: impl FnOnce(&(dyn Fn(usize) + Sync)) -> T + Send,
) -> (Result<T, String>, Option<PyErr>) {
    let hook = InterruptHook::take();
    let mut interrupt = None;
    let out = std::thread::scope(|s| {
        let (done, finished) = mpsc::channel();
        let hook = &hook;
        s.spawn(move || {
            let report = |pixels| hook.report(pixels, stop);
            let frame = || work(&report);
            // The global pool (one worker per core) unless threads= is given.
            let run = || match pool {
                Some(pool) => pool.install(frame),
                None => frame(),
            };
            // A panic (a bug) becomes an exception, not an abort of Python.
            let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).map_err(|p| {
                (p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .or_else(|| p.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "a panic".to_string())
            });
            // The receiver waits for this; it cannot be gone.
            let _ = done.send(out);
        });
        loop {
            match finished.recv_timeout(SIGNAL_POLL) {
                Ok(out) => break out,
                Err(RecvTimeoutError::Timeout) => {
                    if interrupt.is_none()
                        && let Err(e) = Python::attach(|py| py.check_signals())
                    {
                        interrupt = Some(e);
                        stop.store(true, Ordering::SeqCst);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => {
                    panic!("the render thread ended without a frame")
                }
            }
        }
    });
    (out, interrupt)
}

/// A frame that panicked (a bug in volray), as `RuntimeError`.
pub(crate) fn internal_error(name: &str, panic: &str) -> PyErr {
    pyo3::exceptions::PyRuntimeError::new_err(format!(
        "{name}: the frame failed inside volray (a bug, please report it): {panic}"
    ))
}

/// A lazy volume's file (a lazy road's volume is lazy).
fn lazy_file(lazy: &LazyRoad) -> &LazyFile {
    match &lazy.volume.get().lazy {
        Some(file) => file,
        None => unreachable!("a lazy road's volume is lazy"),
    }
}

/// A frame in pieces that failed, as the Python exception.
fn stream_error(e: StreamError, camera: &CameraOptions, name: &str) -> PyErr {
    match e {
        StreamError::Read(e) => source_error(e),
        StreamError::TooLarge(message) => value_error(format!(
            "{name}: {message}: raise max_memory, or pick a coarser level"
        )),
        StreamError::Render(e) => render_error(e, camera, name),
    }
}

/// Level `n` of a file of `levels` levels, or the `ValueError` naming the
/// levels it has.
pub(crate) fn check_level(name: &str, n: usize, levels: usize) -> PyResult<()> {
    match n < levels {
        true => Ok(()),
        false => Err(value_error(format!(
            "{name}: level {n} is not among the file's {levels} levels (0 to {})",
            levels - 1
        ))),
    }
}

/// `level=` given for the volume `name`, which is in memory.
pub(crate) fn level_in_memory(name: &str) -> PyErr {
    value_error(format!(
        "level: {name} is in memory: level picks a level of a volume read lazily from a chunked file (volray.read of a Zarr or OME-Zarr image)"
    ))
}

/// `level=`: `"auto"` or a level number, if given.
pub(crate) fn level_choice(k: &Keywords<'_>) -> PyResult<Option<LevelChoice>> {
    let Some(level) = k.get("level") else {
        return Ok(None);
    };
    if let Ok(s) = level.cast::<PyString>() {
        let text = s.to_cow()?;
        return text
            .parse::<LevelChoice>()
            .map(Some)
            .map_err(|e| value_error(format!("level: {e}")));
    }
    keywords::extract::<usize>(level, "level", "'auto' or a level number (0 the finest)")
        .map(|n| Some(LevelChoice::Index(n)))
}

/// `render(volume, **options)` of one volume (`render.rs` sends a scene
/// to `scene.rs`).
pub fn render_one(
    py: Python<'_>,
    volume: &Bound<'_, PyAny>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Frame> {
    let k = Keywords::new(kwargs, &[VOLUME, CAMERA, FRAME, FIGURE], "render")?;
    Renderer::build(py, volume, &k)?.frame(py, &k, true)
}

/// The test hook behind `_volray._interrupt_next_frame()`: the next frame
/// (of any renderer) simulates Ctrl-C once its first tile is reported,
/// then waits on that worker until the calling thread has seen the signal
/// and set the stop flag, so that tests stop a frame mid-way whatever the
/// machine's load, with no timer racing the frame.
static INTERRUPT_NEXT_FRAME: AtomicBool = AtomicBool::new(false);

/// The pixels the last hooked frame reported in all: fewer than the
/// frame's when it was stopped.
static HOOKED_FRAME_PIXELS: AtomicUsize = AtomicUsize::new(0);

/// How long the hook waits for the stop flag before it lets the frame go
/// on: a guard against a hang where no thread polls for signals (the
/// test then fails on the frame having finished), not a timing.
const HOOK_GUARD: Duration = Duration::from_secs(60);

/// Whether this frame is hooked, and whether its interrupt was raised.
struct InterruptHook {
    armed: bool,
    raised: AtomicBool,
    pixels: AtomicUsize,
}

impl InterruptHook {
    /// The hook for the frame about to render (armed once).
    fn take() -> Self {
        InterruptHook {
            armed: INTERRUPT_NEXT_FRAME.swap(false, Ordering::SeqCst),
            raised: AtomicBool::new(false),
            pixels: AtomicUsize::new(0),
        }
    }

    /// A caster reported `pixels` more finished.
    fn report(&self, pixels: usize, stop: &AtomicBool) {
        if !self.armed {
            return;
        }
        let done = self.pixels.fetch_add(pixels, Ordering::SeqCst) + pixels;
        HOOKED_FRAME_PIXELS.store(done, Ordering::SeqCst);
        if self.raised.swap(true, Ordering::SeqCst) {
            return;
        }
        // SAFETY: `PyErr_SetInterrupt` only sets the flag a SIGINT sets;
        // CPython documents it as callable from any thread without the
        // GIL (it is async-signal-safe), as this worker does.
        unsafe { pyo3::ffi::PyErr_SetInterrupt() };
        let since = std::time::Instant::now();
        while !stop.load(Ordering::SeqCst) && since.elapsed() < HOOK_GUARD {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

/// `_interrupt_next_frame()`: for tests, the next frame simulates Ctrl-C
/// after its first tile (see [`InterruptHook`]).
#[pyfunction]
pub fn _interrupt_next_frame() {
    HOOKED_FRAME_PIXELS.store(0, Ordering::SeqCst);
    INTERRUPT_NEXT_FRAME.store(true, Ordering::SeqCst);
}

/// `_hooked_frame_pixels()`: for tests, the pixels the last hooked frame
/// reported in all.
#[pyfunction]
pub fn _hooked_frame_pixels() -> usize {
    HOOKED_FRAME_PIXELS.load(Ordering::SeqCst)
}

/// `_digest(array)`: for benchmarks, the digest a renderer takes of
/// `array` before each frame (`scripts/python_digest.py` times it).
#[pyfunction]
pub fn _digest(py: Python<'_>, array: &Bound<'_, PyAny>) -> PyResult<u64> {
    let watched = array::watched(array)?;
    Ok(py.detach(|| watched.digest()))
}
