//! `volray convert INPUT -o OUT`: any volume volray reads, written as
//! NRRD, `.npy` or raw, or as an OME-Zarr image (`.zarr`, `.ome.zarr`)
//! with its pyramid of levels; how is volray-app's `convert`.
//!
//! A volume over `--max-memory` whose file maps (volray-io's `MapPolicy`)
//! is mapped, not read, and written from the mapping chunk by chunk: it
//! converts in bounded memory. Every output is written atomically and
//! never over one of the files read; an existing output is replaced (for
//! OME-Zarr, only an existing Zarr store). Here: the flags, and the line
//! saying what was written.

use crate::error::CliError;
use std::path::Path;
use volray_app::convert::{OutputFormat, is_zarr, write_volume, write_zarr, zarr_summary};
use volray_app::input;
use volray_flags::ConvertArgs;

pub fn run(args: &ConvertArgs) -> Result<(), CliError> {
    let out = &args.output;
    let kind = if is_zarr(out) {
        None
    } else {
        refuse_zarr_flags(args)?;
        Some(OutputFormat::of(out).ok_or_else(|| {
            CliError::input(format!(
                "{}: unknown output format: use .nrrd (keeps spacing and origin), .npy, .raw (little-endian, x fastest, in the volume's sample type), or .zarr / .ome.zarr (OME-Zarr, a directory)",
                out.display()
            ))
        })?)
    };
    let spec = args.input.input.as_deref().unwrap_or(input::DEMO);
    volray_app::reads::refuse_overwriting_inputs(
        std::slice::from_ref(out),
        &[spec.to_string()],
        &[],
    )?;
    let mut input = input::load(&args.input.request())?;
    let Some(kind) = kind else {
        if args.labels {
            input.volume.set_labels(true);
        }
        let chunk = args.chunk.map(usize::from);
        let written = write_zarr(
            out,
            &input.volume,
            args.zarr_version,
            chunk,
            input.max_memory,
        )?;
        eprintln!(
            "volray: wrote {}: {}",
            out.display(),
            zarr_summary(&input.volume, &written)
        );
        return Ok(());
    };
    write_volume(&input.volume, out, kind)?;
    let v = &input.volume;
    let [nx, ny, nz] = v.dims();
    let t = v.sample_type().name();
    let what = match kind {
        OutputFormat::Nrrd => {
            let (s, o) = (v.spacing(), v.origin());
            format!(
                "spacing {}, {}, {}, origin {}, {}, {}",
                s.x, s.y, s.z, o.x, o.y, o.z
            )
        }
        OutputFormat::Npy => "a[x, y, z] in Fortran order; .npy keeps no spacing or origin".into(),
        OutputFormat::Raw => format!(
            "read it back with --dims {nx},{ny},{nz} --dtype {t} --endian little; raw keeps no spacing or origin"
        ),
    };
    eprintln!(
        "volray: wrote {}: {nx}x{ny}x{nz} {t}, {what}",
        out.display()
    );
    Ok(())
}

/// The OME-Zarr flags, refused for a file output.
fn refuse_zarr_flags(args: &ConvertArgs) -> Result<(), CliError> {
    let given: Vec<&str> = [
        (args.zarr_version.is_some(), "--zarr-version"),
        (args.chunk.is_some(), "--chunk"),
        (args.labels, "--labels"),
    ]
    .into_iter()
    .filter_map(|(given, flag)| given.then_some(flag))
    .collect();
    if given.is_empty() {
        return Ok(());
    }
    Err(CliError::input(format!(
        "{}: {} appl{} to OME-Zarr output only (-o NAME.zarr or NAME.ome.zarr)",
        args.output.display(),
        given.join(" and "),
        if given.len() == 1 { "ies" } else { "y" }
    )))
}

/// Writes `volume` in the format `path`'s extension names: `.npy`, `.raw`
/// (little-endian, x fastest) or `.nrrd` (with spacing and origin):
/// `volray generate`'s output.
pub fn write(volume: &volray_core::Volume, path: &Path) -> Result<(), CliError> {
    let kind = OutputFormat::of(path).ok_or_else(|| {
        CliError::input(format!(
            "{}: unknown output format: use .nrrd (keeps spacing and origin), .npy or .raw (little-endian, x fastest, in the volume's sample type)",
            path.display()
        ))
    })?;
    Ok(write_volume(volume, path, kind)?)
}
