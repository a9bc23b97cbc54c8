//! A distributed job ([`Job`]): what it reads and how it looks, how a
//! front end words a rank's failure for the others ([`Words`]), and the
//! look the data decides (`--labels`, `--tf auto`) as one process takes it.

use crate::error::AppError;
use crate::input::Request;
use volray_core::transfer::auto;
use volray_core::{NonFinite, RenderSettings};
use volray_distributed::frame::{Distributed, Failure, FrameError};
use volray_distributed::mpi::Mpi;
use volray_options::LookOptions;

/// How a front end tells the other ranks this rank's failure: its own
/// one-line wording, and whether the input was at fault (a corrupt file
/// is bad input on every rank, as in one process).
pub type Words<'a> = &'a dyn Fn(&AppError) -> Failure;

/// What a distributed render reads and how it looks: the input, the
/// frame's settings, the look options (`--labels`, `--log`, `--tf auto`
/// are taken as one process takes them), and non-finite values.
pub struct Job {
    pub request: Request,
    pub settings: RenderSettings,
    pub look: LookOptions,
    pub non_finite: NonFinite,
}

/// A failed distributed step of the input `name`: the same on every rank.
pub(super) fn frame(name: &str, error: FrameError) -> AppError {
    AppError::Frame {
        name: name.to_string(),
        error,
    }
}

/// `settings` with what the look options leave to the volume, as one
/// process takes it (volray-options' `from_volume`): with `--labels`, the label
/// transfer function of the labels every rank found, joined; otherwise
/// `--tf auto` (the default) chosen from the whole volume's histogram,
/// summed over the ranks' owned voxels, within the file's display window
/// where it gives one.
pub(super) fn from_volume(
    d: &Distributed<'_, Mpi>,
    look: &LookOptions,
    (name, window): (&str, Option<(f64, f64)>),
    mut settings: RenderSettings,
) -> Result<RenderSettings, AppError> {
    let fail = |e| frame(name, e);
    volray_options::file_window(look, &mut settings.transfer_function, window);
    if look.labels {
        let found = d
            .labels(volray_core::transfer::labels::MAX_LABELS)
            .map_err(fail)?;
        let found = volray_options::labels_found(found, name).map_err(AppError::Option)?;
        volray_options::label_transfer_function(
            look,
            &mut settings.transfer_function,
            &found,
            name,
        )
        .map_err(AppError::Option)?;
        return Ok(settings);
    }
    if look.auto_tf()
        && let Some(first) = d.histogram(auto::BINS).map_err(fail)?
    {
        // Every pass is collective: the windows depend only on the summed
        // counts, the same on every rank.
        let robust =
            auto::robust_histogram(first, |window| d.histogram_in(Some(window), auto::BINS))
                .map_err(fail)?;
        volray_options::apply_auto(look, &mut settings.transfer_function, &robust);
    }
    Ok(settings)
}
