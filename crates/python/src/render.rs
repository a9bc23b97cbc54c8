//! `volray.render`: one volume (`renderer.rs`) or several in one picture
//! (`scene.rs`), as what it is given says; neither module calls the
//! other.

use crate::frame::Frame;
use pyo3::prelude::*;
use pyo3::types::PyDict;

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
    crate::renderer::render_one(py, volume, kwargs)
}
