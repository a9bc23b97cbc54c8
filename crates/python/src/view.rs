//! The viewer in a notebook (`volray.view`, `python/volray/_jupyter.py`):
//! `_ViewHost` is volray-view's [`Host`] (the viewer without a server)
//! of one volume prepared as `render` prepares it, and `_ViewTab` one
//! page's renderer, whose messages the widget carries over the kernel's
//! connection. The page's states become `render`'s options
//! ([`volray_view::state_options`]): the camera and one whole transfer
//! function, so that `render(volume, camera=w.camera,
//! tf=w.transfer_function)` renders the frame the page shows, and the
//! page's command box shows that call (volray-app's keyword spelling). The page's figure (colour bar,
//! scale bar, text) is drawn into its frames as `render`'s annotation
//! keywords draw it, and read back as those keywords, the colour bar's
//! unit with them (`units="HU"` for a CT preset's: the keywords name the
//! transfer function whole, not the preset). A lazy volume (a chunked
//! file) is served level by level as `volray view` serves it
//! (volray-view's [`Pyramid`]), its read-back naming the stills' `level`.
//!
//! An array the caller writes in a later cell is digested again before
//! each frame ([`Watcher`], volray-view's [`Watch`]) and prepared again
//! where it changed, as `Renderer` does: only a write during a frame is
//! refused. The page acknowledges each frame it is given ([`ViewTab::ack`]):
//! at most [`volray_view::MAX_IN_FLIGHT`] go unacknowledged, their bytes
//! held in the memory limit's ledger.

use crate::errors::{Keywords as Names, io_error, source_error, value_error};
use crate::figure::{self, FIGURE};
use crate::keywords::{self, CAMERA, Camera, FRAME, Keywords, VOLUME};
use crate::renderer::{Recipe, cache_budget, check_level, level_choice, level_in_memory, pool};
use crate::transfer::TransferFunction;
use crate::volume::LazyFile;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::sync::{Arc, Mutex};
use volray_annotate::figure::preset_unit;
use volray_app::reproduce::keywords::{Value, call, figure_keywords, keywords, volume_keywords};
use volray_core::RenderSettings;
use volray_options::level::LevelChoice;
use volray_options::{Options, Tf};
use volray_view::{
    DRAFT_SHARE, Figure, FigureContext, Host, Message, OptionsStart, Pyramid, Refusal, Reproduce,
    Reproduction, Start, Tab, ViewState, Viewer, Watch,
};

/// The most pages of one widget rendering at once.
const MAX_TABS: usize = 8;

/// The viewer of one volume.
#[pyclass(frozen, name = "_ViewHost", module = "volray")]
pub struct ViewHost {
    host: Host,
    reproduce: Arc<PyReproduce>,
    /// The state of the last view a page asked for (the start's before).
    current: Arc<Mutex<ViewState>>,
    page: String,
}

/// One page's renderer.
#[pyclass(frozen, name = "_ViewTab", module = "volray")]
pub struct ViewTab {
    tab: Tab,
    current: Arc<Mutex<ViewState>>,
}

/// States to options, settings and the `volray.render` call.
struct PyReproduce {
    start: OptionsStart,
    /// The file's display window, `render`'s default range.
    window: Option<(f64, f64)>,
    /// The unit the frames' colour bar gives the values: `units=`, else
    /// the preset's.
    value_unit: Option<String>,
    /// A chunked file's level the stills show, as `render`'s `level=`:
    /// `Some(None)` for `"auto"`; `None` for a volume in memory.
    level: Option<Option<usize>>,
    /// `scale=` as given, which the call repeats.
    scale: Option<[f64; 3]>,
}

impl PyReproduce {
    fn options(&self, state: &ViewState) -> Result<Options, Refusal> {
        state.check().map_err(|e| Refusal(e.to_string()))?;
        volray_view::state_options(state, &self.start)
    }

    /// The keywords beside the options': a chunked file's `level`, and
    /// the annotations that draw `figure` as the page does.
    fn extra_words(&self, figure: &Figure) -> Vec<(&'static str, Value)> {
        let mut words = volume_keywords(self.scale);
        words.extend(figure_keywords(
            self.level,
            self.value_unit.as_deref(),
            figure,
        ));
        words
    }

    fn settings(&self, options: &Options) -> Result<RenderSettings, Refusal> {
        let mut settings =
            volray_options::settings(options).map_err(|e| Refusal(e.message(&Names)))?;
        volray_options::file_window(&options.look, &mut settings.transfer_function, self.window);
        Ok(settings)
    }
}

impl Reproduce for PyReproduce {
    fn reproduce(&self, state: &ViewState) -> Result<Reproduction, Refusal> {
        let options = self.options(state)?;
        let settings = self.settings(&options)?;
        Ok(Reproduction {
            settings,
            command: call(&options, &self.extra_words(&state.figure)),
            tf_file: None,
            scene: None,
        })
    }
}

#[pymethods]
impl ViewHost {
    /// `_ViewHost(volume, **kwargs)`: `render`'s keywords; the figure's
    /// give the page's starting figure, `level` a lazy volume's stills'.
    #[new]
    #[pyo3(signature = (volume, **kwargs))]
    fn new(
        py: Python<'_>,
        volume: &Bound<'_, PyAny>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let k = Keywords::new(kwargs, &[VOLUME, CAMERA, FRAME, FIGURE], "view")?;
        let what = figure::annotations(&k)?;
        let level = level_choice(&k)?;
        let recipe = Recipe::build(volume, &k)?;
        let name = recipe.name.clone();
        let facts = recipe.facts(py);
        let (options, mut settings) = recipe.settings_of(&k)?;
        let mut digest = None;
        let (prepared, levels) = match recipe.lazy() {
            None => {
                if level.is_some() {
                    return Err(level_in_memory(&name));
                }
                digest = recipe.digest(py, None)?;
                (recipe.prepare(py, digest, &settings)?, None)
            }
            Some(file) => {
                let opened = open_levels(py, &recipe, file, level, &settings)?;
                let dims = opened.pyramid.grid(opened.start).dims;
                let source = Arc::clone(opened.pyramid.source(opened.start));
                let core = (py.detach(|| source.read_box([0; 3], dims)))
                    .map_err(|e| source_error(e.prefixed(&name)))?;
                (
                    recipe.prepare_core(py, core, None, &settings)?,
                    Some(opened),
                )
            }
        };
        if levels.is_some() && what.any() {
            return Err(value_error(format!(
                "{name}: the figure's annotations are not drawn on a chunked file's levels yet: leave them out, or read a level whole with volray.read(path, level=N)"
            )));
        }
        let threads = keywords::threads(&k)?.unwrap_or(0);
        recipe.leave_to_volume(&prepared.known, &options, &mut settings)?;
        recipe.check_memory(&prepared.inner, &settings)?;
        let non_finite = recipe.nonfinite;
        // The starting view's, as `volray view` budgets its first frame.
        let cache_budget = cache_budget(&prepared.inner, &settings, non_finite, recipe.max_memory);
        let volume = Arc::new(prepared.inner.volume().clone());
        drop(prepared);
        let mut state = volray_view::start_state(&options, &settings);
        state.figure = Figure::of(&what);
        state.check().map_err(|e| {
            value_error(format!(
                "the starting view is beyond the viewer's bounds: {e}"
            ))
        })?;
        let sized = k.get("size").is_some() || k.get("camera").is_some();
        let reproduce = Arc::new(PyReproduce {
            start: OptionsStart {
                options: options.clone(),
                transfer_function: settings.transfer_function.clone(),
            },
            window: recipe.window(),
            value_unit: (what.units.clone())
                .or_else(|| preset_unit(options.look.preset.as_deref()).map(String::from)),
            level: levels.as_ref().map(|o| o.pyramid.fixed()),
            scale: recipe.scale(),
        });
        reproduce
            .reproduce(&state)
            .map_err(|e| value_error(format!("{name}: {e}")))?;
        let mut hello = Start {
            name: &name,
            volume: &volume,
            log: options.look.log,
            state: &state,
            settings: &settings,
            others: Vec::new(),
            time: None,
        }
        .hello();
        if let Some(opened) = &levels {
            opened.pyramid.describe(&mut hello);
        }
        hello.fit = !sized;
        let labels = volume.is_labels();
        let viewer = Viewer {
            volume,
            non_finite,
            cache_budget,
            max_memory: u128::from(recipe.max_memory),
            hello,
            reproduce: Arc::clone(&reproduce) as Arc<dyn Reproduce>,
            pool: Arc::new(pool(threads)?),
            max_sessions: MAX_TABS,
            levels: levels.map(|o| (o.pyramid.with_labels(labels), o.start)),
            others: Vec::new(),
            time: None,
            figure: FigureContext {
                log: facts.log,
                value_unit: reproduce.value_unit.clone(),
                length_unit: facts.length_unit,
                axis_names: facts.axis_names.map(String::from),
            },
        };
        let start_volume = Arc::clone(&viewer.volume);
        let mut host = py
            .detach(|| viewer.host())
            .map_err(|e| value_error(format!("{name}: {e}")))?;
        // Samples the caller can write (an array, a writeable Volume's).
        if digest.is_some() {
            host.watch(Arc::new(Watcher {
                recipe,
                last: Mutex::new(Watched {
                    digest,
                    generation: 0,
                    volume: start_volume,
                }),
            }));
        }
        let nonce =
            volray_view::Token::generate().map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(ViewHost {
            host,
            reproduce,
            current: Arc::new(Mutex::new(state)),
            page: volray_view::embedded_html(nonce.as_str()),
        })
    }

    /// The page, as one document for an iframe's `srcdoc`.
    #[getter]
    fn page(&self) -> &str {
        &self.page
    }

    /// A new page's renderer; `RuntimeError` where too many are open or
    /// memory is short.
    fn open(&self) -> PyResult<ViewTab> {
        let tab = (self.host.open()).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(ViewTab {
            tab,
            current: Arc::clone(&self.current),
        })
    }

    /// The camera of the view shown last.
    #[getter]
    fn camera(&self) -> PyResult<Camera> {
        let options = self.current_options()?;
        Ok(Camera {
            options: options.camera,
        })
    }

    /// The transfer function of the view shown last, whole: its window
    /// (the domain), opacity points and colours.
    #[getter]
    fn transfer_function(&self) -> PyResult<TransferFunction> {
        match self.current_options()?.look.tf {
            Some(Tf::Function(function)) => Ok(TransferFunction { function }),
            _ => Err(PyRuntimeError::new_err("the view has no transfer function")),
        }
    }

    /// The keywords of `render` that render the view shown last (beside
    /// the volume's own given to the viewer).
    fn keywords<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (options, figure) = self.current_words()?;
        let dict = PyDict::new(py);
        for (key, value) in keywords(&options).into_iter().chain(figure) {
            let object: Bound<'py, PyAny> = match value {
                Value::Camera(options) => Bound::new(py, Camera { options })?.into_any(),
                Value::Tf(function) => Bound::new(py, TransferFunction { function })?.into_any(),
                Value::Str(s) => s.into_pyobject(py)?.into_any(),
                Value::Number(x) => x.into_pyobject(py)?.into_any(),
                Value::Int(n) => n.into_pyobject(py)?.into_any(),
                Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
                Value::Numbers(v) => pyo3::types::PyTuple::new(py, v)?.into_any(),
            };
            dict.set_item(key, object)?;
        }
        Ok(dict)
    }

    /// The `render` call of the view shown last, as the page shows it.
    fn call(&self) -> PyResult<String> {
        let (options, figure) = self.current_words()?;
        Ok(call(&options, &figure))
    }

    /// The view shown last, as the page's JSON state.
    fn state(&self) -> String {
        serde_json::to_string(&*lock(&self.current)).expect("a state serialises")
    }

    /// The bytes the viewer's memory ledger holds now (the volume, the
    /// pages' renderers, the frames rendering or not yet acknowledged).
    fn held(&self) -> u128 {
        self.host.held()
    }
}

/// The samples of an array the caller may write between frames, prepared
/// again where they changed (volray-view's [`Watch`]).
struct Watcher {
    recipe: Recipe,
    last: Mutex<Watched>,
}

/// The volume as last prepared.
struct Watched {
    digest: Option<u64>,
    generation: u64,
    volume: Arc<volray_core::Volume>,
}

impl Watch for Watcher {
    fn current(&self, generation: u64) -> Result<Option<(u64, volray_core::Volume)>, String> {
        let name = &self.recipe.name;
        let failed = |e: PyErr| format!("{name}: {e}");
        // Called on a tab's renderer thread: attached to Python to read the
        // array, the lock never held while detached (digesting, preparing),
        // so that no thread holds it while waiting for the interpreter.
        Python::attach(|py| {
            let digest = self.recipe.digest(py, None).map_err(failed)?;
            let (known, last_generation) = {
                let last = lock(&self.last);
                (last.digest, last.generation)
            };
            if digest != known {
                // Only the samples are taken (the viewer's renderers keep
                // their own budget): any settings do.
                let default = RenderSettings::default();
                let prepared = (self.recipe.prepare(py, digest, &default)).map_err(failed)?;
                let mut last = lock(&self.last);
                if last.digest != digest {
                    *last = Watched {
                        digest,
                        generation: last.generation + 1,
                        volume: Arc::new(prepared.inner.volume().clone()),
                    };
                }
            } else if last_generation == generation {
                return Ok(None);
            }
            let last = lock(&self.last);
            Ok((last.generation != generation)
                .then(|| (last.generation, volray_core::Volume::clone(&last.volume))))
        })
    }
}

impl ViewHost {
    fn current_options(&self) -> PyResult<Options> {
        Ok(self.current_words()?.0)
    }

    /// The options of the view shown last, and its figure's keywords.
    fn current_words(&self) -> PyResult<(Options, Vec<(&'static str, Value)>)> {
        let state = lock(&self.current).clone();
        let options = (self.reproduce.options(&state)).map_err(|e| value_error(e.to_string()))?;
        Ok((options, self.reproduce.extra_words(&state.figure)))
    }
}

/// A chunked file opened for the viewer level by level.
struct Opened {
    pyramid: Pyramid,
    /// The level the first drafts show, read whole before the viewer
    /// starts (the page's first message is made from it).
    start: usize,
}

/// Opens `file`'s levels as the viewer's pyramid, as `volray view` opens
/// a chunked file (`src/view/levels.rs`): the stills show `level` (auto
/// by default), the drafts a coarse level held whole, the first of them
/// read before the page opens.
fn open_levels(
    py: Python<'_>,
    recipe: &Recipe,
    file: &LazyFile,
    level: Option<LevelChoice>,
    settings: &RenderSettings,
) -> PyResult<Opened> {
    let name = &recipe.name;
    if recipe.reshaped() || file.spacing_given {
        return Err(value_error(format!(
            "{name}: the viewer reads a chunked file's levels as its frames need them, but not yet with log=True or a spacing or origin given: read a level whole with volray.read(path, level=N)"
        )));
    }
    let count = file.chunked.levels().len();
    let fixed = match level {
        Some(LevelChoice::Index(n)) => {
            check_level(name, n, count)?;
            Some(n)
        }
        Some(LevelChoice::Auto) | None => None,
    };
    // Opened as `volray view` opens it (volray-view's `open_levels`), the
    // refusals worded here.
    let limit = u128::from(recipe.max_memory);
    let opened = py.detach(|| {
        let scale = recipe.scale();
        volray_view::open::open_levels(
            &file.chunked,
            fixed,
            settings,
            recipe.nonfinite,
            limit,
            scale,
        )
    });
    use volray_view::open::OpenError;
    match opened {
        Ok(o) => Ok(Opened {
            pyramid: o.pyramid,
            start: o.start,
        }),
        Err(OpenError::Read(e)) => Err(io_error(e)),
        Err(OpenError::CoarsestTooLarge {
            dims: [x, y, z], ..
        }) => Err(value_error(format!(
            "{name}: its coarsest level ({x}x{y}x{z}) takes more than the 1/{DRAFT_SHARE} of max_memory {} the viewer gives the frames while the view moves: raise max_memory",
            volray_io::format_bytes(limit)
        ))),
        Err(e) => Err(value_error(format!("{name}: {e}"))),
    }
}

#[pymethods]
impl ViewTab {
    /// Files a message from the page; the error message for the page
    /// (JSON) where it is refused.
    fn receive(&self, text: &str) -> Option<String> {
        match self.tab.receive(text) {
            Ok(Some(state)) => {
                *lock(&self.current) = state;
                None
            }
            Ok(None) => None,
            Err(reply) => Some(reply),
        }
    }

    /// The next message for the page, waiting for it with the GIL
    /// released: `(False, text)` or `(True, frame bytes)`; `None` once
    /// the tab is closed.
    fn next<'py>(&self, py: Python<'py>) -> Option<(bool, Bound<'py, PyAny>)> {
        match py.detach(|| self.tab.next())? {
            Message::Text(text) => Some((false, text.into_pyobject(py).ok()?.into_any())),
            Message::Frame(bytes) => Some((true, PyBytes::new(py, &bytes).into_any())),
        }
    }

    /// The page has the oldest frame it was given: the next may go.
    fn ack(&self) {
        self.tab.ack();
    }

    /// The frames given to the page and not acknowledged.
    #[getter]
    fn in_flight(&self) -> usize {
        self.tab.in_flight()
    }

    /// Stops the page's renderer: `next` returns `None`.
    fn close(&self) {
        self.tab.close();
    }
}

fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|e| e.into_inner())
}
