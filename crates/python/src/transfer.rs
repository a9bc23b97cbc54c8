//! `TransferFunction`: volray-core's, from points, JSON or a preset (the
//! camera keywords kept together, `Camera`, are `keywords.rs`').

use crate::errors::value_error;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use std::path::Path;
use volray_core::transfer::{colormap, presets};
use volray_core::{PiecewiseLinear, TransferFunction as CoreTf};

/// The text of the transfer-function file `path`.
pub fn read_json(path: &Path) -> PyResult<String> {
    // The command line's check and read (volray-app's `read_tf_file`),
    // its refusals as Python's exceptions.
    volray_app::look::read_tf_file(path).map_err(|e| {
        let text = format!("tf {}: {e}", path.display());
        if e.is_io_failure() {
            PyOSError::new_err(text)
        } else {
            value_error(text)
        }
    })
}

/// A transfer function: opacity and colour as piecewise-linear functions
/// of the value, over `domain` (the volume's value range if `None`), the
/// `t` of each point in [0, 1] of the domain.
#[pyclass(frozen, module = "volray")]
pub struct TransferFunction {
    pub function: CoreTf,
}

#[pymethods]
impl TransferFunction {
    /// `TransferFunction(opacity=[(t, a), ...], color=[(t, r, g, b), ...],
    /// domain=None)`: points sorted by `t`, values in [0, 1].
    #[new]
    #[pyo3(signature = (opacity=None, color=None, domain=None))]
    fn new(
        opacity: Option<Vec<(f32, f32)>>,
        color: Option<Vec<(f32, f32, f32, f32)>>,
        domain: Option<(f64, f64)>,
    ) -> PyResult<Self> {
        let bad =
            |e: volray_core::transfer::function::TransferFunctionError| value_error(e.to_string());
        let opacity = opacity
            .map(|p| {
                PiecewiseLinear::new("opacity", p.into_iter().map(|(t, a)| (t, [a])).collect())
            })
            .transpose()
            .map_err(bad)?;
        let color = color
            .map(|p| {
                PiecewiseLinear::new(
                    "color",
                    p.into_iter().map(|(t, r, g, b)| (t, [r, g, b])).collect(),
                )
            })
            .transpose()
            .map_err(bad)?;
        if let Some((lo, hi)) = domain
            && !(lo.is_finite() && hi.is_finite() && lo < hi)
        {
            return Err(value_error(format!(
                "domain ({lo}, {hi}) must be two finite numbers with lo < hi"
            )));
        }
        Ok(TransferFunction {
            function: CoreTf {
                domain,
                opacity,
                color,
            },
        })
    }

    /// The transfer function of a JSON text or file (the form `volray
    /// render --tf` reads).
    #[staticmethod]
    fn from_json(text_or_path: &Bound<'_, PyAny>) -> PyResult<Self> {
        let text: String = match text_or_path.extract::<String>() {
            Ok(s) if s.trim_start().starts_with('{') => s,
            _ => {
                let path: std::path::PathBuf = text_or_path.extract()?;
                read_json(&path)?
            }
        };
        CoreTf::from_json(&text)
            .map(|function| TransferFunction { function })
            .map_err(|e| value_error(e.to_string()))
    }

    /// A named transfer function: one of `volray.PRESETS`.
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Self> {
        presets::preset(name)
            .map(|function| TransferFunction { function })
            .ok_or_else(|| {
                value_error(format!(
                    "preset: unknown preset '{name}': expected one of {}",
                    presets::NAMES.join(", ")
                ))
            })
    }

    /// This transfer function with the colours of a named colour map (one
    /// of `volray.COLORMAPS`).
    fn with_colormap(&self, name: &str) -> PyResult<Self> {
        let color = colormap::colormap(name).ok_or_else(|| {
            value_error(format!(
                "colormap: unknown colour map '{name}': expected one of {}",
                colormap::NAMES.join(", ")
            ))
        })?;
        Ok(TransferFunction {
            function: CoreTf {
                color: Some(color),
                ..self.function.clone()
            },
        })
    }

    #[getter]
    fn opacity(&self) -> Option<Vec<(f32, f32)>> {
        (self.function.opacity.as_ref())
            .map(|f| f.points().iter().map(|(t, [a])| (*t, *a)).collect())
    }

    #[getter]
    fn color(&self) -> Option<Vec<(f32, f32, f32, f32)>> {
        (self.function.color.as_ref()).map(|f| {
            f.points()
                .iter()
                .map(|(t, [r, g, b])| (*t, *r, *g, *b))
                .collect()
        })
    }

    #[getter]
    fn domain(&self) -> Option<(f64, f64)> {
        self.function.domain
    }

    /// The value's opacity and colour `(a, r, g, b)` at `t` in [0, 1] of
    /// the domain (1 and white where a function is not given).
    fn __call__(&self, t: f32) -> (f32, f32, f32, f32) {
        let [a] = (self.function.opacity.as_ref()).map_or([1.0], |f| f.eval(t));
        let [r, g, b] = (self.function.color.as_ref()).map_or([1.0; 3], |f| f.eval(t));
        (a, r, g, b)
    }

    fn __repr__(&self) -> String {
        let count = |n: Option<usize>| n.map_or("none".to_string(), |n| format!("{n} points"));
        format!(
            "TransferFunction(opacity: {}, color: {}, domain: {:?})",
            count(self.function.opacity.as_ref().map(|f| f.points().len())),
            count(self.function.color.as_ref().map(|f| f.points().len())),
            self.function.domain
        )
    }
}
