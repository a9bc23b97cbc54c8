//! The paper's volumes, as numpy arrays `a[x, y, z]` of float32 equal to
//! what `volray generate` writes (`numpy.load` of its `.npy`): `hydrogen` (the electron density
//! |ψ_nlm|²) and `fractal` (the fractal cloud).

use crate::array::to_numpy;
use crate::errors::value_error;
use pyo3::prelude::*;
use volray_data::fractal::FractalParams;
use volray_data::hydrogen::HydrogenParams;

/// `hydrogen(n, l, m, grid=50, extent=None, real=False)`: |ψ_nlm|² on a
/// `grid`³ lattice over [−R, R]³ (R = `extent` in Bohr radii, or the
/// orbital's default), as `volray generate hydrogen` writes it.
#[pyfunction]
#[pyo3(signature = (n, l, m, grid=50, extent=None, real=false))]
pub fn hydrogen(
    py: Python<'_>,
    n: u32,
    l: u32,
    m: i32,
    grid: usize,
    extent: Option<f64>,
    real: bool,
) -> PyResult<Bound<'_, PyAny>> {
    let params = HydrogenParams {
        n,
        l,
        m,
        grid,
        extent,
        real,
    };
    let volume = py
        .detach(|| volray_data::hydrogen::generate(&params))
        .map_err(|e| value_error(e.to_string()))?;
    crate::array::xyz(&to_numpy(py, volume, true)?)
}

/// `fractal(size, dimension=3.7, sigma=1, seed=0, ramp=..., threshold=...,
/// raw_field=False, random_additions=...)`: the paper's fractal cloud on a
/// `size`³ grid, as `volray generate fractal` writes it; parameters left
/// out take `volray generate`'s defaults.
#[pyfunction]
#[pyo3(signature = (size, dimension=None, sigma=None, seed=None, ramp=None, threshold=None, raw_field=None, random_additions=None))]
#[allow(clippy::too_many_arguments)]
pub fn fractal(
    py: Python<'_>,
    size: usize,
    dimension: Option<f64>,
    sigma: Option<f64>,
    seed: Option<u64>,
    ramp: Option<f64>,
    threshold: Option<f64>,
    raw_field: Option<bool>,
    random_additions: Option<bool>,
) -> PyResult<Bound<'_, PyAny>> {
    let defaults = FractalParams::default();
    let params = FractalParams {
        size,
        dimension: dimension.unwrap_or(defaults.dimension),
        sigma: sigma.unwrap_or(defaults.sigma),
        seed: seed.unwrap_or(defaults.seed),
        ramp: ramp.unwrap_or(defaults.ramp),
        threshold: threshold.unwrap_or(defaults.threshold),
        raw_field: raw_field.unwrap_or(defaults.raw_field),
        random_additions: random_additions.unwrap_or(defaults.random_additions),
    };
    let volume = py
        .detach(|| volray_data::fractal::generate(&params))
        .map_err(|e| value_error(e.to_string()))?;
    crate::array::xyz(&to_numpy(py, volume, true)?)
}
