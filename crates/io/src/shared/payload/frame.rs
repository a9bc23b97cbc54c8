//! Which volume of a multi-volume file is kept ([`chosen_frame`]), and
//! which of the samples read belong to it ([`FrameSelect`]).

use std::path::Path;

use crate::error::IoError;

/// Which samples of a multi-volume file to keep: sample `n` (counted
/// across all regions, file order) belongs to frame
/// `(n / stride) % count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct FrameSelect {
    pub stride: usize,
    pub count: usize,
    pub index: usize,
}

impl FrameSelect {
    /// Every sample (a file holding one volume).
    pub(crate) const ALL: FrameSelect = FrameSelect {
        stride: 1,
        count: 1,
        index: 0,
    };

    pub(super) fn keep_into<T: Copy>(&self, first: usize, values: &[T], out: &mut Vec<T>) {
        if self.count == 1 {
            out.extend_from_slice(values);
        } else {
            out.extend(
                values
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| ((first + i) / self.stride) % self.count == self.index)
                    .map(|(_, &v)| v),
            );
        }
    }
}

/// The volume [`ReadOptions::frame`](crate::ReadOptions::frame) asks for
/// (`requested`, default 0) of a file that holds `frames`; refused if there
/// is no such volume.
pub(crate) fn chosen_frame(
    path: &Path,
    requested: Option<usize>,
    frames: usize,
) -> Result<usize, IoError> {
    let frame = requested.unwrap_or(0);
    if frame >= frames {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the file holds {frames} volume{} (frames 0 to {})",
                if frames == 1 { "" } else { "s" },
                frames.saturating_sub(1)
            ),
        ));
    }
    Ok(frame)
}
