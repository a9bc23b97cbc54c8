//! `volray generate`: write a generated volume (hydrogen density, fractal
//! cloud) to a file, in the format its extension names.

use crate::error::CliError;
use volray_data::DataError;
use volray_data::fractal::FractalParams;
use volray_data::hydrogen::HydrogenParams;
use volray_flags::{FractalArgs, GenerateArgs, GenerateKind, HydrogenArgs};

pub fn run(args: &GenerateArgs) -> Result<(), CliError> {
    match &args.kind {
        GenerateKind::Hydrogen(h) => check_hydrogen(h)?,
        GenerateKind::Fractal(f) => check_fractal(f)?,
    }
    let (volume, output) = match &args.kind {
        GenerateKind::Hydrogen(h) => (
            volray_data::hydrogen::generate(&hydrogen_params(h))?,
            &h.output,
        ),
        GenerateKind::Fractal(f) => (
            volray_data::fractal::generate(&fractal_params(f))?,
            &f.output,
        ),
    };
    crate::convert::write(&volume, output)?;
    let [nx, ny, nz] = volume.dims();
    let s = volume.spacing();
    let o = volume.origin();
    eprintln!(
        "wrote {}: {nx}x{ny}x{nz} f32, spacing {}, {}, {}, origin {}, {}, {}",
        output.display(),
        s.x,
        s.y,
        s.z,
        o.x,
        o.y,
        o.z
    );
    Ok(())
}

/// Checks each option against the library's own rules, one at a time with
/// the others at valid values, so that the error names the flag.
fn check_hydrogen(a: &HydrogenArgs) -> Result<(), CliError> {
    let base = HydrogenParams {
        n: 1,
        l: 0,
        m: 0,
        grid: 2,
        extent: None,
        real: a.real,
    };
    for (flag, params) in [
        ("--n", HydrogenParams { n: a.n, ..base }),
        (
            "--l",
            HydrogenParams {
                n: a.n,
                l: a.l,
                ..base
            },
        ),
        (
            "--m",
            HydrogenParams {
                n: a.n,
                l: a.l,
                m: a.m,
                ..base
            },
        ),
        (
            "--grid",
            HydrogenParams {
                grid: a.grid,
                ..base
            },
        ),
        (
            "--extent",
            HydrogenParams {
                extent: a.extent,
                ..base
            },
        ),
    ] {
        params.validate().map_err(|e| match e {
            DataError::Invalid { message, .. } => CliError::input(format!("{flag}: {message}")),
            e => CliError::input(format!("{flag}: {e}")),
        })?;
    }
    Ok(())
}

/// The largest `--sigma` (and the inverse of the smallest): the field is a
/// sum of displacements of a few sigma and is stored as `f32`, which
/// overflows to infinity near 3.4e38 and flushes to 0 below 1e-38.
const SIGMA_LIMIT: f64 = 1e30;

/// As [`check_hydrogen`], for the fractal's options.
fn check_fractal(a: &FractalArgs) -> Result<(), CliError> {
    let base = FractalParams::default();
    for (flag, params) in [
        (
            "--size",
            FractalParams {
                size: a.size,
                ..base
            },
        ),
        (
            "--dimension",
            FractalParams {
                dimension: a.dimension,
                ..base
            },
        ),
        (
            "--sigma",
            FractalParams {
                sigma: a.sigma,
                ..base
            },
        ),
        (
            "--ramp",
            FractalParams {
                ramp: a.ramp,
                ..base
            },
        ),
        (
            "--threshold",
            FractalParams {
                threshold: a.threshold,
                ..base
            },
        ),
    ] {
        params
            .validate()
            .map_err(|message| CliError::input(format!("{flag}: {message}")))?;
    }
    if !(1.0 / SIGMA_LIMIT..=SIGMA_LIMIT).contains(&a.sigma) {
        return Err(CliError::input(format!(
            "--sigma: {} is outside {:e} to {SIGMA_LIMIT:e}: the field is stored as 32-bit floats",
            a.sigma,
            1.0 / SIGMA_LIMIT
        )));
    }
    Ok(())
}

pub fn hydrogen_params(a: &HydrogenArgs) -> HydrogenParams {
    HydrogenParams {
        n: a.n,
        l: a.l,
        m: a.m,
        grid: a.grid,
        extent: a.extent,
        real: a.real,
    }
}

pub fn fractal_params(a: &FractalArgs) -> FractalParams {
    FractalParams {
        size: a.size,
        dimension: a.dimension,
        sigma: a.sigma,
        seed: a.seed,
        ramp: a.ramp,
        threshold: a.threshold,
        raw_field: a.raw_field,
        random_additions: a.random_additions,
    }
}
