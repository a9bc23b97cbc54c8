//! PLACEHOLDER: reader being written (issue 6); replaced before submission.

use std::path::Path;

use crate::error::IoError;
use crate::{Loaded, ReadOptions};

pub(crate) fn read(path: &Path, _opts: &ReadOptions) -> Result<Loaded, IoError> {
    Err(IoError::invalid(path, "reader not written yet"))
}
