//! Failures of a command, each one line, and the exit code it maps to:
//! 0 success, 1 bad input or arguments, 2 I/O failure.

use std::fmt;

use volray_app::AppError;
use volray_app::error::OverBudget;
use volray_core::SourceError;
use volray_distributed::frame::FrameError;
use volray_distributed::streamed::StreamError;
use volray_io::{IoError, VolumeFormat, format_bytes};

#[derive(Debug)]
pub struct CliError {
    pub code: u8,
    pub message: String,
}

impl CliError {
    /// Bad input or arguments: exit code 1.
    pub fn input(message: impl Into<String>) -> Self {
        CliError {
            code: 1,
            message: message.into(),
        }
    }

    /// The operating system failed to read or write: exit code 2.
    pub fn io(message: impl Into<String>) -> Self {
        CliError {
            code: 2,
            message: message.into(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<IoError> for CliError {
    fn from(e: IoError) -> Self {
        io_error(&e)
    }
}

/// A reader's error worded with the flags: an I/O failure exits 2, bad
/// input 1.
fn io_error(e: &IoError) -> CliError {
    let message = naming_flags(e);
    if e.is_io_failure() {
        CliError::io(message)
    } else {
        CliError::input(message)
    }
}

/// `e`'s message, naming the flags that set the reader option it is about
/// where volray-io names the option (`frame 5` becomes `--frame 5`, `the
/// memory limit of 4 GiB` becomes `--max-memory 4 GiB`).
fn naming_flags(e: &IoError) -> String {
    let file = e.path().display();
    match e {
        IoError::RawSizeMismatch {
            dims: [x, y, z],
            dtype,
            actual,
            expected,
            ..
        } => format!(
            "{file}: file is {actual} bytes but --dims {x},{y},{z} with --dtype {dtype} need {expected} bytes"
        ),
        IoError::DimsOverflow {
            dims: [x, y, z],
            dtype,
            ..
        } => format!(
            "{file}: --dims {x},{y},{z} with --dtype {dtype} describe more bytes than this machine can address"
        ),
        IoError::UnknownFormat { .. } => format!(
            "{file}: unknown volume format (known by extension or content: {}); raw data needs --dims (and --dtype, --endian, --spacing as needed), or name the format with --format",
            VolumeFormat::KNOWN
        ),
        IoError::RawOptionsNotApplicable { format, .. } => {
            format!(
                "{file}: raw options (--dims, --dtype, --endian) do not apply to {format} files"
            )
        }
        IoError::FrameNotApplicable { format, .. } => {
            format!("{file}: --frame does not apply to {format} files: they hold one volume")
        }
        IoError::LevelNotApplicable { format, .. } => {
            format!("{file}: --level applies to Zarr/OME-Zarr images only, not to {format} files")
        }
        IoError::FrameOutOfRange { frame, held, .. } => {
            format!("{file}: --frame {frame} is out of range: {held}")
        }
        IoError::ChannelOutOfRange { channel, held, .. } => {
            format!("{file}: --channel {channel} is out of range: {held}")
        }
        IoError::FrameNeeded { held, choices, .. } => {
            format!("{file}: {held}; pick one with --frame N: {choices}")
        }
        IoError::ArrayNotApplicable { format, .. } => {
            format!(
                "{file}: --array applies to VTK files and OME-Zarr plates and collections only, not to {format} files"
            )
        }
        IoError::NoSuchArray { name, held, .. } => {
            format!("{file}: no array named \"{name}\" (--array): {held}")
        }
        IoError::ArrayNotScalar { array, scalars, .. } => format!(
            "{file}: {array}: volray renders scalar arrays; pick a one-component array with --array ({scalars})"
        ),
        IoError::OverMemoryLimit { need, limit, .. } => format!(
            "{file}: {need} --max-memory {}",
            format_bytes(u128::from(*limit))
        ),
        IoError::Os { .. }
        | IoError::NotAFile { .. }
        | IoError::Truncated { .. }
        | IoError::NoSuchDirectory { .. }
        | IoError::BadDestination { .. }
        | IoError::Volume { .. }
        | IoError::Npy { .. }
        | IoError::Invalid { .. }
        | IoError::NotRead { .. }
        | IoError::FlatImage { .. }
        | IoError::ImageSize { .. } => e.to_string(),
    }
}

impl From<AppError> for CliError {
    fn from(e: AppError) -> Self {
        word(&e)
    }
}

/// volray-app's error worded with the flags. A render error names no
/// flag here: `session::app_failure` names it where the view
/// flags are at hand.
pub fn word(e: &AppError) -> CliError {
    match e {
        AppError::Io(e) => io_error(e),
        AppError::Data(e) => CliError::input(e.to_string()),
        AppError::BadValue { option, message } => {
            CliError::input(format!("--{}: {message}", option.name()))
        }
        AppError::RawLayoutOnFormat { spec, format } => CliError::input(format!(
            "{spec}: --dims, --dtype and --endian describe raw files; this is a {format} file (give --format raw to read it as raw)"
        )),
        AppError::RawNeedsDims { path } => CliError::input(format!(
            "{path}: raw data needs --dims X,Y,Z (and --dtype unless it is f32)"
        )),
        AppError::FileOptionsOnSource { spec } => CliError::input(format!(
            "{spec}: --dims, --dtype, --endian, --format, --frame, --array, --level and --channel apply to files only, not to built-in sources"
        )),
        AppError::AutoLevelNeedsStill => CliError::input(
            "--level auto chooses the level a still image needs (volray render ... -o OUT.png): give a level number here, 0 the finest",
        ),
        AppError::AutoLevelOneLevel { spec } => CliError::input(format!(
            "{spec}: --level auto applies to multiscale images (OME-Zarr); this file holds one level"
        )),
        AppError::AutoLevel { spec, error } => CliError::input(format!("{spec}: {error}")),
        AppError::Log { name, message } => CliError::input(format!("--log: {name}: {message}")),
        AppError::Spacing(e) => CliError::input(format!("--spacing: {e}")),
        AppError::OverBudget(over) => over_budget(over),
        // Named with the flags by `session::app_failure`.
        AppError::Option(e) => CliError::input(e.to_string()),
        AppError::Render { name, error } => render_error(name, error),
        AppError::Stream { name, error } => match error {
            StreamError::Read(error) => CliError::from(error.clone()),
            StreamError::TooLarge(message) => CliError::input(format!(
                "{name}: {message}: raise --max-memory, or pick a coarser --level"
            )),
            StreamError::Render(error) => render_error(name, error),
        },
        // A failed distributed step: the same line on every rank.
        AppError::Frame { name, error } => match error {
            FrameError::Render(error) => render_error(name, error),
            FrameError::Rank {
                rank,
                message,
                bad_input: true,
            } => CliError::input(format!("rank {rank}: {message}")),
            FrameError::Rank { rank, message, .. } => {
                CliError::io(format!("rank {rank}: {message}"))
            }
            e => CliError::io(e.to_string()),
        },
        AppError::PieceOverBudget {
            name,
            dims: [x, y, z],
            need,
            limit,
        } => CliError::input(format!(
            "{name}: this rank's piece, {x}x{y}x{z} voxels with its ghost layers, needs {} to read and render, over --max-memory {}: run on more ranks",
            format_bytes(*need),
            format_bytes(u128::from(*limit)),
        )),
        AppError::ScatterOverBudget {
            name,
            generated,
            volume,
            need,
            limit,
        } => {
            let how = if *generated {
                "generates the fractal whole"
            } else {
                "reads the file whole (its format cannot be read by range)"
            };
            CliError::input(format!(
                "{name}: rank 0 {how} to send each rank its piece: the volume ({}) with the pieces it cuts needs {}, over --max-memory {}",
                format_bytes(*volume),
                format_bytes(*need),
                format_bytes(u128::from(*limit)),
            ))
        }
        AppError::ChannelsAndFrame { spec } => CliError::input(format!(
            "--channels renders the time points of {spec} (one channel) together; --frame picks one: give one of them"
        )),
        AppError::Refused { message, bad_input } => CliError {
            code: if *bad_input { 1 } else { 2 },
            message: message.clone(),
        },
    }
}

/// A render error of `name` naming no flag; the samples changing under
/// the renderer is the file's failure, not the flags'.
fn render_error(name: &str, error: &volray_core::RenderError) -> CliError {
    if let volray_core::RenderError::SamplesChanged(_) = error {
        return CliError::io(format!("{name}: {error}"));
    }
    CliError::input(format!("{name}: {error}"))
}

/// A frame over `--max-memory`, and the way out.
fn over_budget(over: &OverBudget) -> CliError {
    let [nx, ny, nz] = over.dims;
    let (w, h) = over.size;
    let what = format!(
        "{}: rendering {nx}x{ny}x{nz} voxels at {w}x{h} pixels",
        over.name
    );
    let (need, limit) = (format_bytes(over.need), format_bytes(over.limit));
    match over.fast_need {
        // The oracle is dense: say so where the default path would fit.
        Some(fast) => CliError::input(format!(
            "{what} on the reference path (--reference) may take up to {need}, more than --max-memory {limit}; the default path takes at most {}: leave out --reference",
            format_bytes(fast)
        )),
        None => CliError::input(format!(
            "{what} may take up to {need}, more than --max-memory {limit} (raise it, or use a smaller grid)"
        )),
    }
}

/// A box of a source that could not be read: an I/O failure exits 2,
/// bad data (a corrupt or lying chunk) and the rest 1.
impl From<SourceError> for CliError {
    fn from(e: SourceError) -> Self {
        match e.is_io_failure() {
            true => CliError::io(e.message),
            false => CliError::input(e.message),
        }
    }
}

/// An output that is one of the inputs (volray-app's `reads`).
impl From<volray_app::reads::Overwrites> for CliError {
    fn from(e: volray_app::reads::Overwrites) -> Self {
        CliError::input(e.to_string())
    }
}

impl From<volray_data::DataError> for CliError {
    fn from(e: volray_data::DataError) -> Self {
        CliError::input(e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use volray_io::{DType, RawOptions, ReadOptions};

    #[test]
    fn io_errors_name_the_flags() {
        let dir = tempfile::tempdir().unwrap();
        let raw = dir.path().join("data.raw");
        std::fs::write(&raw, [0u8; 1000]).unwrap();
        let read = |opts: ReadOptions| CliError::from(volray_io::read(&raw, &opts).unwrap_err());
        let err = read(ReadOptions {
            raw: Some(RawOptions::new([10, 10, 10], DType::F32)),
            ..ReadOptions::default()
        });
        assert_eq!(err.code, 1);
        assert_eq!(
            err.message,
            format!(
                "{}: file is 1000 bytes but --dims 10,10,10 with --dtype f32 need 4000 bytes",
                raw.display()
            )
        );
        let err = read(ReadOptions::default());
        assert!(err.message.contains("raw data needs --dims"), "{err}");
        assert!(err.message.ends_with("with --format"), "{err}");

        let frame = CliError::from(IoError::FrameOutOfRange {
            path: "a.nii".into(),
            frame: 5,
            held: "the file holds 2 volumes (dim[4]), numbered from 0".into(),
        });
        assert_eq!(
            frame.message,
            "a.nii: --frame 5 is out of range: the file holds 2 volumes (dim[4]), numbered from 0"
        );
        let memory = volray_io::check_volume_size(Path::new("a.nrrd"), "sizes", &[10; 3], 4, 3999)
            .unwrap_err();
        assert_eq!(
            CliError::from(memory).message,
            "a.nrrd: sizes 10 10 10 (1000 values, 3.9 KiB as f32) exceed --max-memory 3.9 KiB"
        );
        // Errors no option caused read as volray-io writes them.
        let os =
            volray_io::read(&dir.path().join("gone.npy"), &ReadOptions::default()).unwrap_err();
        let text = os.to_string();
        let err = CliError::from(os);
        assert_eq!((err.code, err.message), (2, text));
    }
}
