//! `Renderer` (a volume prepared once, rendered frame after frame at
//! `volray bench` speed) and `render` (one frame), with the GIL released
//! while rendering and Ctrl-C honoured: the frame renders on a worker
//! thread while the calling thread waits for it, asking Python for
//! pending signals every 20 ms of the wait (a finished frame returns at
//! once); on KeyboardInterrupt it stops the frame (volray-core's
//! `render_stoppable`: the work left is skipped) and raises.

use crate::array::Order;
use crate::errors::{option_error, render_error, settings_error, value_error};
use crate::frame::Frame;
use crate::keywords::{self, CAMERA, FRAME, Keywords, VOLUME};
use crate::volume::Volume;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
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
/// over views pays for them once.
#[pyclass(frozen, module = "volray")]
pub struct Renderer {
    inner: CoreRenderer<'static>,
    /// What the volume-level options fixed.
    labels: bool,
    log: bool,
    nonfinite: NonFinite,
    max_memory: u64,
    name: String,
    /// The labels present (with `labels=True`), or the histogram the
    /// automatic transfer function is chosen from (else), found once.
    found_labels: Option<Vec<i64>>,
    histogram: Option<Histogram>,
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
        let given: Option<Py<Volume>> = volume.cast::<Volume>().ok().map(|v| v.clone().unbind());
        let owned;
        let vol: &Volume = match &given {
            Some(v) => {
                if k.get("order").is_some() {
                    return Err(value_error(
                        "order applies to numpy arrays; a volray.Volume's axes are fixed",
                    ));
                }
                v.get()
            }
            None => {
                owned = Volume::from_array(volume, spacing, origin, order, false)?;
                &owned
            }
        };
        let mut core = vol.core(py)?;
        if given.is_some() {
            if let Some(s) = spacing {
                core = core
                    .with_spacing(s.into())
                    .map_err(|e| value_error(format!("spacing: {e}")))?;
            }
            if let Some(o) = origin {
                core = core
                    .with_origin(o.into())
                    .map_err(|e| value_error(format!("origin: {e}")))?;
            }
        }
        let labels = labels_given.unwrap_or(vol.labels);
        let log = k.take::<bool>("log", "True or False")?.unwrap_or(false);
        let name = vol.name.clone();
        if labels && log {
            return Err(value_error(
                "labels=True conflicts with log=True: a label volume's values are names, not quantities",
            ));
        }
        if log {
            core = py
                .detach(|| core.to_log10())
                .map_err(|e| value_error(format!("log=True: {name}: {e}")))?;
        }
        let requested = keywords::nonfinite(k)?;
        let nonfinite = if vol.nan_is_empty() {
            NonFinite::Transparent
        } else {
            requested
        };
        let max_memory = k
            .take::<u64>("max_memory", "a number of bytes")?
            .unwrap_or_else(volray_io::default_max_memory);
        let (found_labels, histogram) = if labels {
            let found = volray_options::volume_labels(&core, &name).map_err(option_error)?;
            (Some(found), None)
        } else {
            (None, py.detach(|| Histogram::of(&core, auto::BINS)))
        };
        let core = if labels { core.as_labels() } else { core };
        let inner = py
            .detach(|| CoreRenderer::owning(core, nonfinite))
            .map_err(|e| render_error(e, &volray_options::CameraOptions::default(), &name))?;
        let inner = {
            let budget = cache_budget(&inner, nonfinite, max_memory);
            inner.with_cache_budget(budget)
        };
        Ok(Renderer {
            inner,
            labels,
            log,
            nonfinite,
            max_memory,
            name,
            found_labels,
            histogram,
        })
    }

    /// One frame with the frame keywords of `k`.
    fn frame(&self, py: Python<'_>, k: &Keywords<'_>) -> PyResult<Frame> {
        let look = LookOptions {
            labels: self.labels,
            log: self.log,
            ..LookOptions::default()
        };
        let options = keywords::options(k, look)?;
        let threads = keywords::threads(k)?;
        let mut settings =
            volray_options::settings(&options).map_err(|e| settings_error(e, &options.camera))?;
        // What the options leave to the volume, as volray-options'
        // from_volume does, from what was found once.
        match (&self.found_labels, &self.histogram) {
            (Some(found), _) => volray_options::label_transfer_function(
                &options.look,
                &mut settings.transfer_function,
                found,
                &self.name,
            )
            .map_err(option_error)?,
            (None, Some(histogram)) if options.look.auto_tf() => volray_options::apply_auto(
                &options.look,
                &mut settings.transfer_function,
                histogram,
            ),
            _ => {}
        }
        self.check_memory(&settings)?;
        let pool = threads.map(pool).transpose()?;
        let stop = AtomicBool::new(false);
        let inner = &self.inner;
        let settings = &settings;
        let mut interrupt = None;
        let rendered = py.detach(|| {
            std::thread::scope(|s| {
                let (done, finished) = mpsc::channel();
                let (pool, stop) = (&pool, &stop);
                s.spawn(move || {
                    let frame = || inner.render_stoppable(settings, &|_| {}, stop);
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
        let image = rendered.map_err(|e| render_error(e, &options.camera, &self.name))?;
        Ok(Frame { image })
    }

    /// Refuses a frame that may take more than `max_memory` even with no
    /// brick cache (the command line's rule, `src/memory.rs`).
    fn check_memory(&self, settings: &RenderSettings) -> PyResult<()> {
        let need = need(&self.inner, settings, self.nonfinite);
        let volume = self.inner.volume();
        let limit = u128::from(self.max_memory);
        if need > limit {
            let [nx, ny, nz] = volume.dims();
            return Err(value_error(format!(
                "{}: rendering {nx}x{ny}x{nz} voxels at {}x{} pixels may take up to {}, more than max_memory {} (raise it, or use a smaller grid)",
                self.name,
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
        self.frame(py, &k)
    }

    /// The volume's finite value range `(min, max)`, as rendered.
    #[getter]
    fn value_range(&self) -> (f32, f32) {
        self.inner.value_range()
    }

    fn __repr__(&self) -> String {
        let [x, y, z] = self.inner.volume().dims();
        format!("Renderer({}: {x}x{y}x{z})", self.name)
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
    Renderer::build(py, volume, &k)?.frame(py, &k)
}
