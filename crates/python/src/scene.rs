//! `Scene` and `render([a, b, ...])`: several volumes in one picture
//! (volray-core's [`volray_core::scene`]: one ray march through every
//! volume, so that each occludes the others where it lies in front).
//!
//! Each volume is prepared as a `Renderer` prepares one (`renderer.rs`'s
//! `Recipe`: its volume keywords, value range, labels or histogram, brick
//! caches), and each frame builds each volume's settings from the shared
//! keywords and its own look (a dict of the per-volume keywords `render`
//! takes for one volume, and `color`, `opacity_scale` and `visible`)
//! exactly as a frame of that volume alone would: its core `Look` is
//! `Look::of` those settings. One volume in a list renders as alone.
//!
//! A `Scene` keeps its volumes prepared across frames. Before each frame
//! it digests the arrays it renders (as a `Renderer` does) and, when one
//! changed, prepares every volume again (a core scene owns its
//! renderers and hands none back).
//!
//! Files: this one (the scene, its volumes prepared, its frames), and
//! `looks.rs` (its keywords read from Python: channels, looks, mix,
//! colours).

mod looks;

use crate::errors::{render_error, value_error};
use crate::figure::{self, FIGURE};
use crate::frame::Frame;
use crate::keywords::{self, CAMERA, FRAME, Keywords, extract};
use crate::renderer::{Known, Recipe, internal_error, interruptible, need, pool};
use crate::volume::Volume;
use looks::{LAYER_EXTRA, LAYER_VOLUME};
use looks::{channels, check_looks, parse_color, parse_mix, sequence};
use numpy::{PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use volray_app::scene::{channel_color, default_mix, mix_name};
use volray_core::RenderSettings;
use volray_core::scene::{Look, Mix, Scene as CoreScene, SceneSettings};
use volray_core::{FrameRequest, Render, Rendered};
use volray_io::format_bytes;
use volray_options::Options;
use volray_options::colors::channel_colour;

/// The keywords that make `render` render a scene.
pub const SCENE: &[&str] = &["looks", "mix", "channel_axis"];

const MAX_MEMORY: &[&str] = &["max_memory"];

/// Several volumes rendered together, each kept prepared across frames
/// (see the module documentation).
#[pyclass(frozen, module = "volray")]
pub struct Scene {
    layers: Vec<Layer>,
    /// One look per volume (a dict, the caller's copied).
    looks: Mutex<Vec<Py<PyDict>>>,
    mix: Mutex<Mix>,
    /// The volumes as last prepared.
    state: Mutex<Arc<Built>>,
}

/// One volume of a scene.
struct Layer {
    recipe: Recipe,
    /// Its colour unless its look gives one: a channel's, from the palette.
    palette: Option<[f32; 3]>,
}

/// The volumes prepared, together.
struct Built {
    scene: CoreScene<'static>,
    known: Vec<Known>,
    digests: Vec<Option<u64>>,
    /// The most each volume's brick caches may take: what `max_memory`
    /// leaves after the frames rendered so far, shared (volray-app's
    /// `shared_cache_budget`); `None` before the first frame. It never
    /// grows back, as a `Renderer`'s budget does not.
    share: Option<usize>,
}

/// Whether `render(volume, **kwargs)` renders a scene: a list or tuple of
/// volumes (each a `Volume` or a 3-D numpy array), or a scene's keyword.
pub fn is_scene(volume: &Bound<'_, PyAny>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<bool> {
    if let Some(kwargs) = kwargs {
        for key in SCENE {
            if kwargs.get_item(key)?.is_some_and(|v| !v.is_none()) {
                return Ok(true);
            }
        }
    }
    let Some(items) = sequence(volume) else {
        return Ok(false);
    };
    let each = |v: &Bound<'_, PyAny>| {
        v.cast::<Volume>().is_ok() || v.cast::<PyUntypedArray>().is_ok_and(|a| a.ndim() == 3)
    };
    Ok(!items.is_empty() && items.iter().all(each))
}

/// `render([a, b, ...], **kwargs)`: a scene made and rendered once
/// (`render.rs` sends it here).
pub fn render(
    py: Python<'_>,
    volumes: &Bound<'_, PyAny>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Frame> {
    if kwargs.is_some_and(|k| {
        k.get_item("level")
            .is_ok_and(|v| v.is_some_and(|v| !v.is_none()))
    }) {
        return Err(value_error(
            "level: several volumes are each read whole; level picks the level of one lazy volume",
        ));
    }
    let known = [
        LAYER_VOLUME,
        MAX_MEMORY,
        CAMERA,
        FRAME,
        LAYER_EXTRA,
        SCENE,
        FIGURE,
    ];
    Keywords::new(kwargs, &known, "render")?;
    let (volume_kwargs, frame_kwargs) = (PyDict::new(py), PyDict::new(py));
    let (mut looks, mut mix, mut channel_axis) = (None, None, None);
    if let Some(kwargs) = kwargs {
        for (key, value) in kwargs.iter() {
            let name: String = key.extract()?;
            match name.as_str() {
                "looks" => looks = Some(value),
                "mix" => mix = Some(value),
                "channel_axis" => channel_axis = Some(value),
                n if LAYER_VOLUME.contains(&n) || n == "max_memory" => {
                    volume_kwargs.set_item(key, value)?
                }
                _ => frame_kwargs.set_item(key, value)?,
            }
        }
    }
    let scene = Scene::make(
        py,
        volumes,
        looks.as_ref(),
        mix.as_ref(),
        channel_axis.as_ref(),
        Some(&volume_kwargs),
    )?;
    scene.frame(py, Some(&frame_kwargs), true)
}

impl Scene {
    /// The scene of `volumes` (a list, or with `channel_axis` a 4-D
    /// array, or one volume), its `looks`, `mix` and the shared volume
    /// keywords `kwargs`.
    fn make(
        py: Python<'_>,
        volumes: &Bound<'_, PyAny>,
        looks: Option<&Bound<'_, PyAny>>,
        mix: Option<&Bound<'_, PyAny>>,
        channel_axis: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        Keywords::new(kwargs, &[LAYER_VOLUME, MAX_MEMORY], "Scene")?;
        let channel_axis = channel_axis.filter(|a| !a.is_none());
        let (volumes, palette) = match channel_axis {
            Some(axis) => {
                let axis = extract::<isize>(axis, "channel_axis", "an axis number")?;
                let channels = channels(py, volumes, axis)?;
                let colours = (0..channels.len()).map(|c| Some(channel_colour(c)));
                (channels, colours.collect())
            }
            None => {
                let volumes = sequence(volumes).unwrap_or_else(|| vec![volumes.clone()]);
                if volumes.is_empty() {
                    return Err(value_error("a scene needs at least one volume"));
                }
                let palette = vec![None; volumes.len()];
                (volumes, palette)
            }
        };
        let n = volumes.len();
        let looks = check_looks(py, looks, n)?;
        // Channels add up by default, as napari and the command line show them.
        let mix = parse_mix(mix, default_mix(channel_axis.is_some()))?;
        let mut layers = Vec::with_capacity(n);
        for (i, (volume, palette)) in volumes.iter().zip(palette).enumerate() {
            // The shared volume keywords, then its look's.
            let given = PyDict::new(py);
            if let Some(kwargs) = kwargs {
                given.update(kwargs.as_mapping())?;
            }
            for (key, value) in looks[i].bind(py).iter() {
                if LAYER_VOLUME.contains(&key.extract::<String>()?.as_str()) {
                    given.set_item(key, value)?;
                }
            }
            let k = Keywords::new(Some(&given), &[LAYER_VOLUME, MAX_MEMORY], "Scene")?;
            let recipe = Recipe::build(volume, &k).map_err(|e| in_volume(py, i, n, e))?;
            layers.push(Layer { recipe, palette });
        }
        let digests = (layers.iter())
            .map(|l| l.recipe.digest(py, None))
            .collect::<PyResult<Vec<_>>>()?;
        let built = prepare(py, &layers, digests, None)?;
        Ok(Scene {
            layers,
            looks: Mutex::new(looks),
            mix: Mutex::new(mix),
            state: Mutex::new(Arc::new(built)),
        })
    }

    /// The volumes prepared from their samples as they are now: the last
    /// ones, or (an array changed since) every one again.
    fn current(&self, py: Python<'_>, pool: Option<&rayon::ThreadPool>) -> PyResult<Arc<Built>> {
        let last = Arc::clone(&self.state.lock().unwrap_or_else(|e| e.into_inner()));
        let digests = (self.layers.iter())
            .map(|l| l.recipe.digest(py, pool))
            .collect::<PyResult<Vec<_>>>()?;
        if digests == last.digests {
            return Ok(last);
        }
        let share = last.share;
        drop(last);
        let fresh = Arc::new(prepare(py, &self.layers, digests, share)?);
        *self.state.lock().unwrap_or_else(|e| e.into_inner()) = Arc::clone(&fresh);
        Ok(fresh)
    }

    /// One frame with the shared frame keywords `kwargs`; `fresh`: the
    /// volumes were prepared just now, so they need no second digest.
    fn frame(
        &self,
        py: Python<'_>,
        kwargs: Option<&Bound<'_, PyDict>>,
        fresh: bool,
    ) -> PyResult<Frame> {
        let k = Keywords::new(kwargs, &[CAMERA, FRAME, LAYER_EXTRA, FIGURE], "render")?;
        let what = figure::annotations(&k)?;
        let pool = keywords::threads(&k)?.map(pool).transpose()?;
        let built = match fresh {
            true => Arc::clone(&self.state.lock().unwrap_or_else(|e| e.into_inner())),
            false => self.current(py, pool.as_ref())?,
        };
        let looks: Vec<Bound<'_, PyDict>> = (self.looks.lock().unwrap_or_else(|e| e.into_inner()))
            .iter()
            .map(|d| d.bind(py).clone())
            .collect();
        let mix = *self.mix.lock().unwrap_or_else(|e| e.into_inner());
        let n = self.layers.len();
        let mut first: Option<(Options, RenderSettings)> = None;
        let mut scene_looks = Vec::with_capacity(n);
        let mut needed = 0u128;
        for (i, layer) in self.layers.iter().enumerate() {
            let (options, settings, look) = self
                .layer_settings(py, layer, kwargs, &looks[i], &built.known[i])
                .map_err(|e| {
                    // Named by its volume unless the shared keywords alone
                    // are wrong so.
                    let bare = PyDict::new(py);
                    match self.layer_settings(py, layer, kwargs, &bare, &built.known[i]) {
                        Err(shared) if same_error(py, &shared, &e) => e,
                        _ => in_volume(py, i, n, e),
                    }
                })?;
            let renderer = &built.scene.layers()[i];
            if n == 1 {
                layer.recipe.check_memory(renderer, &settings)?;
            }
            needed += need(renderer, &settings, layer.recipe.nonfinite);
            scene_looks.push(look);
            first.get_or_insert((options, settings));
        }
        let Some((options, settings)) = first else {
            unreachable!("a scene has a volume")
        };
        // The first volume's colour bar and scale bar, in the view that
        // frames every volume; the box of each volume for the outline (as
        // `volray render --channels/--overlay` draws them).
        let mut first_settings = settings.clone();
        first_settings.camera.bounds =
            Some((first_settings.camera).framed_bounds(built.scene.bounds()));
        let max_memory = self.layers[0].recipe.max_memory;
        if needed > u128::from(max_memory) {
            return Err(value_error(format!(
                "rendering {n} volumes at {}x{} pixels may take up to {}, more than max_memory {} (raise it, or use smaller grids)",
                settings.width,
                settings.height,
                format_bytes(needed),
                format_bytes(u128::from(max_memory)),
            )));
        }
        // The caches share what the frames leave: the volumes are
        // prepared again with smaller ones where this frame needs more
        // room than the last (the pixels are the same).
        let share = volray_app::memory::shared_cache_budget(needed, n, max_memory);
        let built = match built
            .scene
            .layers()
            .iter()
            .any(|r| r.cache_budget() > share)
        {
            false => built,
            true => {
                let digests = built.digests.clone();
                drop(built);
                let fresh = Arc::new(prepare(py, &self.layers, digests, Some(share))?);
                *self.state.lock().unwrap_or_else(|e| e.into_inner()) = Arc::clone(&fresh);
                fresh
            }
        };
        let name = match n {
            1 => self.layers[0].recipe.name.clone(),
            _ => "scene".to_string(),
        };
        let request = SceneSettings {
            settings,
            looks: scene_looks,
            mix,
        };
        let stop = AtomicBool::new(false);
        let (scene, request) = (&built.scene, &request);
        let (rendered, interrupt) = py.detach(|| {
            interruptible(pool.as_ref(), &stop, |report| {
                let request = FrameRequest::new(request).reporting(report);
                scene.render(request.stopped_by(&stop)).map(Rendered::image)
            })
        });
        if let Some(e) = interrupt {
            return Err(e);
        }
        let mut image = rendered
            .map_err(|panic| internal_error(&name, &panic))?
            .map_err(|e| render_error(e, &options.camera, &name))?;
        if what.any() {
            let renderers = built.scene.layers();
            let boxes: Vec<_> = renderers.iter().map(|r| r.volume().bounds()).collect();
            let facts = self.layers[0].recipe.facts(py);
            figure::draw(
                &mut image,
                &what,
                &renderers[0],
                &first_settings,
                &options,
                &facts,
                &boxes,
                boxes[0],
            )?;
        }
        Ok(Frame { image })
    }

    /// A volume's options, settings and look in a frame of the shared
    /// keywords `kwargs` and its `look`.
    fn layer_settings(
        &self,
        py: Python<'_>,
        layer: &Layer,
        kwargs: Option<&Bound<'_, PyDict>>,
        look: &Bound<'_, PyDict>,
        known: &Known,
    ) -> PyResult<(Options, RenderSettings, Look)> {
        let given = PyDict::new(py);
        if let Some(kwargs) = kwargs {
            given.update(kwargs.as_mapping())?;
        }
        for (key, value) in look.iter() {
            if !LAYER_VOLUME.contains(&key.extract::<String>()?.as_str()) {
                given.set_item(key, value)?;
            }
        }
        let own = |key: &str| -> PyResult<Option<Bound<'_, PyAny>>> {
            let value = given.get_item(key)?.filter(|v| !v.is_none());
            if value.is_some() {
                given.del_item(key)?;
            }
            Ok(value)
        };
        let color = own("color")?.map(|c| parse_color(&c)).transpose()?;
        let opacity_scale = own("opacity_scale")?
            .map(|v| extract::<f32>(&v, "opacity_scale", "a number in [0, 1]"))
            .transpose()?
            .unwrap_or(1.0);
        if !(opacity_scale.is_finite() && (0.0..=1.0).contains(&opacity_scale)) {
            return Err(value_error(format!(
                "opacity_scale: {opacity_scale} must be a number in [0, 1]"
            )));
        }
        let visible = own("visible")?
            .map(|v| extract::<bool>(&v, "visible", "True or False"))
            .transpose()?
            .unwrap_or(true);
        // The annotations are the frame's, drawn after it (`frame`).
        let k = Keywords::new(Some(&given), &[CAMERA, FRAME, FIGURE], "render")?;
        let recipe = &layer.recipe;
        let (options, mut settings) = recipe.settings_of(&k)?;
        let tf = &mut settings.transfer_function;
        if color.is_some() {
            let conflict = if options.look.colormap.is_some() {
                Some("colormap")
            } else if recipe.labels {
                Some("labels=True (a label volume takes its labels' colours)")
            } else if tf.color.is_some() && options.look.tf_given() {
                Some("tf, which gives colours")
            } else if tf.color.is_some() {
                Some("preset, which gives colours")
            } else {
                None
            };
            if let Some(other) = conflict {
                return Err(value_error(format!(
                    "color conflicts with {other}: give one of them"
                )));
            }
        }
        let colour = color.or(layer
            .palette
            .filter(|_| options.look.colormap.is_none() && !recipe.labels && tf.color.is_none()));
        if let Some(rgb) = colour {
            tf.color = Some(channel_color(rgb, settings.blend.is_projection()));
        }
        recipe.leave_to_volume(known, &options, &mut settings)?;
        let look = Look {
            opacity: opacity_scale,
            visible,
            ..Look::of(&settings)
        };
        Ok((options, settings, look))
    }
}

/// Every volume of `layers` prepared, whose samples' digests are
/// `digests`, and put together, each volume's caches within `share`.
fn prepare(
    py: Python<'_>,
    layers: &[Layer],
    digests: Vec<Option<u64>>,
    share: Option<usize>,
) -> PyResult<Built> {
    let n = layers.len();
    let mut renderers = Vec::with_capacity(n);
    let mut known = Vec::with_capacity(n);
    for (i, (layer, digest)) in layers.iter().zip(&digests).enumerate() {
        // Each volume's brick caches as a `Renderer`'s of it (the frame's
        // check counts every volume's frame, not their caches).
        let prepared = (layer.recipe)
            .prepare(py, *digest, &RenderSettings::default())
            .map_err(|e| in_volume(py, i, n, e))?;
        let budget = prepared
            .inner
            .cache_budget()
            .min(share.unwrap_or(usize::MAX));
        renderers.push(prepared.inner.with_cache_budget(budget));
        known.push(prepared.known);
    }
    let scene = CoreScene::new(renderers).map_err(|e| value_error(e.to_string()))?;
    Ok(Built {
        scene,
        known,
        digests,
        share,
    })
}

/// `e` of volume `i` of `n`, naming it where there are several.
fn in_volume(py: Python<'_>, i: usize, n: usize, e: PyErr) -> PyErr {
    if n == 1 {
        return e;
    }
    PyErr::from_type(e.get_type(py), format!("volume {i}: {}", e.value(py)))
}

/// Whether `a` and `b` are the same exception, word for word.
fn same_error(py: Python<'_>, a: &PyErr, b: &PyErr) -> bool {
    a.get_type(py).is(b.get_type(py)) && a.value(py).to_string() == b.value(py).to_string()
}

#[pymethods]
impl Scene {
    /// `Scene(volumes, *, looks=None, mix=None, channel_axis=None,
    /// spacing=None, origin=None, order="xyz", labels=None, log=False,
    /// nonfinite="refuse", max_memory=None)`: the volumes prepared once.
    #[new]
    #[pyo3(signature = (volumes, *, looks=None, mix=None, channel_axis=None, **kwargs))]
    fn new(
        py: Python<'_>,
        volumes: &Bound<'_, PyAny>,
        looks: Option<&Bound<'_, PyAny>>,
        mix: Option<&Bound<'_, PyAny>>,
        channel_axis: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        Scene::make(py, volumes, looks, mix, channel_axis, kwargs)
    }

    /// One frame: the camera and frame keywords of `render`, shared by
    /// every volume; per-volume keywords given here apply to every volume
    /// whose look does not give them.
    #[pyo3(signature = (**kwargs))]
    fn render(&self, py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Frame> {
        self.frame(py, kwargs, false)
    }

    /// The budgets of the volumes' brick caches, in bytes, as the next
    /// frame starts with them (for tests: they change speed, never pixels).
    #[getter]
    fn _cache_budgets(&self) -> Vec<usize> {
        let built = self.state.lock().unwrap_or_else(|e| e.into_inner());
        built
            .scene
            .layers()
            .iter()
            .map(|r| r.cache_budget())
            .collect()
    }

    /// The looks, one dict per volume (copies: set `looks` to change them).
    #[getter]
    fn get_looks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let looks = self.looks.lock().unwrap_or_else(|e| e.into_inner());
        let copies = (looks.iter())
            .map(|d| d.bind(py).copy())
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, copies)
    }

    /// New looks, one per volume; a volume keyword (`spacing`, `labels`,
    /// ...) may be repeated but not changed: the volumes are prepared.
    #[setter]
    fn set_looks(&self, py: Python<'_>, looks: &Bound<'_, PyAny>) -> PyResult<()> {
        let fresh = check_looks(py, Some(looks), self.layers.len())?;
        let mut kept = self.looks.lock().unwrap_or_else(|e| e.into_inner());
        for (i, (new, old)) in fresh.iter().zip(kept.iter()).enumerate() {
            let (new, old) = (new.bind(py), old.bind(py));
            for key in LAYER_VOLUME {
                let Some(value) = new.get_item(key)?.filter(|v| !v.is_none()) else {
                    continue;
                };
                let before = old.get_item(key)?.filter(|v| !v.is_none());
                let same = before.is_some_and(|b| b.eq(&value).unwrap_or(false));
                if !same {
                    return Err(value_error(format!(
                        "looks[{i}]: {key} is fixed when the scene is made (volume {i} is prepared): make a new Scene to change it"
                    )));
                }
            }
        }
        *kept = fresh;
        Ok(())
    }

    /// How the volumes mix: `'composite'` or `'additive'`.
    #[getter]
    fn get_mix(&self) -> &'static str {
        mix_name(*self.mix.lock().unwrap_or_else(|e| e.into_inner()))
    }

    #[setter]
    fn set_mix(&self, mix: &Bound<'_, PyAny>) -> PyResult<()> {
        let mix = parse_mix(Some(mix), Mix::Composite)?;
        *self.mix.lock().unwrap_or_else(|e| e.into_inner()) = mix;
        Ok(())
    }

    fn __len__(&self) -> usize {
        self.layers.len()
    }

    fn __repr__(&self) -> String {
        let state = Arc::clone(&self.state.lock().unwrap_or_else(|e| e.into_inner()));
        let dims: Vec<String> = (state.scene.layers().iter())
            .map(|l| {
                let [x, y, z] = l.volume().dims();
                format!("{x}x{y}x{z}")
            })
            .collect();
        let mix = mix_name(*self.mix.lock().unwrap_or_else(|e| e.into_inner()));
        format!("Scene({}, {mix})", dims.join(", "))
    }
}
