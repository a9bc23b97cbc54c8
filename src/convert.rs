//! `volray convert INPUT -o OUT`: any volume volray reads, written as
//! NRRD, `.npy` or raw, in the sample type volray reads it in (`u8`,
//! `i8`, `u16`, `i16`; other types as `f32`, as they are read), or as an
//! OME-Zarr image (`.zarr`, `.ome.zarr`: a directory) with its pyramid of
//! levels (volray-io's `write_ome_zarr`).
//!
//! A volume over `--max-memory` whose file maps (volray-io's `MapPolicy`)
//! is mapped, not read, and written from the mapping chunk by chunk (an
//! OME-Zarr image: box by box, each lower level made from the one before
//! read back from the store): it converts in bounded memory, its pages
//! read by the operating system and dropped again. Every output is
//! written atomically (no half-written file or store on a failure or
//! Ctrl-C) and never over one of the files read; an existing output is
//! replaced (for OME-Zarr, only an existing Zarr store).

use crate::error::CliError;
use crate::flags::ConvertArgs;
use std::path::Path;
use volray_app::input;
use volray_core::Volume;
use volray_io::{OmeZarrOptions, OmeZarrWritten, ZarrVersion, format_bytes};

pub fn run(args: &ConvertArgs) -> Result<(), CliError> {
    let out = &args.output;
    let zarr = is_zarr(out);
    let kind = if zarr {
        None
    } else {
        refuse_zarr_flags(args)?;
        Some(OutputFormat::of(out).map_err(|_| {
            CliError::input(format!(
                "{}: unknown output format: use .nrrd (keeps spacing and origin), .npy, .raw (little-endian, x fastest, in the volume's sample type), or .zarr / .ome.zarr (OME-Zarr, a directory)",
                out.display()
            ))
        })?)
    };
    let spec = args.input.input.as_deref().unwrap_or(input::DEMO);
    crate::overwrite::refuse_overwriting_inputs(
        std::slice::from_ref(out),
        &[spec.to_string()],
        &[],
    )?;
    let mut input = input::load(&args.input.request())?;
    let Some(kind) = kind else {
        if args.labels {
            input.volume.set_labels(true);
        }
        let options = OmeZarrOptions {
            zarr_version: match args.zarr_version {
                Some(2) => ZarrVersion::V2,
                _ => ZarrVersion::V3,
            },
            chunk: args.chunk.map_or(64, usize::from),
            max_memory: input.max_memory,
            ..OmeZarrOptions::default()
        };
        let written = volray_io::write_ome_zarr(out, &input.volume, &options)?;
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

/// Whether `path` names an OME-Zarr output: `.zarr` (`.ome.zarr` too).
fn is_zarr(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("zarr"))
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

/// What an OME-Zarr image holds, for the line `convert` prints: version,
/// type, levels (dims x by y by z), chunks and shards, codec, bytes.
fn zarr_summary(volume: &Volume, w: &OmeZarrWritten) -> String {
    let xyz = |d: [usize; 3]| format!("{}x{}x{}", d[0], d[1], d[2]);
    let dims: Vec<String> = w.levels.iter().map(|l| xyz(l.dims)).collect();
    let first = &w.levels[0];
    let (zarr, layout) = match first.shard {
        Some(shard) => (
            "3",
            format!("chunks {} in shards {}", xyz(first.chunk), xyz(shard)),
        ),
        None => ("2", format!("chunks {}", xyz(first.chunk))),
    };
    let raw: u64 = w
        .levels
        .iter()
        .map(|l| l.dims.iter().product::<usize>() as u64 * volume.sample_type().bytes() as u64)
        .sum();
    format!(
        "OME-Zarr {} (Zarr v{zarr}), {}, {} level{} ({}): {}; {}, {}; {} stored ({:.0}% of {} raw)",
        w.ome_version,
        volume.sample_type().name(),
        w.levels.len(),
        if w.levels.len() == 1 { "" } else { "s" },
        if w.labels {
            "block modes"
        } else {
            "block means"
        },
        dims.join(", "),
        layout,
        w.codec,
        format_bytes(u128::from(w.bytes_stored)),
        100.0 * w.bytes_stored as f64 / raw.max(1) as f64,
        format_bytes(u128::from(raw)),
    )
}

/// The formats volray writes volumes in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    Nrrd,
    Npy,
    Raw,
}

impl OutputFormat {
    /// The format `path`'s extension names, or the error saying which
    /// there are.
    pub fn of(path: &Path) -> Result<OutputFormat, CliError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("nrrd") => Ok(OutputFormat::Nrrd),
            Some("npy") => Ok(OutputFormat::Npy),
            Some("raw") => Ok(OutputFormat::Raw),
            _ => Err(CliError::input(format!(
                "{}: unknown output format: use .nrrd (keeps spacing and origin), .npy or .raw (little-endian, x fastest, in the volume's sample type)",
                path.display()
            ))),
        }
    }
}

/// Writes `volume` to `path` as `kind`, atomically, in its own sample
/// type (volray-io's writers stream it in chunks: a mapped volume is
/// written without being read whole).
pub fn write_volume(volume: &Volume, path: &Path, kind: OutputFormat) -> Result<(), CliError> {
    match kind {
        OutputFormat::Nrrd => volray_io::write_nrrd(path, volume)?,
        OutputFormat::Npy => volray_io::write_npy(path, volume)?,
        OutputFormat::Raw => volray_io::write_raw(path, volume)?,
    }
    Ok(())
}
