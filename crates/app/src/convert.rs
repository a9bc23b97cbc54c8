//! Volumes written back as files: `volray convert` and `volray generate`
//! write any volume volray reads as NRRD, `.npy` or raw, in the sample
//! type volray reads it in (`u8`, `i8`, `u16`, `i16`; other types as
//! `f32`, as they are read), or as an OME-Zarr image (`.zarr`,
//! `.ome.zarr`: a directory) with its pyramid of levels (volray-io's
//! `write_ome_zarr`).
//!
//! volray-io's writers stream the samples in chunks (an OME-Zarr image:
//! box by box, each lower level made from the one before read back from
//! the store), so a mapped volume converts in bounded memory, its pages
//! read by the operating system and dropped again; every output is
//! written atomically (no half-written file or store on a failure or
//! Ctrl-C). Here: which format a path names, the writing, and what was
//! written, in words.

use std::path::Path;
use volray_core::Volume;
use volray_io::{IoError, OmeZarrOptions, OmeZarrWritten, ZarrVersion, format_bytes};

/// Whether `path` names an OME-Zarr output: `.zarr` (`.ome.zarr` too).
pub fn is_zarr(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("zarr"))
}

/// What an OME-Zarr image holds, for the line `convert` prints: version,
/// type, levels (dims x by y by z), chunks and shards, codec, bytes.
pub fn zarr_summary(volume: &Volume, w: &OmeZarrWritten) -> String {
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

/// Writes `volume` as an OME-Zarr image at `path`: Zarr `version` (2 or
/// 3, the default), chunks of `chunk` voxels a side (64 by default),
/// within `max_memory` bytes.
pub fn write_zarr(
    path: &Path,
    volume: &Volume,
    version: Option<u8>,
    chunk: Option<usize>,
    max_memory: u64,
) -> Result<OmeZarrWritten, IoError> {
    let options = OmeZarrOptions {
        zarr_version: match version {
            Some(2) => ZarrVersion::V2,
            _ => ZarrVersion::V3,
        },
        chunk: chunk.unwrap_or(64),
        max_memory,
        ..OmeZarrOptions::default()
    };
    volray_io::write_ome_zarr(path, volume, &options)
}

/// The formats volray writes volumes in as one file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    Nrrd,
    Npy,
    Raw,
}

impl OutputFormat {
    /// The format `path`'s extension names (`.nrrd`, `.npy`, `.raw`), if
    /// one.
    pub fn of(path: &Path) -> Option<OutputFormat> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("nrrd") => Some(OutputFormat::Nrrd),
            Some("npy") => Some(OutputFormat::Npy),
            Some("raw") => Some(OutputFormat::Raw),
            _ => None,
        }
    }
}

/// Writes `volume` to `path` as `kind`, atomically, in its own sample
/// type (volray-io's writers stream it in chunks: a mapped volume is
/// written without being read whole).
pub fn write_volume(volume: &Volume, path: &Path, kind: OutputFormat) -> Result<(), IoError> {
    match kind {
        OutputFormat::Nrrd => volray_io::write_nrrd(path, volume),
        OutputFormat::Npy => volray_io::write_npy(path, volume),
        OutputFormat::Raw => volray_io::write_raw(path, volume),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_are_named_by_their_extensions() {
        assert_eq!(
            OutputFormat::of(Path::new("a.NRRD")),
            Some(OutputFormat::Nrrd)
        );
        assert_eq!(
            OutputFormat::of(Path::new("a.npy")),
            Some(OutputFormat::Npy)
        );
        assert_eq!(
            OutputFormat::of(Path::new("d/a.raw")),
            Some(OutputFormat::Raw)
        );
        for other in ["a.png", "a", "a.zarr", "a.nrrd.gz"] {
            assert_eq!(OutputFormat::of(Path::new(other)), None, "{other}");
        }
        assert!(is_zarr(Path::new("a.ome.zarr")) && is_zarr(Path::new("b.ZARR")));
        assert!(!is_zarr(Path::new("a.zarr.npy")));
    }
}
