//! Keyword arguments to volray-options' [`Options`]: each keyword is one
//! option of `volray render` (`look_at` is `--look-at`), taking a Python
//! value (a tuple where the flag takes `X,Y,Z`). A keyword left out, or
//! `None`, keeps the command line's default. Types are checked here
//! (`TypeError` naming the keyword); ranges and combinations are checked
//! by volray-options and volray-core, as for the command line. `Camera`
//! keeps the camera keywords together (`camera=`).

use crate::errors::value_error;
use crate::transfer::TransferFunction;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyString};
use std::collections::HashSet;
use volray_core::NonFinite;
use volray_core::shadows::ambient;
use volray_options::{BlendMode, CameraOptions, LookOptions, Options, Tf};

/// The camera's keywords, for `Camera(...)`, `Renderer.render` and
/// `render`.
pub const CAMERA: &[&str] = &[
    "size",
    "view",
    "look_at",
    "up",
    "perspective",
    "azimuth",
    "elevation",
    "zoom",
    "clip",
    "crop",
];

/// The keywords of one frame besides the camera's, for `Renderer.render`
/// and `render`.
pub const FRAME: &[&str] = &[
    "camera",
    "step",
    "jitter",
    "reference",
    "opacity",
    "tf",
    "preset",
    "colormap",
    "range",
    "blend",
    "iso",
    "iso_thickness",
    "gradient_opacity",
    "post_classification",
    "shading",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "light",
    "light_color",
    "shadows",
    "ambient_occlusion",
    "background",
    "label_opacity",
    "show_labels",
    "threads",
];

/// The keywords of the volume as rendered, for `Renderer(...)` and
/// `render`.
pub const VOLUME: &[&str] = &[
    "spacing",
    "origin",
    "scale",
    "order",
    "labels",
    "log",
    "nonfinite",
    "max_memory",
    "level",
];

/// Keyword arguments, each taken once.
pub struct Keywords<'py> {
    given: Vec<(String, Bound<'py, PyAny>)>,
}

impl<'py> Keywords<'py> {
    /// The arguments of `kwargs` for `function` (in messages), refused
    /// (`TypeError`, as Python does) where one is not in `known`.
    pub fn new(
        kwargs: Option<&Bound<'py, PyDict>>,
        known: &[&[&str]],
        function: &'static str,
    ) -> PyResult<Self> {
        let known: HashSet<&str> = known.iter().flat_map(|k| k.iter().copied()).collect();
        let mut given = Vec::new();
        if let Some(kwargs) = kwargs {
            for (key, value) in kwargs.iter() {
                let key: String = key.extract()?;
                if !known.contains(key.as_str()) {
                    return Err(PyTypeError::new_err(format!(
                        "{function}() got an unexpected keyword argument '{key}'"
                    )));
                }
                if !value.is_none() {
                    given.push((key, value));
                }
            }
        }
        Ok(Keywords { given })
    }

    /// The value of `key`, if given and not `None`.
    pub fn get(&self, key: &str) -> Option<&Bound<'py, PyAny>> {
        self.given.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// The first of `keys` given, if any.
    pub fn any(&self, keys: &[&str]) -> Option<String> {
        keys.iter()
            .find(|k| self.get(k).is_some())
            .map(|k| k.to_string())
    }

    /// `key` as `T`, `TypeError` saying `expected` otherwise.
    pub fn take<T: for<'a> FromPyObject<'a, 'py>>(
        &self,
        key: &str,
        expected: &str,
    ) -> PyResult<Option<T>> {
        self.get(key).map(|v| extract(v, key, expected)).transpose()
    }
}

/// `value` as `T`, or a `TypeError` naming `key` and what was `expected`.
pub fn extract<'py, T: for<'a> FromPyObject<'a, 'py>>(
    value: &Bound<'py, PyAny>,
    key: &str,
    expected: &str,
) -> PyResult<T> {
    value.extract::<T>().map_err(|_| {
        let got = value
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default();
        PyTypeError::new_err(format!("{key}: expected {expected}, got {got}"))
    })
}

const VEC3: &str = "three numbers (x, y, z)";
const PAIR: &str = "two numbers";
const RGB: &str = "a number or three (r, g, b)";

fn rgb<'py>(k: &Keywords<'py>, key: &str) -> PyResult<Option<[f32; 3]>> {
    let Some(v) = k.get(key) else { return Ok(None) };
    if let Ok(x) = v.extract::<f32>() {
        return Ok(Some([x; 3]));
    }
    extract::<[f32; 3]>(v, key, RGB).map(Some)
}

/// The camera keywords (or a `Camera`'s, given as `camera=`).
pub fn camera_options(k: &Keywords<'_>) -> PyResult<CameraOptions> {
    if let Some(camera) = k.get("camera") {
        let camera = camera
            .cast::<Camera>()
            .map_err(|_| PyTypeError::new_err("camera: expected a volray.Camera"))?;
        if let Some(key) = k.any(CAMERA) {
            return Err(value_error(format!(
                "{key} conflicts with camera=, which sets the whole camera: give one of them"
            )));
        }
        return Ok(camera.get().options.clone());
    }
    camera_from(k)
}

/// The camera keywords alone (`Camera(...)` takes the same).
pub fn camera_from(k: &Keywords<'_>) -> PyResult<CameraOptions> {
    let mut cam = CameraOptions::default();
    if let Some(size) = k.get("size") {
        cam.size = match size.extract::<usize>() {
            Ok(n) => (n, n),
            Err(_) => extract(size, "size", "an int or (width, height)")?,
        };
    }
    cam.view = k.take("view", VEC3)?;
    cam.look_at = k.take("look_at", VEC3)?;
    if let Some(up) = k.take("up", VEC3)? {
        cam.up = up;
    }
    cam.perspective = k.take("perspective", "a field of view in degrees")?;
    if let Some(a) = k.take("azimuth", "degrees")? {
        cam.azimuth = a;
    }
    if let Some(e) = k.take("elevation", "degrees")? {
        cam.elevation = e;
    }
    if let Some(z) = k.take("zoom", "a number")? {
        cam.zoom = z;
    }
    if let Some(clip) = k.get("clip") {
        const PLANE: &str =
            "a plane (x, y, z, nx, ny, nz) or ((x, y, z), (nx, ny, nz)), or a list of them";
        let one = |v: &Bound<'_, PyAny>| -> PyResult<([f64; 3], [f64; 3])> {
            if let Ok([x, y, z, nx, ny, nz]) = v.extract::<[f64; 6]>() {
                return Ok(([x, y, z], [nx, ny, nz]));
            }
            extract(v, "clip", PLANE)
        };
        cam.clip = match one(clip) {
            Ok(plane) => vec![plane],
            Err(_) => {
                let planes: Vec<Bound<'_, PyAny>> = extract(clip, "clip", PLANE)?;
                planes.iter().map(one).collect::<PyResult<_>>()?
            }
        };
    }
    if let Some([x0, x1, y0, y1, z0, z1]) =
        k.take::<[f64; 6]>("crop", "six numbers (x0, x1, y0, y1, z0, z1)")?
    {
        cam.crop = Some(([x0, y0, z0], [x1, y1, z1]));
    }
    Ok(cam)
}

/// A camera: the camera keywords of `render` kept together
/// (`render(volume, camera=cam)`), with the same defaults.
#[pyclass(frozen, module = "volray")]
pub struct Camera {
    pub options: CameraOptions,
}

#[pymethods]
impl Camera {
    /// `Camera(size=480, view=None, look_at=None, up=(0, 0, 1),
    /// perspective=None, azimuth=0, elevation=0, zoom=1, clip=None,
    /// crop=None)`.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let k = Keywords::new(kwargs, &[CAMERA], "Camera")?;
        Ok(Camera {
            options: camera_from(&k)?,
        })
    }

    #[getter]
    fn size(&self) -> (usize, usize) {
        self.options.size
    }

    #[getter]
    fn view(&self) -> Option<[f64; 3]> {
        self.options.view
    }

    #[getter]
    fn look_at(&self) -> Option<[f64; 3]> {
        self.options.look_at
    }

    #[getter]
    fn azimuth(&self) -> f64 {
        self.options.azimuth
    }

    #[getter]
    fn elevation(&self) -> f64 {
        self.options.elevation
    }

    #[getter]
    fn zoom(&self) -> f64 {
        self.options.zoom
    }

    #[getter]
    fn perspective(&self) -> Option<f64> {
        self.options.perspective
    }

    fn __repr__(&self) -> String {
        format!("Camera({:?})", self.options)
    }
}

/// `tf=`: `"auto"`, a `TransferFunction`, a dict of its JSON form, or the
/// path of a JSON file.
fn tf(value: &Bound<'_, PyAny>) -> PyResult<Tf> {
    if let Ok(f) = value.cast::<TransferFunction>() {
        return Ok(Tf::Function(f.get().function.clone()));
    }
    if let Ok(s) = value.cast::<PyString>()
        && s.to_cow()? == "auto"
    {
        return Ok(Tf::Auto);
    }
    if value.cast::<PyDict>().is_ok() {
        let text: String = value
            .py()
            .import("json")?
            .call_method1("dumps", (value,))?
            .extract()?;
        return Ok(Tf::Json {
            source: "(dict)".into(),
            text,
        });
    }
    let path: std::path::PathBuf = extract(
        value,
        "tf",
        "'auto', a volray.TransferFunction, a dict or the path of a JSON file",
    )?;
    let text = crate::transfer::read_json(&path)?;
    Ok(Tf::Json {
        source: path.display().to_string(),
        text,
    })
}

/// Every option of a frame but the volume's own (`labels`, `log`,
/// `nonfinite`), which the renderer fixes: `look` holds them already.
pub fn options(k: &Keywords<'_>, mut look: LookOptions) -> PyResult<Options> {
    let camera = camera_options(k)?;
    look.opacity = k.take("opacity", PAIR)?;
    look.tf = k.get("tf").map(tf).transpose()?;
    look.preset = k.take("preset", "a preset's name")?;
    look.colormap = k.take("colormap", "a colour map's name")?;
    look.range = k.take("range", "(lo, hi)")?;
    if let Some(name) = k.take::<String>("blend", "a blend mode's name")? {
        look.blend = BlendMode::from_name(&name).ok_or_else(|| {
            value_error(format!(
                "blend: unknown blend mode '{name}': expected one of {}",
                BlendMode::NAMES.join(", ")
            ))
        })?;
    }
    look.iso = k.take("iso", "a number")?;
    look.iso_thickness = k.take("iso_thickness", "a number")?;
    look.gradient_opacity = k.take("gradient_opacity", PAIR)?;
    if let Some(post) = k.take("post_classification", "True or False")? {
        look.post_classification = post;
    }
    if let Some(shading) = k.take("shading", "True or False")? {
        look.shading = shading;
    }
    if let Some(a) = rgb(k, "ambient")? {
        look.ambient = a;
    }
    if let Some(d) = rgb(k, "diffuse")? {
        look.diffuse = d;
    }
    if let Some(s) = rgb(k, "specular")? {
        look.specular = s;
    }
    if let Some(n) = k.take("shininess", "a number")? {
        look.shininess = n;
    }
    look.light = k.take("light", VEC3)?;
    if let Some(c) = rgb(k, "light_color")? {
        look.light_color = c;
    }
    if let Some(shadows) = k.take("shadows", "True or False")? {
        look.shadows = shadows;
    }
    if let Some(v) = k.get("ambient_occlusion") {
        // `True` is an `int` too: it means the default radius, not 1.
        look.ambient_occlusion = match v.cast::<PyBool>() {
            Ok(on) => on.is_true().then_some(ambient::DEFAULT_RADIUS),
            Err(_) => {
                let what = "True, False or a radius in voxels";
                Some(extract::<f64>(v, "ambient_occlusion", what)?)
            }
        };
    }
    if let Some(b) = rgb(k, "background")? {
        look.background = b;
    }
    if let Some(v) = k.get("label_opacity") {
        const WHAT: &str = "a dict {label: opacity} or a list of (label, opacity)";
        look.label_opacity = Some(match v.cast::<PyDict>() {
            Ok(d) => d
                .iter()
                .map(|(l, a)| {
                    Ok((
                        extract(&l, "label_opacity", WHAT)?,
                        extract(&a, "label_opacity", WHAT)?,
                    ))
                })
                .collect::<PyResult<_>>()?,
            Err(_) => extract(v, "label_opacity", WHAT)?,
        });
    }
    look.show_labels = k.take("show_labels", "a list of labels")?;
    let mut sampling = volray_options::SamplingOptions::default();
    if let Some(step) = k.take("step", "a number")? {
        sampling.step = step;
    }
    if let Some(jitter) = k.take("jitter", "True or False")? {
        sampling.jitter = jitter;
    }
    if let Some(reference) = k.take("reference", "True or False")? {
        sampling.reference = reference;
    }
    Ok(Options {
        camera,
        look,
        sampling,
    })
}

/// `nonfinite=`: `'refuse'` or `'transparent'`.
pub fn nonfinite(k: &Keywords<'_>) -> PyResult<NonFinite> {
    match k
        .take::<String>("nonfinite", "'refuse' or 'transparent'")?
        .as_deref()
    {
        None | Some("refuse") => Ok(NonFinite::Refuse),
        Some("transparent") => Ok(NonFinite::Transparent),
        Some(other) => Err(value_error(format!(
            "nonfinite: '{other}' is not a choice: expected 'refuse' or 'transparent'"
        ))),
    }
}

/// `threads=`: worker threads for the frame (default one per core).
pub fn threads(k: &Keywords<'_>) -> PyResult<Option<usize>> {
    match k.take::<usize>("threads", "a positive int")? {
        Some(0) => Err(value_error(
            "threads: 0 threads cannot render: give 1 or more",
        )),
        n => Ok(n),
    }
}
