//! `volray generate`: write a generated volume (hydrogen density, fractal
//! cloud) to a file, in the format its extension names.

use crate::cli::{FractalArgs, GenerateArgs, GenerateKind, HydrogenArgs};
use crate::error::CliError;
use std::path::Path;
use volray_core::Volume;
use volray_data::fractal::FractalParams;
use volray_data::hydrogen::HydrogenParams;

pub fn run(args: &GenerateArgs) -> Result<(), CliError> {
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
    write(&volume, output)?;
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

/// Writes `volume` in the format `path`'s extension names: `.npy`, `.raw`
/// (little-endian f32, x fastest) or `.nrrd` (with spacing and origin).
fn write(volume: &Volume, path: &Path) -> Result<(), CliError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("npy") => volray_io::write_npy(path, volume)?,
        Some("raw") => volray_io::write_raw(path, volume)?,
        Some("nrrd") => volray_io::write_nrrd(path, volume)?,
        _ => {
            return Err(CliError::input(format!(
                "{}: unknown output format: use .nrrd (keeps spacing and origin), .npy or .raw (f32, little-endian, x fastest)",
                path.display()
            )));
        }
    }
    Ok(())
}
