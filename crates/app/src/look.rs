//! What the look options leave to an input's volume, decided the same way
//! for every volume a front end reads whole (INPUT, a channel, an
//! overlay): the file's own display window (OME-Zarr `omero`) as the
//! default range, then labels or the transfer function chosen from the
//! volume's histogram (volray-options' `file_window` and `from_volume`),
//! or, for a CT in Hounsfield units, the CT look ([`ct_look`]); and a
//! transfer-function file read ([`read_tf_file`]), bounded.

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

/// The preset a CT gets where the look is left to the volume: bone, as
/// 3D Slicer's default CT volume rendering ("CT-Bone") and ParaView's
/// first CT preset show it; the soft tissue a histogram choice draws as
/// a slab is hidden.
pub const CT_PRESET: &str = "ct-bone";

/// The lowest value a CT in Hounsfield units holds is air (−1000) or the
/// scanner's padding outside the reconstructed circle (−1024, Siemens'
/// −2048, GE's −3024: about −1000 to −3100); its highest is bone or
/// contrast, above 200 HU (cancellous bone from about 200). A CT stored
/// without its rescale (0 to 4095) is not in this range, and keeps the
/// histogram's choice.
pub const HOUNSFIELD_MIN: (f32, f32) = (-3100.0, -900.0);
pub const HOUNSFIELD_MAX_ABOVE: f32 = 200.0;

/// Whether values from `min` to `max` are a CT's in Hounsfield units
/// ([`HOUNSFIELD_MIN`], [`HOUNSFIELD_MAX_ABOVE`]).
pub fn hounsfield(min: f32, max: f32) -> bool {
    (HOUNSFIELD_MIN.0..=HOUNSFIELD_MIN.1).contains(&min) && max > HOUNSFIELD_MAX_ABOVE
}

/// Whether `look` leaves the transfer function wholly to the volume:
/// none of `--tf` (`--tf auto` given keeps the histogram's choice),
/// `--preset`, `--colormap`, `--range`, `--opacity`, `--labels`, `--log`,
/// an isovalue or another blend mode.
pub fn nothing_given(look: &LookOptions) -> bool {
    look.tf.is_none()
        && look.auto_tf()
        && look.range.is_none()
        && look.opacity.is_none()
        && !look.log
}

/// The look of a CT where `look` leaves it to the volume: its file says
/// it is a CT (`modality`: DICOM Modality `CT`, MetaImage
/// `MET_MOD_CT`) and its values (`range`) are in Hounsfield units. A CT
/// without its modality (a NIfTI from dcm2niix) is not guessed from its
/// values alone: an MR or a simulation may hold the same range. The
/// transfer function, and the note that says so.
pub fn ct_look(
    look: &LookOptions,
    modality: Option<&str>,
    range: Option<(f32, f32)>,
) -> Option<(TransferFunction, String)> {
    let (min, max) = range?;
    if !(nothing_given(look) && modality == Some("CT") && hounsfield(min, max)) {
        return None;
    }
    let tf = volray_core::transfer::presets::preset(CT_PRESET)?;
    let note = format!(
        "a CT (modality CT, values {min} to {max} in Hounsfield units): drawn with --preset {CT_PRESET}; --tf auto for the look chosen from the histogram"
    );
    Some((tf, note))
}

/// [`ct_look`] of `input`'s volume and file.
pub fn ct_look_of(look: &LookOptions, input: &Input) -> Option<(TransferFunction, String)> {
    let modality = (input.file.as_ref()).and_then(|(_, info)| info.modality.as_deref());
    // Only a CT's values are looked at.
    modality?;
    ct_look(look, modality, input.volume.value_range())
}

/// Puts into `transfer_function` (and `input`'s volume, marked as labels)
/// what `look` leaves to `input`: a CT's look ([`ct_look`]), else the
/// file's display window, then labels (in the colours the file gives
/// them, if any) or `--tf auto`. The note to say, where a CT's look was
/// chosen.
pub fn leave_to_volume(
    look: &LookOptions,
    transfer_function: &mut TransferFunction,
    input: &mut Input,
) -> Result<Option<String>, OptionError> {
    if let Some((tf, note)) = ct_look_of(look, input) {
        *transfer_function = tf;
        return Ok(Some(note));
    }
    let window = (input.file.as_ref()).and_then(|(_, info)| info.display_window());
    volray_options::file_window(look, transfer_function, window);
    let look = with_file_colours(look, crate::input::label_colours(input));
    volray_options::from_volume(&look, transfer_function, &mut input.volume, &input.name)?;
    Ok(None)
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
