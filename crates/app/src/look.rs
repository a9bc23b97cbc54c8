//! What the look options leave to an input's volume, decided the same way
//! for every volume a front end reads whole (INPUT, a channel, an
//! overlay): the file's own display window (OME-Zarr `omero`) as the
//! default range, then labels or the transfer function chosen from the
//! volume's histogram (volray-options' `file_window` and `from_volume`);
//! and a transfer-function file read ([`read_tf_file`]), bounded.

use crate::input::Input;
use std::borrow::Cow;
use std::path::Path;
use volray_core::TransferFunction;
use volray_options::{LookOptions, OptionError};

/// The largest transfer-function file read: a transfer function is a few
/// hundred points; this bounds what a wrong path (a device, a huge file)
/// costs.
pub const TF_MAX_BYTES: u64 = 16 << 20;

/// Why a transfer-function file was not read; each front end puts the
/// option and the path before the message.
#[derive(Debug, thiserror::Error)]
pub enum TfFileError {
    /// The system's failure.
    #[error("cannot read: {0}")]
    Os(std::io::Error),
    #[error("not a regular file")]
    NotAFile,
    #[error("{0} bytes is too large for a transfer function (at most {TF_MAX_BYTES})")]
    TooLarge(u64),
    #[error("not UTF-8 text (a JSON file is expected)")]
    NotUtf8,
}

impl TfFileError {
    /// Whether the system failed (rather than the file being wrong).
    pub fn is_io_failure(&self) -> bool {
        matches!(self, TfFileError::Os(_))
    }
}

/// Reads a transfer-function file: a regular file of at most
/// [`TF_MAX_BYTES`], UTF-8 text.
pub fn read_tf_file(path: &Path) -> Result<String, TfFileError> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(TfFileError::Os)?;
    if !meta.is_file() {
        return Err(TfFileError::NotAFile);
    }
    if meta.len() > TF_MAX_BYTES {
        return Err(TfFileError::TooLarge(meta.len()));
    }
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(TF_MAX_BYTES).read_to_string(&mut text))
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::InvalidData => TfFileError::NotUtf8,
            _ => TfFileError::Os(e),
        })?;
    Ok(text)
}

/// Puts into `transfer_function` (and `input`'s volume, marked as labels)
/// what `look` leaves to `input`: the file's display window, then labels
/// (in the colours the file gives them, if any) or `--tf auto`.
pub fn leave_to_volume(
    look: &LookOptions,
    transfer_function: &mut TransferFunction,
    input: &mut Input,
) -> Result<(), OptionError> {
    let window = (input.file.as_ref()).and_then(|(_, info)| info.display_window());
    volray_options::file_window(look, transfer_function, window);
    let look = with_file_colours(look, crate::input::label_colours(input));
    volray_options::from_volume(&look, transfer_function, &mut input.volume, &input.name)
}

/// `look` with the colours its file gives the labels (a DICOM
/// Segmentation's segments, `file_colours`) for `--labels`, unless the
/// look names its own.
pub fn with_file_colours(
    look: &LookOptions,
    file_colours: Vec<(i64, [f32; 3])>,
) -> Cow<'_, LookOptions> {
    if look.label_colours.is_empty() && !file_colours.is_empty() {
        return Cow::Owned(LookOptions {
            label_colours: file_colours,
            ..look.clone()
        });
    }
    Cow::Borrowed(look)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tf_file_must_be_a_regular_file_of_utf8_text() {
        let dir = tempfile::tempdir().unwrap();
        let json = dir.path().join("tf.json");
        std::fs::write(&json, "{\"opacity\": []}").unwrap();
        assert_eq!(read_tf_file(&json).unwrap(), "{\"opacity\": []}");
        let binary = dir.path().join("tf.bin");
        std::fs::write(&binary, [0xff, 0xfe, 0x00]).unwrap();
        assert!(matches!(read_tf_file(&binary), Err(TfFileError::NotUtf8)));
        assert!(matches!(
            read_tf_file(dir.path()),
            Err(TfFileError::NotAFile)
        ));
        let gone = read_tf_file(&dir.path().join("gone.json")).unwrap_err();
        assert!(gone.is_io_failure() && gone.to_string().starts_with("cannot read: "));
        let big = dir.path().join("big.json");
        std::fs::File::create(&big)
            .unwrap()
            .set_len(TF_MAX_BYTES + 1)
            .unwrap();
        assert_eq!(
            read_tf_file(&big).unwrap_err().to_string(),
            format!(
                "{} bytes is too large for a transfer function (at most {TF_MAX_BYTES})",
                TF_MAX_BYTES + 1
            )
        );
    }
}
