//! Which of the samples of a multi-volume file read belong to the volume
//! kept ([`FrameSelect`]; which volume that is, `axes.rs` says).

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
