//! `Renderer` (a volume prepared once, rendered frame after frame at
//! `volray bench` speed) and `render` (one frame), with the GIL released
//! while rendering and Ctrl-C honoured: the frame renders on a worker
//! thread while the calling thread waits for it, asking Python for
//! pending signals every 20 ms of the wait (a finished frame returns at
//! once); on KeyboardInterrupt it stops the frame (volray-core's
//! `render_stoppable`: the work left is skipped) and raises.

use crate::array::{self, ArrayBytes, Order};
use crate::errors::{option_error, render_error, settings_error, value_error};
use crate::frame::Frame;
use crate::keywords::{self, CAMERA, FRAME, Keywords, VOLUME};
use crate::volume::Volume;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use volray_core::transfer::auto;
use volray_core::{
    DEFAULT_CACHE_BUDGET, Histogram, MemoryBound, NonFinite, RenderSettings,
    Renderer as CoreRenderer,
};
use volray_io::format_bytes;
use volray_options::LookOptions;

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
    /// The volume as last prepared. Frames take a reference and render
    /// from it; a frame that finds the samples changed prepares them
    /// again and puts its result here.
    prepared: Mutex<Arc<Prepared>>,
}

/// The volume and the volume-level options: what a renderer is prepared
/// from, again whenever the samples change.
struct Recipe {
    source: Source,
    /// Spacing and origin given with a `Volume` (an array's are in its
    /// `Source`).
    spacing: Option<[f64; 3]>,
    origin: Option<[f64; 3]>,
    /// What the volume-level options fixed.
    labels: bool,
    log: bool,
    nonfinite: NonFinite,
    max_memory: u64,
    name: String,
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
struct Prepared {
    inner: CoreRenderer<'static>,
    /// The labels present (with `labels=True`), or the histogram the
    /// automatic transfer function is chosen from (else).
    found_labels: Option<Vec<i64>>,
    histogram: Option<Histogram>,
    /// The digest of the samples this was prepared from, where watched.
    digest: Option<u64>,
}

impl Recipe {
    /// The bytes to digest, where the samples can change under the
    /// renderer.
    fn watched(&self, py: Python<'_>) -> PyResult<Option<ArrayBytes>> {
        match &self.source {
            Source::Volume(v) if v.get().frozen => Ok(None),
            Source::Volume(v) => ArrayBytes::new(v.get().data.bind(py), None).map(Some),
            Source::Array { object, .. } => array::watched(object.bind(py)).map(Some),
        }
    }

    /// The digest of the samples as they are now (on `pool`, or the
    /// global pool; the GIL released while hashing); `None` if they are
    /// read-only.
    fn digest(&self, py: Python<'_>, pool: Option<&rayon::ThreadPool>) -> PyResult<Option<u64>> {
        let Some(watched) = self.watched(py)? else {
            return Ok(None);
        };
        Ok(Some(py.detach(|| match pool {
            Some(pool) => pool.install(|| watched.digest()),
            None => watched.digest(),
        })))
    }

    /// The volume prepared from its samples, whose digest is `digest`:
    /// value range, labels or histogram, non-finite values, the brick
    /// caches' budget. Samples read in place are checked against the
    /// digest after each frame (`ArrayBytes::verify`).
    fn prepare(&self, py: Python<'_>, digest: Option<u64>) -> PyResult<Prepared> {
        let name = &self.name;
        let mut core = match &self.source {
            Source::Volume(v) => v.get().core_expecting(py, digest)?,
            Source::Array {
                object,
                order,
                spacing,
                origin,
            } => {
                let object = object.bind(py);
                let volume = Volume::from_array(object, *spacing, *origin, *order, false)?;
                // Checked after each frame only where the frame reads the
                // caller's memory; a copy is the renderer's alone.
                let kept = ArrayBytes::new(volume.data.bind(py), None)?;
                let in_place = digest.is_some() && array::watched(object)?.same_bytes(&kept);
                volume.core_expecting(py, digest.filter(|_| in_place))?
            }
        };
        if let Some(s) = self.spacing {
            core = core
                .with_spacing(s.into())
                .map_err(|e| value_error(format!("spacing: {e}")))?;
        }
        if let Some(o) = self.origin {
            core = core
                .with_origin(o.into())
                .map_err(|e| value_error(format!("origin: {e}")))?;
        }
        if self.log {
            core = py
                .detach(|| core.to_log10())
                .map_err(|e| value_error(format!("log=True: {name}: {e}")))?;
        }
        let (found_labels, histogram) = if self.labels {
            let found = volray_options::volume_labels(&core, name).map_err(option_error)?;
            (Some(found), None)
        } else {
            (None, py.detach(|| Histogram::of(&core, auto::BINS)))
        };
        let core = if self.labels { core.as_labels() } else { core };
        let nonfinite = self.nonfinite;
        let inner = py
            .detach(|| CoreRenderer::owning(core, nonfinite))
            .map_err(|e| render_error(e, &volray_options::CameraOptions::default(), name))?;
        let inner = {
            let budget = cache_budget(&inner, nonfinite, self.max_memory);
            inner.with_cache_budget(budget)
        };
        Ok(Prepared {
            inner,
            found_labels,
            histogram,
            digest,
        })
    }
}

impl Renderer {
    /// The renderer of `volume` (an array or a `Volume`) with the
    /// volume-level keywords of `k`.
    fn build(py: Python<'_>, volume: &Bound<'_, PyAny>, k: &Keywords<'_>) -> PyResult<Self> {
        let order = match k.take::<String>("order", "'zyx' or 'xyz'")? {
            Some(o) => Order::parse(&o)?,
            None => Order::Xyz,
        };
        let spacing = k.take::<[f64; 3]>("spacing", "three numbers (dx, dy, dz)")?;
        let origin = k.take::<[f64; 3]>("origin", "three numbers (x, y, z)")?;
        let labels_given = k.take::<bool>("labels", "True or False")?;
        let (source, spacing, origin, vol_labels, name, nan_is_empty) =
            match volume.cast::<Volume>() {
                Ok(v) => {
                    if k.get("order").is_some() {
                        return Err(value_error(
                            "order applies to numpy arrays; a volray.Volume's axes are fixed",
                        ));
                    }
                    let vol = v.get();
                    let (labels, name, nan) = (vol.labels, vol.name.clone(), vol.nan_is_empty());
                    let source = Source::Volume(v.clone().unbind());
                    (source, spacing, origin, labels, name, nan)
                }
                Err(_) => {
                    let source = Source::Array {
                        object: volume.clone().unbind(),
                        order,
                        spacing,
                        origin,
                    };
                    (source, None, None, false, "volume".to_string(), false)
                }
            };
        let labels = labels_given.unwrap_or(vol_labels);
        let log = k.take::<bool>("log", "True or False")?.unwrap_or(false);
        if labels && log {
            return Err(value_error(
                "labels=True conflicts with log=True: a label volume's values are names, not quantities",
            ));
        }
        let requested = keywords::nonfinite(k)?;
        let nonfinite = if nan_is_empty {
            NonFinite::Transparent
        } else {
            requested
        };
        let max_memory = k
            .take::<u64>("max_memory", "a number of bytes")?
            .unwrap_or_else(volray_io::default_max_memory);
        let recipe = Recipe {
            source,
            spacing,
            origin,
            labels,
            log,
            nonfinite,
            max_memory,
            name,
        };
        let digest = recipe.digest(py, None)?;
        let prepared = recipe.prepare(py, digest)?;
        Ok(Renderer {
            recipe,
            prepared: Mutex::new(Arc::new(prepared)),
        })
    }

    /// The volume prepared from the samples as they are now: the last
    /// one, or (the samples changed since) a new one.
    fn current(&self, py: Python<'_>, pool: Option<&rayon::ThreadPool>) -> PyResult<Arc<Prepared>> {
        // The lock is held only to clone or replace the `Arc`, never
        // across a call that waits for the GIL or another thread.
        let last = Arc::clone(&self.prepared.lock().unwrap_or_else(|e| e.into_inner()));
        let digest = self.recipe.digest(py, pool)?;
        if digest == last.digest {
            return Ok(last);
        }
        let fresh = Arc::new(self.recipe.prepare(py, digest)?);
        *self.prepared.lock().unwrap_or_else(|e| e.into_inner()) = Arc::clone(&fresh);
        Ok(fresh)
    }

    /// One frame with the frame keywords of `k`; `fresh`: the renderer
    /// was prepared just now, so its samples need no second digest.
    fn frame(&self, py: Python<'_>, k: &Keywords<'_>, fresh: bool) -> PyResult<Frame> {
        let look = LookOptions {
            labels: self.recipe.labels,
            log: self.recipe.log,
            ..LookOptions::default()
        };
        let options = keywords::options(k, look)?;
        let threads = keywords::threads(k)?;
        let mut settings =
            volray_options::settings(&options).map_err(|e| settings_error(e, &options.camera))?;
        let pool = threads.map(pool).transpose()?;
        let prepared = match fresh {
            true => Arc::clone(&self.prepared.lock().unwrap_or_else(|e| e.into_inner())),
            false => self.current(py, pool.as_ref())?,
        };
        let name = &self.recipe.name;
        // What the options leave to the volume, as volray-options'
        // from_volume does, from what was found once.
        match (&prepared.found_labels, &prepared.histogram) {
            (Some(found), _) => volray_options::label_transfer_function(
                &options.look,
                &mut settings.transfer_function,
                found,
                name,
            )
            .map_err(option_error)?,
            (None, Some(histogram)) if options.look.auto_tf() => volray_options::apply_auto(
                &options.look,
                &mut settings.transfer_function,
                histogram,
            ),
            _ => {}
        }
        self.check_memory(&prepared.inner, &settings)?;
        let stop = AtomicBool::new(false);
        let inner = &prepared.inner;
        let settings = &settings;
        let mut interrupt = None;
        let hook = InterruptHook::take();
        let rendered = py.detach(|| {
            std::thread::scope(|s| {
                let (done, finished) = mpsc::channel();
                let (pool, stop) = (&pool, &stop);
                s.spawn(move || {
                    let report = |pixels| hook.report(pixels, stop);
                    let frame = || inner.render_stoppable(settings, &report, stop);
                    // The global pool (one worker per core) unless threads= is given.
                    let image = match pool {
                        Some(pool) => pool.install(frame),
                        None => frame(),
                    };
                    // The receiver waits for this; it cannot be gone.
                    let _ = done.send(image);
                });
                loop {
                    match finished.recv_timeout(SIGNAL_POLL) {
                        Ok(image) => break image,
                        Err(RecvTimeoutError::Timeout) => {
                            if interrupt.is_none()
                                && let Err(e) = Python::attach(|py| py.check_signals())
                            {
                                interrupt = Some(e);
                                stop.store(true, Ordering::Relaxed);
                            }
                        }
                        Err(RecvTimeoutError::Disconnected) => {
                            panic!("the render thread ended without a frame")
                        }
                    }
                }
            })
        });
        if let Some(e) = interrupt {
            return Err(e);
        }
        let image = rendered.map_err(|e| render_error(e, &options.camera, name))?;
        Ok(Frame { image })
    }

    /// Refuses a frame that may take more than `max_memory` even with no
    /// brick cache (the command line's rule, `src/memory.rs`).
    fn check_memory(&self, inner: &CoreRenderer<'_>, settings: &RenderSettings) -> PyResult<()> {
        let need = need(inner, settings, self.recipe.nonfinite);
        let volume = inner.volume();
        let limit = u128::from(self.recipe.max_memory);
        if need > limit {
            let [nx, ny, nz] = volume.dims();
            return Err(value_error(format!(
                "{}: rendering {nx}x{ny}x{nz} voxels at {}x{} pixels may take up to {}, more than max_memory {} (raise it, or use a smaller grid)",
                self.recipe.name,
                settings.width,
                settings.height,
                format_bytes(need),
                format_bytes(limit),
            )));
        }
        Ok(())
    }
}

/// What rendering a frame of `settings` may take beyond the samples
/// (a numpy array's are the caller's) with no brick cache.
fn need(renderer: &CoreRenderer<'_>, settings: &RenderSettings, mode: NonFinite) -> u128 {
    let volume = renderer.volume();
    let bound = MemoryBound::new(
        volume.dims(),
        volume.spacing(),
        volume.sample_type(),
        settings,
        mode,
        0,
    )
    .total();
    bound.saturating_sub((volume.len() * volume.sample_type().bytes()) as u128)
}

/// The budget of the brick caches: the library's default, or what is
/// left under `max_memory` after a default frame when that is less (the
/// command line's rule, `src/memory.rs`; the budget changes speed, never
/// pixels).
fn cache_budget(renderer: &CoreRenderer<'_>, mode: NonFinite, max_memory: u64) -> usize {
    let need = need(renderer, &RenderSettings::default(), mode);
    (u128::from(max_memory).saturating_sub(need)).min(DEFAULT_CACHE_BUDGET as u128) as usize
}

/// A pool of `threads` workers.
fn pool(threads: usize) -> PyResult<rayon::ThreadPool> {
    let builder = rayon::ThreadPoolBuilder::new().num_threads(threads);
    builder.build().map_err(|e| {
        pyo3::exceptions::PyOSError::new_err(format!("cannot start worker threads: {e}"))
    })
}

#[pymethods]
impl Renderer {
    /// `Renderer(volume, *, spacing=None, origin=None, order="xyz",
    /// labels=None, log=False, nonfinite="refuse", max_memory=None)`.
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
        let k = Keywords::new(kwargs, &[CAMERA, FRAME], "render")?;
        self.frame(py, &k, false)
    }

    /// The volume's finite value range `(min, max)`, as rendered: of the
    /// samples as they are now.
    #[getter]
    fn value_range(&self, py: Python<'_>) -> PyResult<(f32, f32)> {
        Ok(self.current(py, None)?.inner.value_range())
    }

    fn __repr__(&self) -> String {
        let prepared = Arc::clone(&self.prepared.lock().unwrap_or_else(|e| e.into_inner()));
        let [x, y, z] = prepared.inner.volume().dims();
        format!("Renderer({}: {x}x{y}x{z})", self.recipe.name)
    }
}

/// `render(volume, **options) -> Frame`: one frame of `volume` (a numpy
/// array or a `volray.Volume`) with `volray render`'s options and
/// defaults, as keywords (see the package's documentation).
#[pyfunction]
#[pyo3(signature = (volume, **kwargs))]
pub fn render(
    py: Python<'_>,
    volume: &Bound<'_, PyAny>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Frame> {
    let k = Keywords::new(kwargs, &[VOLUME, CAMERA, FRAME], "render")?;
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
