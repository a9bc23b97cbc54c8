//! Library errors as Python exceptions, with the command line's one-line
//! messages, options named as Python spells them ([`Keywords`]): bad
//! input is `ValueError`, a wrong type `TypeError`, a failure to read or
//! write `OSError`.

use pyo3::PyErr;
use pyo3::exceptions::{PyOSError, PyValueError};
use volray_app::AppError;
use volray_io::IoError;
use volray_options::{CameraOptions, Naming, Opt, OptionError};

/// How Python writes an option: `preset`, `labels=True`,
/// `shading=False`, `blend='mip'`.
pub struct Keywords;

impl Naming for Keywords {
    fn option(&self, opt: Opt) -> String {
        match opt {
            Opt::Labels | Opt::Log | Opt::PostClassification => {
                format!("{}=True", keyword(opt))
            }
            Opt::NoShading => "shading=False".to_string(),
            _ => keyword(opt),
        }
    }

    fn with_value(&self, opt: Opt, value: &str) -> String {
        // A placeholder (VALUE) stands bare; a name is a string.
        if value.chars().all(|c| c.is_ascii_uppercase()) {
            format!("{}={value}", keyword(opt))
        } else {
            format!("{}='{value}'", keyword(opt))
        }
    }
}

/// The keyword argument of `opt`: its name with `_` between words.
pub fn keyword(opt: Opt) -> String {
    opt.name().replace('-', "_")
}

pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// A box of a chunked file that could not be read: `OSError` where the
/// system failed to read it, `ValueError` for bad data (a corrupt or
/// lying chunk) and the rest, as for a file read whole.
pub fn source_error(e: volray_core::SourceError) -> PyErr {
    match e.is_io_failure() {
        true => PyOSError::new_err(e.message),
        false => value_error(e.message),
    }
}

pub fn option_error(e: OptionError) -> PyErr {
    value_error(e.message(&Keywords))
}

/// [`option_error`], a setting out of range prefixed with the keyword
/// that set it (`zoom: zoom -1 must be ...`); `camera` says which camera
/// keywords were given.
pub fn settings_error(e: OptionError, camera: &CameraOptions) -> PyErr {
    match &e {
        OptionError::Invalid(r) => match volray_options::option_of(r, camera) {
            Some(opt) => value_error(format!("{}: {r}", Keywords.option(opt))),
            None => value_error(r.to_string()),
        },
        _ => option_error(e),
    }
}

/// A reader's or writer's error: `OSError` where the system failed,
/// `ValueError` where the file is not what it should be.
pub fn io_error(e: IoError) -> PyErr {
    if e.is_io_failure() {
        PyOSError::new_err(e.to_string())
    } else {
        value_error(e.to_string())
    }
}

/// volray-app's error opening, planning or budgeting an input, in its
/// one-line words: the reader's failures as [`io_error`] maps them
/// (`OSError` where the system failed), a piece's read as
/// [`source_error`] does, the rest (bad input, bad options) `ValueError`.
/// A `log=True` refusal names the keyword as Python spells it.
pub fn app_error(e: AppError) -> PyErr {
    use volray_distributed::streamed::StreamError;
    match e {
        AppError::Io(e) => io_error(e),
        AppError::Stream {
            error: StreamError::Read(e),
            ..
        } => source_error(e),
        AppError::Log { name, message } => value_error(format!("log=True: {name}: {message}")),
        AppError::Refused {
            message,
            bad_input: false,
        } => PyOSError::new_err(message),
        other => value_error(other.to_string()),
    }
}

/// A render error of the volume `name`, naming the option to blame as
/// the command line does (`name: zoom: ...`).
pub fn render_error(e: volray_core::RenderError, camera: &CameraOptions, name: &str) -> PyErr {
    use volray_core::RenderError;
    match (&e, volray_options::option_of(&e, camera)) {
        (RenderError::SamplesChanged(_), _) => PyOSError::new_err(format!("{name}: {e}")),
        (RenderError::NonFinite { .. }, _) => value_error(format!(
            "{name}: {e}; use nonfinite='transparent' to render them as empty space"
        )),
        (_, Some(opt)) => value_error(format!("{name}: {}: {e}", Keywords.option(opt))),
        (_, None) => value_error(format!("{name}: {e}")),
    }
}
