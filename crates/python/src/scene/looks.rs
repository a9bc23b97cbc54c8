//! A scene's keywords read from Python: `channel_axis`'s channels of a
//! 4-D array, `looks` (one dict of per-volume keywords each), `mix` and
//! `color` (the names and decisions are volray-app's `scene`).

use crate::errors::value_error;
use crate::keywords::extract;
use crate::volume::Volume;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};
use volray_app::scene::{hex_colour, mix_of_name};
use volray_core::scene::Mix;
use volray_options::colors::named;

/// The per-volume keywords that decide how a volume is prepared (fixed
/// when a `Scene` is made).
pub const LAYER_VOLUME: &[&str] = &["spacing", "origin", "order", "labels", "log", "nonfinite"];

/// The per-volume keywords of a frame: how each volume is classified.
pub const LAYER_LOOK: &[&str] = &[
    "opacity",
    "tf",
    "preset",
    "colormap",
    "range",
    "iso",
    "iso_thickness",
    "gradient_opacity",
    "label_opacity",
    "show_labels",
];

/// A look's own keywords: a constant colour, an opacity scale, shown.
pub const LAYER_EXTRA: &[&str] = &["color", "opacity_scale", "visible"];

/// The items of a list or tuple.
pub(super) fn sequence<'py>(value: &Bound<'py, PyAny>) -> Option<Vec<Bound<'py, PyAny>>> {
    if let Ok(list) = value.cast::<PyList>() {
        return Some(list.iter().collect());
    }
    value.cast::<PyTuple>().ok().map(|t| t.iter().collect())
}

/// The channels of the 4-D array `volume` along `axis`, each a 3-D view.
pub(super) fn channels<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    axis: isize,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if sequence(volume).is_some() || volume.cast::<Volume>().is_ok() {
        return Err(value_error(
            "channel_axis splits one 4-D numpy array into its channels: give the array",
        ));
    }
    let numpy = py.import("numpy")?;
    let array = numpy.call_method1("asarray", (volume,))?;
    let ndim: usize = array.getattr("ndim")?.extract()?;
    if ndim != 4 {
        return Err(value_error(format!(
            "channel_axis: expected a 4-D array (channels and three axes), got {ndim}-D"
        )));
    }
    let axis0 = if axis < 0 { axis + 4 } else { axis };
    if !(0..4).contains(&axis0) {
        return Err(value_error(format!(
            "channel_axis: {axis} is not an axis of a 4-D array (0 to 3, or -4 to -1)"
        )));
    }
    let moved = numpy.call_method1("moveaxis", (array, axis0, 0))?;
    let count = moved.len()?;
    if count == 0 {
        return Err(value_error("channel_axis: the array has no channels"));
    }
    (0..count).map(|c| moved.get_item(c)).collect()
}

/// `looks=`: one dict per volume (copied), each key a per-volume keyword;
/// none given, an empty look each.
pub(super) fn check_looks(
    py: Python<'_>,
    looks: Option<&Bound<'_, PyAny>>,
    n: usize,
) -> PyResult<Vec<Py<PyDict>>> {
    let Some(looks) = looks.filter(|l| !l.is_none()) else {
        return Ok((0..n).map(|_| PyDict::new(py).unbind()).collect());
    };
    let type_name = |v: &Bound<'_, PyAny>| {
        (v.get_type().name())
            .map(|n| n.to_string())
            .unwrap_or_default()
    };
    let Some(items) = sequence(looks) else {
        return Err(PyTypeError::new_err(format!(
            "looks: expected a list of dicts, one per volume, got {}",
            type_name(looks)
        )));
    };
    if items.len() != n {
        return Err(value_error(format!(
            "looks: {} looks for {n} volumes: give one per volume",
            items.len()
        )));
    }
    let keys = [LAYER_VOLUME, LAYER_LOOK, LAYER_EXTRA].concat();
    (items.iter().enumerate())
        .map(|(i, item)| {
            let look = item.cast::<PyDict>().map_err(|_| {
                PyTypeError::new_err(format!(
                    "looks[{i}]: expected a dict of volume {i}'s keywords, got {}",
                    type_name(item)
                ))
            })?;
            for key in look.keys() {
                let name: String = key.extract().map_err(|_| {
                    PyTypeError::new_err(format!("looks[{i}]: keys must be keyword names"))
                })?;
                if !keys.contains(&name.as_str()) {
                    return Err(PyTypeError::new_err(format!(
                        "looks[{i}]: unknown key '{name}' for volume {i}: expected one of {}",
                        keys.join(", ")
                    )));
                }
            }
            Ok(look.copy()?.unbind())
        })
        .collect()
}

/// `mix=`: `'composite'` or `'additive'` (`default` when not given).
pub(super) fn parse_mix(value: Option<&Bound<'_, PyAny>>, default: Mix) -> PyResult<Mix> {
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(default);
    };
    let name: String = extract(value, "mix", "'composite' or 'additive'")?;
    mix_of_name(&name).ok_or_else(|| {
        value_error(format!(
            "mix: unknown mix '{name}': expected 'composite' or 'additive'"
        ))
    })
}

/// `color=`: a colour's name, `'#rrggbb'` (or `'#rgb'`), a grey level or
/// `(r, g, b)`, each in [0, 1].
pub(super) fn parse_color(value: &Bound<'_, PyAny>) -> PyResult<[f32; 3]> {
    if let Ok(s) = value.cast::<PyString>() {
        let text = s.to_cow()?;
        let lower = text.trim().to_ascii_lowercase();
        if let Some(rgb) = named(&lower) {
            return Ok(rgb);
        }
        if let Some(rgb) = lower.strip_prefix('#').and_then(hex_colour) {
            return Ok(rgb);
        }
        let names = volray_options::colors::names();
        return Err(value_error(format!(
            "color: unknown colour '{text}': expected '#rrggbb', (r, g, b) or one of {}",
            names.join(", ")
        )));
    }
    const WHAT: &str = "a colour's name, '#rrggbb' or (r, g, b)";
    let rgb = match value.extract::<f32>() {
        Ok(grey) => [grey; 3],
        Err(_) => extract::<[f32; 3]>(value, "color", WHAT)?,
    };
    if !rgb.iter().all(|c| (0.0..=1.0).contains(c)) {
        let [r, g, b] = rgb;
        return Err(value_error(format!(
            "color: ({r}, {g}, {b}) must be numbers in [0, 1]"
        )));
    }
    Ok(rgb)
}
