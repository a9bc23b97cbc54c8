//! `volray convert INPUT -o OUT`: any volume volray reads, written as
//! NRRD, `.npy` or raw, in the sample type volray reads it in (`u8`,
//! `i8`, `u16`, `i16`; other types as `f32`, as they are read).
//!
//! A volume over `--max-memory` whose file maps (volray-io's `MapPolicy`)
//! is mapped, not read, and written from the mapping chunk by chunk: it
//! converts in bounded memory, its pages read by the operating system and
//! dropped again. Every output is written atomically (no half-written
//! file on a failure or Ctrl-C) and never over one of the files read.

use crate::error::CliError;
use crate::flags::ConvertArgs;
use crate::input;
use std::path::Path;
use volray_core::Volume;

pub fn run(args: &ConvertArgs) -> Result<(), CliError> {
    let out = &args.output;
    let kind = OutputFormat::of(out)?;
    let spec = args.input.input.as_deref().unwrap_or(input::DEMO);
    crate::overwrite::refuse_overwriting_inputs(
        std::slice::from_ref(out),
        &[spec.to_string()],
        &[],
    )?;
    let input = input::load(&args.input)?;
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
