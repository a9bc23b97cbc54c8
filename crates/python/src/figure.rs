//! The annotations' keywords (`colorbar` and its `units`, `scale_bar`,
//! `title`, `label`, `axes`, `outline`), drawn into a frame by volray-annotate's
//! `annotate_frame` from the frame's renderer and settings, as `volray
//! render`'s flags of the same names draw them (`src/figure.rs`): the same
//! pixels for the same frame.

use crate::errors::value_error;
use crate::keywords::{Keywords, extract};
use pyo3::prelude::*;
use pyo3::types::PyBool;
use volray_annotate::colorbar::Side;
use volray_annotate::figure::{Annotations, Rendered, annotate_frame, parse_unit, preset_unit};
use volray_core::glam::DVec3;
use volray_core::{Image, RenderSettings, Renderer as CoreRenderer};
use volray_io::{FileInfo, VolumeFormat};
use volray_options::Options;

/// The annotations' keywords, for `render`, `Renderer.render` and a
/// `Scene`'s `render`.
pub const FIGURE: &[&str] = &[
    "colorbar",
    "units",
    "scale_bar",
    "title",
    "label",
    "axes",
    "outline",
];

/// The annotations `k` asks for.
pub fn annotations(k: &Keywords<'_>) -> PyResult<Annotations> {
    let colorbar = match k.get("colorbar") {
        None => None,
        Some(v) if v.is_instance_of::<PyBool>() => v.extract::<bool>()?.then_some(Side::Right),
        Some(v) => match extract::<String>(v, "colorbar", "'right', 'left' or None")?.as_str() {
            "right" => Some(Side::Right),
            "left" => Some(Side::Left),
            other => {
                return Err(value_error(format!(
                    "colorbar: {other:?} is not a side: give 'right', 'left' or None"
                )));
            }
        },
    };
    let scale_bar = match k.get("scale_bar") {
        None => None,
        Some(v) if v.is_instance_of::<PyBool>() => v.extract::<bool>()?.then_some(None),
        Some(v) => {
            let l: f64 = extract(v, "scale_bar", "True, a length or None")?;
            if !(l.is_finite() && l > 0.0) {
                return Err(value_error(format!(
                    "scale_bar: {l} is not a positive length"
                )));
            }
            Some(Some(l))
        }
    };
    let flag = |key: &str| -> PyResult<bool> {
        Ok(k.get(key)
            .map(|v| extract::<bool>(v, key, "True or False"))
            .transpose()?
            .unwrap_or(false))
    };
    Ok(Annotations {
        colorbar,
        scale_bar,
        title: k.take("title", "a str")?,
        label: k.take("label", "a str")?,
        axes: flag("axes")?,
        outline: flag("outline")?,
        units: (k.take::<String>("units", "a str")?)
            .map(|text| parse_unit(&text).map_err(|e| value_error(format!("units: {e}"))))
            .transpose()?,
    })
}

/// What a frame's volume tells the annotations: its units and the names
/// of its world's axes (a file's), as the command line takes them.
pub struct Facts {
    pub log: bool,
    pub length_unit: Option<String>,
    pub axis_names: [&'static str; 3],
}

impl Facts {
    pub fn of(file: Option<&(VolumeFormat, FileInfo)>, log: bool) -> Self {
        Facts {
            log,
            length_unit: file.and_then(|(_, info)| info.length_unit.clone()),
            axis_names: (file)
                .and_then(|(format, info)| volray_io::world_axis_names(*format, info))
                .unwrap_or(["x", "y", "z"]),
        }
    }
}

/// Draws `what` into `image`, rendered by `renderer` with `settings` from
/// `options`; the outline of `boxes`, a perspective scale bar at the
/// centre of `scale_box`.
#[allow(clippy::too_many_arguments)]
pub fn draw(
    image: &mut Image,
    what: &Annotations,
    renderer: &CoreRenderer<'_>,
    settings: &RenderSettings,
    options: &Options,
    facts: &Facts,
    boxes: &[(DVec3, DVec3)],
    scale_box: (DVec3, DVec3),
) -> PyResult<()> {
    if !what.any() {
        return Ok(());
    }
    let rendered = Rendered {
        log: facts.log,
        value_unit: preset_unit(options.look.preset.as_deref()),
        length_unit: facts.length_unit.as_deref(),
        axis_names: facts.axis_names,
        boxes,
        scale_box,
    };
    annotate_frame(image, what, renderer, settings, &rendered)
        .map_err(|e| value_error(e.to_string()))
}

/// The refusal of annotations for a frame rendered piece by piece.
pub fn refuse_pieces(what: &Annotations, name: &str) -> PyResult<()> {
    if what.any() {
        return Err(value_error(format!(
            "{name}: annotations are drawn into frames of a volume read whole; not into a volume rendered piece by piece yet (raise max_memory or pick a coarser level)"
        )));
    }
    Ok(())
}
