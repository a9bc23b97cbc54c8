//! `Renderer` (a volume prepared once, rendered frame after frame at
//! `volray bench` speed) and `render` (one frame), with the GIL released
//! while rendering and Ctrl-C honoured: the frame renders on a worker
//! thread while the calling thread waits for it, asking Python for
//! pending signals every 20 ms of the wait (a finished frame returns at
//! once); on KeyboardInterrupt it stops the frame (volray-core's
//! `FrameRequest::stopped_by`: the work left is skipped) and raises.
//!
//! A lazy volume (`volume.rs`: a chunked file read from its metadata)
//! takes volray-lazy's road, as `volray render` does (`src/streamed.rs`):
//! each frame picks its level (`level="auto"`: the coarsest whose voxels
//! are no larger than a pixel's footprint; else the level asked for, or
//! the volume's), then reads that level whole when its frame fits
//! `max_memory` (prepared as any volume, kept while frames need that
//! level: the same pixels as `read(path, level=N)` rendered) or renders
//! it piece by piece (volray-distributed's `Streamed`, kept likewise, the
//! labels and `tf="auto"` histogram found piece by piece once). A frame
//! in pieces stops at its next piece on Ctrl-C: `Streamed` has no stop
//! flag within a piece, so the piece being rendered finishes first.

use crate::array::{self, ArrayBytes, Order};
use crate::errors::{io_error, option_error, render_error, settings_error, value_error};
use crate::figure::{self, FIGURE};
use crate::frame::Frame;
use crate::keywords::{self, CAMERA, FRAME, Keywords, VOLUME};
use crate::volume::{LazyFile, Volume};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use volray_annotate::figure::Annotations;
use volray_core::transfer::auto;
use volray_core::{
    DEFAULT_CACHE_BUDGET, FrameRequest, Histogram, Image, MemoryBound, NonFinite, Render,
    RenderError, RenderSettings, Rendered, Renderer as CoreRenderer, Volume as CoreVolume,
};
use volray_distributed::streamed::{StreamError, Streamed};
use volray_io::{MapPolicy, ReadOptions, format_bytes};
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
    /// What the volume-level options fixed.
    pub labels: bool,
    log: bool,
    pub nonfinite: NonFinite,
    pub max_memory: u64,
    pub name: String,
    /// The file's display window (an OME-Zarr `omero` window), the
    /// default `range`.
    window: Option<(f64, f64)>,
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
    pub histogram: Option<Histogram>,
}

impl Recipe {
    /// The bytes to digest, where the samples can change under the
    /// renderer.
    fn watched(&self, py: Python<'_>) -> PyResult<Option<ArrayBytes>> {
        match &self.source {
            Source::Volume(v) if v.get().frozen => Ok(None),
            Source::Volume(v) => ArrayBytes::new(v.get().array(py)?, None).map(Some),
            Source::Array { object, .. } => array::watched(object.bind(py)).map(Some),
        }
    }

    /// The digest of the samples as they are now (on `pool`, or the
    /// global pool; the GIL released while hashing); `None` if they are
    /// read-only.
    pub(crate) fn digest(
        &self,
        py: Python<'_>,
        pool: Option<&rayon::ThreadPool>,
    ) -> PyResult<Option<u64>> {
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
    pub(crate) fn prepare(&self, py: Python<'_>, digest: Option<u64>) -> PyResult<Prepared> {
        let core = match &self.source {
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
                let kept = ArrayBytes::new(volume.array(py)?, None)?;
                let in_place = digest.is_some() && array::watched(object)?.same_bytes(&kept);
                volume.core_expecting(py, digest.filter(|_| in_place))?
            }
        };
        self.prepare_core(py, core, digest)
    }

    /// [`Recipe::prepare`] of the samples `core`.
    pub(crate) fn prepare_core(
        &self,
        py: Python<'_>,
        mut core: CoreVolume,
        digest: Option<u64>,
    ) -> PyResult<Prepared> {
        let name = &self.name;
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
            known: Known {
                labels: found_labels,
                histogram,
            },
            digest,
        })
    }
}

impl Recipe {
    /// The recipe of `volume` (an array or a `Volume`) with the
    /// volume-level keywords of `k` (but `level`).
    pub(crate) fn build(volume: &Bound<'_, PyAny>, k: &Keywords<'_>) -> PyResult<Self> {
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
        let window = match &source {
            Source::Volume(v) => v.get().display_window(),
            Source::Array { .. } => None,
        };
        Ok(Recipe {
            source,
            spacing,
            origin,
            labels,
            log,
            nonfinite,
            max_memory,
            name,
            window,
        })
    }

    /// The options and settings of a frame of this volume with the frame
    /// keywords of `k` (its file's display window the default range).
    pub(crate) fn settings_of(&self, k: &Keywords<'_>) -> PyResult<(Options, RenderSettings)> {
        let options = keywords::options(k, self.look())?;
        let mut settings =
            volray_options::settings(&options).map_err(|e| settings_error(e, &options.camera))?;
        volray_options::file_window(&options.look, &mut settings.transfer_function, self.window);
        Ok((options, settings))
    }

    /// What the annotations take from the volume: its file's units and
    /// axes, and whether it is rendered as log10.
    pub(crate) fn facts(&self, py: Python<'_>) -> figure::Facts {
        match &self.source {
            Source::Volume(v) => figure::Facts::of(v.bind(py).get().file.as_ref(), self.log),
            Source::Array { .. } => figure::Facts::of(None, self.log),
        }
    }

    /// The chunked file a lazy volume is read from, if it is one.
    pub(crate) fn lazy(&self) -> Option<&LazyFile> {
        match &self.source {
            Source::Volume(v) => v.get().lazy.as_ref(),
            Source::Array { .. } => None,
        }
    }

    /// Whether a spacing or origin was given with the volume (or `log`):
    /// what applies to a level read whole, not yet to a pyramid's levels.
    pub(crate) fn reshaped(&self) -> bool {
        self.spacing.is_some() || self.origin.is_some() || self.log
    }

    /// The file's display window (an OME-Zarr `omero` window), if any.
    pub(crate) fn window(&self) -> Option<(f64, f64)> {
        self.window
    }

    /// The look options the recipe fixes (labels, log).
    pub(crate) fn look(&self) -> LookOptions {
        LookOptions {
            labels: self.labels,
            log: self.log,
            ..LookOptions::default()
        }
    }

    /// Puts into `settings` what `options` leave to the volume, as
    /// volray-options' from_volume does, from what `prepared` found
    /// once: the labels' transfer function, or the automatic one.
    pub(crate) fn leave_to_volume(
        &self,
        known: &Known,
        options: &Options,
        settings: &mut RenderSettings,
    ) -> PyResult<()> {
        match (&known.labels, &known.histogram) {
            (Some(found), _) => volray_options::label_transfer_function(
                &options.look,
                &mut settings.transfer_function,
                found,
                &self.name,
            )
            .map_err(option_error),
            (None, Some(histogram)) if options.look.auto_tf() => {
                volray_options::apply_auto(
                    &options.look,
                    &mut settings.transfer_function,
                    histogram,
                );
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// Refuses a frame that may take more than `max_memory` even with no
    /// brick cache (the command line's rule, `src/memory.rs`).
    pub(crate) fn check_memory(
        &self,
        inner: &CoreRenderer<'_>,
        settings: &RenderSettings,
    ) -> PyResult<()> {
        let need = need(inner, settings, self.nonfinite);
        let volume = inner.volume();
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
                    .map_or(1, |l| l.chunked.levels().len());
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
        let prepared = recipe.prepare(py, digest)?;
        Ok(Renderer {
            recipe,
            road: Road::Memory(Mutex::new(Arc::new(prepared))),
        })
    }

    /// The volume prepared from the samples as they are now: the last
    /// one, or (the samples changed since) a new one.
    fn current(
        &self,
        py: Python<'_>,
        memory: &Mutex<Arc<Prepared>>,
        pool: Option<&rayon::ThreadPool>,
    ) -> PyResult<Arc<Prepared>> {
        // The lock is held only to clone or replace the `Arc`, never
        // across a call that waits for the GIL or another thread.
        let last = Arc::clone(&memory.lock().unwrap_or_else(|e| e.into_inner()));
        let digest = self.recipe.digest(py, pool)?;
        if digest == last.digest {
            return Ok(last);
        }
        let fresh = Arc::new(self.recipe.prepare(py, digest)?);
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
            false => self.current(py, memory, pool.as_ref())?,
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

    /// A frame of a lazy volume: its level, then the level whole or in
    /// pieces, as its plan says.
    fn lazy_frame(
        &self,
        py: Python<'_>,
        lazy: &LazyRoad,
        options: &Options,
        mut settings: RenderSettings,
        pool: Option<rayon::ThreadPool>,
        what: &Annotations,
    ) -> PyResult<Frame> {
        let level = self.level_for(lazy, &settings, &options.camera)?;
        let pool = pool.as_ref();
        let name = &self.recipe.name;
        let settings_ref = &mut settings;
        let next = py.detach(|| -> PyResult<(Next, Option<Image>)> {
            let mut state = lazy.state.lock().unwrap_or_else(|e| e.into_inner());
            self.settle(lazy, &mut state, level, settings_ref)?;
            state.settings = Some(settings_ref.clone());
            if let Way::Whole { prepared, .. } = &state.way {
                return Ok((Next::Whole(Arc::clone(prepared)), None));
            }
            let Way::Pieces {
                streamed, found, ..
            } = &mut state.way
            else {
                unreachable!("settled above")
            };
            figure::refuse_pieces(what, name)?;
            lazy.stop.store(false, Ordering::SeqCst);
            let settings = &mut *settings_ref;
            let (rendered, interrupt) = interruptible(pool, &lazy.stop, |report| {
                found
                    .apply(streamed, &options.look, settings, name)
                    .and_then(|()| {
                        let request = FrameRequest::new(&*settings).reporting(report);
                        (streamed.render(request.stopped_by(&lazy.stop)))
                            .map(Rendered::image_and_times)
                            .map_err(LookError::Stream)
                    })
            });
            let rendered = rendered.map_err(|panic| {
                // What the pieces knew may be half updated: start afresh.
                state.way = Way::None;
                internal_error(name, &panic)
            });
            if let Some(e) = interrupt {
                return Err(e);
            }
            let (image, _times) = rendered?.map_err(|e| match e {
                LookError::Stream(e) => stream_error(e, &options.camera, name),
                LookError::Refused(e) => option_error(e),
            })?;
            Ok((Next::Pieces, Some(image)))
        })?;
        match next {
            (Next::Whole(prepared), _) => {
                self.render_prepared(py, &prepared, options, settings, pool, what)
            }
            (Next::Pieces, image) => Ok(Frame {
                image: image.expect("a frame in pieces returns its image"),
            }),
        }
    }

    /// The level a frame of `settings` needs: `level="auto"`'s choice
    /// for the view, or the level asked for.
    fn level_for(
        &self,
        lazy: &LazyRoad,
        settings: &RenderSettings,
        camera: &CameraOptions,
    ) -> PyResult<usize> {
        match lazy.choice {
            LevelChoice::Index(n) => Ok(n),
            LevelChoice::Auto => lazy_file(lazy)
                .chunked
                .auto_level(settings)
                .map_err(|e| render_error(RenderError::from(e), camera, &self.recipe.name)),
        }
    }

    /// Makes `state` ready for a frame of `settings` at `level`: the level
    /// open, and read whole (prepared) or set to be rendered in pieces,
    /// as volray-lazy's plan says for `max_memory`. What the last frame
    /// kept is kept where the plan is the same. Called detached from
    /// Python, the state locked.
    fn settle(
        &self,
        lazy: &LazyRoad,
        state: &mut LazyState,
        level: usize,
        settings: &RenderSettings,
    ) -> PyResult<()> {
        let file = lazy_file(lazy);
        let name = &self.recipe.name;
        if state.chunked.as_ref().map(Chunked::level) != Some(level) {
            state.way = Way::None;
            state.chunked = None;
            let chunked = file.chunked.open_level(level).map_err(io_error)?;
            state.chunked = Some(chunked.stoppable(Arc::clone(&lazy.stop)));
        }
        let Some(chunked) = &state.chunked else {
            unreachable!("opened above")
        };
        let own = file.chunked.level();
        let overridden =
            self.recipe.spacing.is_some() || self.recipe.origin.is_some() || file.spacing_given;
        let refuse_override = |how: &str| {
            value_error(format!(
                "{name}: spacing and origin given apply to level {own} read whole, not to level {level} {how}: leave them out (the file's own are used)"
            ))
        };
        let (mode, max_memory) = (self.recipe.nonfinite, self.recipe.max_memory);
        let plan = if self.recipe.log {
            // The log scale's pass over the level is made once, when its
            // pieces are first needed.
            let level = chunked.level();
            let need = chunked.whole_log_bytes(settings, mode);
            if need <= u128::from(max_memory) {
                Plan::Whole { level, need }
            } else if matches!(state.way, Way::Pieces { level: l, .. } if l == level) {
                return Ok(());
            } else {
                if overridden {
                    return Err(refuse_override("in pieces"));
                }
                let streamed = (chunked.log_pieces(mode, max_memory))
                    .map_err(|e| value_error(format!("log=True: {name}: {e}")))?;
                Plan::Pieces {
                    level,
                    need,
                    streamed: Box::new(streamed),
                }
            }
        } else {
            chunked.plan(settings, mode, max_memory, 0)
        };
        match plan {
            Plan::Whole { level, .. } => {
                if overridden && level != own {
                    return Err(refuse_override("read whole"));
                }
                if !matches!(state.way, Way::Whole { level: l, .. } if l == level) {
                    // The last level's samples go before the next is read.
                    state.way = Way::None;
                    let prepared =
                        Python::attach(|py| self.prepare_level(py, lazy, file, chunked))?;
                    state.way = Way::Whole {
                        level,
                        prepared: Arc::new(prepared),
                    };
                }
            }
            Plan::Pieces {
                level, streamed, ..
            } => {
                if overridden {
                    return Err(refuse_override("in pieces"));
                }
                if !matches!(state.way, Way::Pieces { level: l, .. } if l == level) {
                    state.way = Way::Pieces {
                        level,
                        streamed: Box::new(streamed.with_labels(self.recipe.labels)),
                        found: Found::default(),
                    };
                }
            }
        }
        Ok(())
    }

    /// The level `chunked` read whole and prepared: the volume's own
    /// samples where `data` read them already, else read from the file.
    fn prepare_level(
        &self,
        py: Python<'_>,
        lazy: &LazyRoad,
        file: &LazyFile,
        chunked: &Chunked,
    ) -> PyResult<Prepared> {
        let volume = lazy.volume.get();
        let own = chunked.level() == file.chunked.level();
        if own && volume.loaded(py).is_some() {
            return self.recipe.prepare_core(py, volume.core(py)?, None);
        }
        let opts = ReadOptions {
            max_memory: self.recipe.max_memory,
            map: MapPolicy::Never,
            ..chunked.read_options()
        };
        let path = chunked.path();
        let read = py
            .detach(|| volray_io::read(path, &opts))
            .map_err(io_error)?;
        let mut core = read.volume;
        if own && file.spacing_given {
            core = core
                .with_spacing(volume.spacing.into())
                .map_err(|e| value_error(format!("spacing: {e}")))?;
        }
        if volume.labels {
            core = core.as_labels();
        }
        self.recipe.prepare_core(py, core, None)
    }

    /// A lazy volume's value range: of the level of the last frame; before
    /// the first (or after one that failed), of the level asked for (the
    /// volume's own with `level="auto"`, which needs a view). Read whole,
    /// or found piece by piece (every piece read once).
    fn lazy_value_range(&self, py: Python<'_>, lazy: &LazyRoad) -> PyResult<(f32, f32)> {
        let (options, default, _) = self.settings_of(&Keywords::new(None, &[], "value_range")?)?;
        let name = &self.recipe.name;
        py.detach(|| {
            let mut state = lazy.state.lock().unwrap_or_else(|e| e.into_inner());
            let settings = match (&state.way, state.settings.clone()) {
                (Way::Whole { .. } | Way::Pieces { .. }, Some(settings)) => settings,
                _ => {
                    // A small frame: the range does not depend on it, and
                    // the pieces need fit no picture.
                    let settings = RenderSettings {
                        width: 16,
                        height: 16,
                        ..default
                    };
                    let level = match lazy.choice {
                        LevelChoice::Index(n) => n,
                        LevelChoice::Auto => lazy_file(lazy).chunked.level(),
                    };
                    self.settle(lazy, &mut state, level, &settings)?;
                    state.settings = Some(settings.clone());
                    settings
                }
            };
            match &mut state.way {
                Way::None => unreachable!("settled by a frame before, or above"),
                Way::Whole { prepared, .. } => Ok(prepared.inner.value_range()),
                Way::Pieces {
                    streamed, found, ..
                } => {
                    let histogram = found
                        .histogram(streamed, &settings)
                        .map_err(|e| stream_error(e, &options.camera, name))?;
                    Ok(histogram.map_or((0.0, 0.0), |h| (h.min, h.max)))
                }
            }
        })
    }
}

/// What rendering a frame of `settings` may take beyond the samples
/// (a numpy array's are the caller's) with no brick cache.
pub(crate) fn need(
    renderer: &CoreRenderer<'_>,
    settings: &RenderSettings,
    mode: NonFinite,
) -> u128 {
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
pub(crate) fn cache_budget(renderer: &CoreRenderer<'_>, mode: NonFinite, max_memory: u64) -> usize {
    let need = need(renderer, &RenderSettings::default(), mode);
    (u128::from(max_memory).saturating_sub(need)).min(DEFAULT_CACHE_BUDGET as u128) as usize
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
            Road::Memory(memory) => Ok(self.current(py, memory, None)?.inner.value_range()),
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
        StreamError::Read(message) => PyOSError::new_err(message),
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
    if crate::scene::is_scene(volume, kwargs)? {
        return crate::scene::render(py, volume, kwargs);
    }
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
