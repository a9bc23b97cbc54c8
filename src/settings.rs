//! The render settings the flags describe: the flags read into
//! volray-options' [`Options`] (the `--tf` file's text with them), which
//! checks them together and builds volray-core's settings, as it does for
//! Python and the viewer; its errors worded with the flags ([`Flags`]).

use crate::error::CliError;
use std::path::Path;
use volray_core::{RenderSettings, TransferFunction};
use volray_flags::{Flags, LookArgs, RenderArgs, ViewArgs, look};
use volray_options::{OptionError, Options, Tf};

/// An option error as one line naming the flags: bad input, exit 1.
pub fn refused(e: OptionError) -> CliError {
    CliError::input(e.message(&Flags))
}

/// The render settings the view arguments describe (reading `--tf`).
pub fn settings(view: &ViewArgs) -> Result<RenderSettings, CliError> {
    let tf_text = view.look.tf_file().map(read_tf_file).transpose()?;
    settings_with_tf_text(view, tf_text.as_deref())
}

/// The render settings the view arguments describe, with the text of the
/// `--tf` file given rather than read: [`settings`] reads it, `volray
/// view` writes the file its Command box names. `tf_text` is used only
/// when `--tf` is given.
pub fn settings_with_tf_text(
    view: &ViewArgs,
    tf_text: Option<&str>,
) -> Result<RenderSettings, CliError> {
    volray_options::settings(&options(view, tf_text)?).map_err(refused)
}

/// The options the view arguments give (volray-flags' `options`), with
/// the text of the `--tf` file, which must be given if `--tf` is.
pub fn options(view: &ViewArgs, tf_text: Option<&str>) -> Result<Options, CliError> {
    if let (Some(path), None) = (view.look.tf_file(), tf_text) {
        return Err(CliError::io(format!(
            "--tf {}: the file was not read",
            path.display()
        )));
    }
    Ok(volray_flags::options(view, tf_text))
}

/// The transfer function of `--tf` (its file's text `tf_text`) or
/// `--preset` (else the default), with `--colormap`'s colours and
/// `--range`'s window (volray-options' `named_transfer_function`).
pub fn named_transfer_function(
    look_args: &LookArgs,
    tf_text: Option<&str>,
) -> Result<TransferFunction, CliError> {
    let mut look = look(look_args);
    if let Some(Tf::Json { text, .. }) = &mut look.tf {
        *text = tf_text.unwrap_or_default().to_string();
    }
    volray_options::named_transfer_function(&look).map_err(refused)
}

/// `settings` with what the flags leave to `input`'s volume (volray-app's
/// `look`): the file's display window as the default `--range`, then
/// `--labels` or the transfer function chosen from it (`--tf auto`), the
/// volume marked as labels.
pub fn from_input(
    args: &RenderArgs,
    settings: &RenderSettings,
    input: &mut volray_app::input::Input,
) -> Result<RenderSettings, CliError> {
    let mut settings = settings.clone();
    let tf = &mut settings.transfer_function;
    let note = volray_app::look::leave_to_volume(&look(&args.view.look), tf, input);
    // A CT's look, said.
    if let Some(note) = note.map_err(refused)? {
        eprintln!("volray: {}: {note}", input.name);
    }
    Ok(settings)
}

/// Reads a `--tf` file (volray-app's `look`: a regular file of UTF-8
/// text, bounded).
pub fn read_tf_file(path: &Path) -> Result<String, CliError> {
    volray_app::look::read_tf_file(path).map_err(|e| {
        let message = format!("--tf {}: {e}", path.display());
        match e.is_io_failure() {
            true => CliError::io(message),
            false => CliError::input(message),
        }
    })
}
