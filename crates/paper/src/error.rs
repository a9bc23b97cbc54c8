//! The one error type of this crate: every message is one line naming what
//! failed (the figure, the data set or the file).

use std::fmt::Display;
use std::path::PathBuf;

use thiserror::Error;
use volray_core::RenderError;
use volray_data::DataError;
use volray_io::IoError;
use volray_surface::SurfaceError;

use crate::montage::MontageError;

/// Why a figure or the table could not be made.
#[derive(Debug, Error)]
pub enum PaperError {
    /// A data set could not be generated.
    #[error(transparent)]
    Data(#[from] DataError),
    /// A render was refused.
    #[error("{what}: {source}")]
    Render {
        what: String,
        #[source]
        source: RenderError,
    },
    /// A surface (Figure 1c) could not be built or rendered.
    #[error("{what}: {source}")]
    Surface {
        what: String,
        #[source]
        source: SurfaceError,
    },
    /// A montage could not be assembled.
    #[error(transparent)]
    Montage(#[from] MontageError),
    /// An output file could not be written.
    #[error(transparent)]
    Io(#[from] IoError),
    /// The output directory could not be created.
    #[error("{}: cannot create the output directory: {source}", dir.display())]
    OutputDir {
        dir: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl PaperError {
    /// Wraps a render error with what was being rendered.
    pub fn render(what: impl Display) -> impl FnOnce(RenderError) -> PaperError {
        move |source| PaperError::Render {
            what: what.to_string(),
            source,
        }
    }

    /// Whether the operating system failed (exit code 2) rather than the
    /// input or the arguments (exit code 1).
    pub fn is_io_failure(&self) -> bool {
        match self {
            PaperError::Io(e) => e.is_io_failure(),
            PaperError::OutputDir { .. } => true,
            PaperError::Data(_)
            | PaperError::Render { .. }
            | PaperError::Surface { .. }
            | PaperError::Montage(_) => false,
        }
    }
}
