//! [`AppError`]: why an input could not be opened, planned or budgeted,
//! typed, each one line naming the file (or the built-in source). The
//! [`Display`](std::fmt::Display) words name options plainly (`dims`,
//! `max-memory`); each front end words them in its own syntax (the
//! command line's `--dims`, Python's `dims=`) by matching the variants.

use volray_core::{CameraError, RenderError, VolumeError};
use volray_distributed::frame::FrameError;
use volray_distributed::streamed::StreamError;
use volray_io::{IoError, format_bytes};
use volray_options::OptionError;

/// An input option whose value was not understood.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputOpt {
    Spacing,
    Format,
    Dtype,
    Endian,
}

impl InputOpt {
    /// The option's name as the command line spells it without its dashes.
    pub fn name(self) -> &'static str {
        match self {
            InputOpt::Spacing => "spacing",
            InputOpt::Format => "format",
            InputOpt::Dtype => "dtype",
            InputOpt::Endian => "endian",
        }
    }
}

/// A frame that would not fit the memory limit even with no brick cache
/// ([`crate::memory::cache_budget`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OverBudget {
    /// The input, for messages.
    pub name: String,
    /// The volume's grid points.
    pub dims: [usize; 3],
    /// The frame's width and height in pixels.
    pub size: (usize, usize),
    /// What the frame may take, and the limit.
    pub need: u128,
    pub limit: u128,
    /// On the reference path: what the fast path would take, where that
    /// fits the limit.
    pub fast_need: Option<u128>,
}

impl std::fmt::Display for OverBudget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [nx, ny, nz] = self.dims;
        write!(
            f,
            "{}: rendering {nx}x{ny}x{nz} voxels at {}x{} pixels may take up to {}, more than the memory limit {}",
            self.name,
            self.size.0,
            self.size.1,
            format_bytes(self.need),
            format_bytes(self.limit)
        )
    }
}

/// Why an input could not be opened, planned or rendered within its
/// budget.
#[derive(Debug, thiserror::Error)]
pub enum AppError {
    /// A reader's failure (volray-io's one-line message, naming the file).
    #[error(transparent)]
    Io(#[from] IoError),
    /// A built-in source's spec refused (volray-data).
    #[error(transparent)]
    Data(#[from] volray_data::DataError),
    /// An input option's value not understood (`message` says why).
    #[error("{}: {message}", option.name())]
    BadValue { option: InputOpt, message: String },
    /// Raw layout options given for a file that names another format.
    #[error(
        "{spec}: dims, dtype and endian describe raw files; this is a {format} file (give format raw to read it as raw)"
    )]
    RawLayoutOnFormat { spec: String, format: &'static str },
    /// A raw file without its dimensions.
    #[error("{path}: raw data needs dims X,Y,Z (and dtype unless it is f32)")]
    RawNeedsDims { path: String },
    /// File options given for a built-in source.
    #[error(
        "{spec}: dims, dtype, endian, format, frame, array, level, channel and series apply to files only, not to built-in sources"
    )]
    FileOptionsOnSource { spec: String },
    /// `level auto` where no still image picks the level.
    #[error("level auto chooses the level a still image needs: give a level number, 0 the finest")]
    AutoLevelNeedsStill,
    /// `level auto` for a file of one level.
    #[error(
        "{spec}: level auto applies to multiscale images (OME-Zarr); this file holds one level"
    )]
    AutoLevelOneLevel { spec: String },
    /// `level auto` could not frame the camera.
    #[error("{spec}: {error}")]
    AutoLevel { spec: String, error: CameraError },
    /// The log10 of the input refused (no positive value).
    #[error("log: {name}: {message}")]
    Log { name: String, message: String },
    /// A frame over the memory limit.
    #[error("{0}")]
    OverBudget(Box<OverBudget>),
    /// A volume refused: its non-finite values, or the renderer's
    /// settings.
    #[error("{name}: {error}")]
    Render { name: String, error: RenderError },
    /// A frame rendered in pieces failed.
    #[error("{name}: {error}")]
    Stream { name: String, error: StreamError },
    /// What the options leave to the volume refused (`labels`).
    #[error("{0}")]
    Option(OptionError),
    /// The spacing given is not positive and finite.
    #[error("spacing: {0}")]
    Spacing(VolumeError),
    /// A distributed step failed (the same on every rank).
    #[error("{name}: {error}")]
    Frame { name: String, error: FrameError },
    /// A rank's piece would not fit the memory limit (per rank).
    #[error(
        "{name}: this rank's piece, {}x{}x{} voxels with its ghost layers, needs {} to read and render, over the memory limit {}: run on more ranks",
        dims[0], dims[1], dims[2], format_bytes(*need), format_bytes(u128::from(*limit))
    )]
    PieceOverBudget {
        name: String,
        dims: [usize; 3],
        need: u128,
        limit: u64,
    },
    /// Rank 0 could not hold the volume it reads (or generates, if
    /// `generated`) whole with the pieces it sends.
    #[error(
        "{name}: rank 0 reads the volume whole to send each rank its piece: the volume ({}) with the pieces it cuts needs {}, over the memory limit {}",
        format_bytes(*volume), format_bytes(*need), format_bytes(u128::from(*limit))
    )]
    ScatterOverBudget {
        name: String,
        generated: bool,
        volume: u128,
        need: u128,
        limit: u64,
    },
    /// Channels along the time points of a file, with one time point picked.
    #[error(
        "{spec}: its channels are its time points (one channel); a frame picks one: give one of them"
    )]
    ChannelsAndFrame { spec: String },
    /// A front end's own refusal, carried through (its words; whether the
    /// input was at fault).
    #[error("{message}")]
    Refused { message: String, bad_input: bool },
}
