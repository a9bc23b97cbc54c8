//! volray for Python: `import volray`, numpy arrays in, images out.
//!
//! The module wraps the libraries, not the command line: volray-io reads
//! files, volray-data generates the paper's volumes, volray-options turns
//! keyword arguments into render settings exactly as it turns `volray
//! render`'s flags into them (so the same options give the same pixels),
//! and volray-core renders with the GIL released. The Python half
//! (`python/volray/__init__.py`) re-exports this module's names with
//! their documentation; `python/volray/__init__.pyi` types them.
//!
//! ```python
//! import numpy as np, volray
//! x, y, z = np.mgrid[-1:1:64j, -1:1:64j, -1:1:64j]
//! frame = volray.render(np.exp(-4 * (x*x + y*y + z*z)).astype(np.float32), azimuth=30)
//! frame.save("ball.png")            # or show it in Jupyter, or np.asarray(frame)
//! ```
//!
//! Where things are: `array.rs` (numpy arrays as volumes, without a copy),
//! `volume.rs` (`Volume`, `read`), `keywords.rs` (keyword arguments to
//! options, `Camera`), `render.rs` (`render`), `renderer.rs` (`Renderer`, Ctrl-C), `frame.rs`
//! (`Frame`), `transfer.rs` (`TransferFunction`), `generate.rs`
//! (`hydrogen`, `fractal`), `scene.rs` (`Scene`, `render` of several
//! volumes), `view.rs` (the viewer in a notebook: `volray.view`'s
//! host and tabs, the widget itself in `python/volray/_jupyter.py`),
//! `errors.rs` (library errors as Python
//! exceptions, options named as Python spells them).

use pyo3::prelude::*;

mod array;
mod digest;
mod errors;
mod figure;
mod frame;
mod generate;
mod keywords;
mod render;
mod renderer;
mod scene;
mod transfer;
mod view;
mod volume;

#[pymodule]
fn _volray(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<volume::Volume>()?;
    m.add_class::<renderer::Renderer>()?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<frame::Frame>()?;
    m.add_class::<transfer::TransferFunction>()?;
    m.add_class::<keywords::Camera>()?;
    m.add_class::<view::ViewHost>()?;
    m.add_class::<view::ViewTab>()?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(volume::read, m)?)?;
    m.add_function(wrap_pyfunction!(generate::hydrogen, m)?)?;
    m.add_function(wrap_pyfunction!(generate::fractal, m)?)?;
    // Test hooks, not exported by the package.
    m.add_function(wrap_pyfunction!(renderer::_interrupt_next_frame, m)?)?;
    m.add_function(wrap_pyfunction!(renderer::_hooked_frame_pixels, m)?)?;
    m.add_function(wrap_pyfunction!(renderer::_digest, m)?)?;
    m.add("PRESETS", volray_core::transfer::presets::NAMES.to_vec())?;
    m.add("COLORMAPS", volray_core::transfer::colormap::NAMES.to_vec())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
