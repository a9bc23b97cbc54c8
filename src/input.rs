//! The INPUT argument: a built-in source spec or a volume file.

use crate::cli::InputArgs;
use crate::error::CliError;
use std::path::{Path, PathBuf};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{DType, Endian, RawOptions};

/// What `volray render` shows when given no input.
pub const DEMO: &str = "blobs:64";

/// A loaded volume and how to name it in messages.
pub struct Input {
    pub volume: Volume,
    /// The spec or the file's path, for messages.
    pub name: String,
    /// The file it came from, if any.
    pub path: Option<PathBuf>,
}

pub fn load(args: &InputArgs) -> Result<Input, CliError> {
    let spec = args.input.as_deref().unwrap_or(DEMO);
    let raw_flags = args.dims.is_some() || args.dtype.is_some() || args.endian.is_some();
    let (volume, path) = if volray_data::is_source_spec(spec) {
        if raw_flags {
            return Err(CliError::input(format!(
                "{spec}: --dims, --dtype and --endian apply to raw files only, not to built-in sources"
            )));
        }
        (volray_data::generate(spec)?, None)
    } else {
        let path = PathBuf::from(spec);
        let raw = if raw_flags {
            Some(raw_options(args, &path)?)
        } else {
            None
        };
        (volray_io::read_volume(&path, raw.as_ref())?, Some(path))
    };
    let volume = match args.spacing {
        Some(s) => volume
            .with_spacing(DVec3::from(s))
            .map_err(|e| CliError::input(format!("--spacing: {e}")))?,
        None => volume,
    };
    Ok(Input {
        volume,
        name: spec.to_string(),
        path,
    })
}

fn raw_options(args: &InputArgs, path: &Path) -> Result<RawOptions, CliError> {
    let name = path.display();
    let dims = args.dims.ok_or_else(|| {
        CliError::input(format!(
            "{name}: raw data needs --dims X,Y,Z (and --dtype unless it is f32)"
        ))
    })?;
    let dtype = match &args.dtype {
        Some(d) => d
            .parse::<DType>()
            .map_err(|e| CliError::input(format!("--dtype: {e}")))?,
        None => DType::F32,
    };
    let endian = match &args.endian {
        Some(e) => e
            .parse::<Endian>()
            .map_err(|e| CliError::input(format!("--endian: {e}")))?,
        None => Endian::Little,
    };
    let mut raw = RawOptions::new(dims, dtype);
    raw.endian = endian;
    raw.spacing = DVec3::from(args.spacing.unwrap_or([1.0; 3]));
    Ok(raw)
}
