//! SPM's orientation of an Analyze 7.5 image: the `.mat` file beside the
//! header (`x.hdr`, `x.img`, `x.mat`), which SPM99/SPM2 write because the
//! Analyze header has no room for it, read as nibabel's
//! `Spm99AnalyzeImage` reads it (and `nibabel.load` picks that class for
//! an Analyze header):
//!
//! ```text
//! A = mat                          if the file holds `mat` (its first page
//!                                  where it holds several), which
//!                                  includes any flip;
//!   = diag(-1, 1, 1, 1) · M        else, from `M`, which does not (the
//!                                  Analyze convention is radiological)
//! world(i, j, k) = A · (i + 1, j + 1, k + 1, 1)   (MATLAB counts from 1)
//! ```
//!
//! An empty `.mat` is ignored, as nibabel ignores it; one that cannot be
//! read, or holds neither matrix, or a matrix that is not an invertible
//! finite 4×4 affine, is refused naming the `.mat` file (nibabel raises
//! too): taking the header's orientation instead would mirror the volume
//! without a word.

use std::path::{Path, PathBuf};

use volray_core::glam::DVec3;

use crate::FileInfo;
use crate::error::IoError;
use crate::shared::input::open_input;
use crate::shared::matlab::{self, MAX_BYTES, Matrix};

/// The `.mat` file beside the Analyze header at `path`.
fn mat_path(path: &Path) -> PathBuf {
    path.with_extension("mat")
}

/// The world step per index axis and the world position of voxel (0, 0,
/// 0) from SPM's `.mat` beside `path`, or `None` where there is none (or
/// it is empty).
pub(super) fn spm_geometry(
    path: &Path,
    info: &mut FileInfo,
) -> Result<Option<([DVec3; 3], DVec3)>, IoError> {
    let mat = mat_path(path);
    if !mat.is_file() {
        return Ok(None);
    }
    let (file, len) = open_input(&mat)?;
    if len == 0 {
        info.notes.push(format!(
            "{} is empty: ignored, as nibabel ignores it",
            mat.display()
        ));
        return Ok(None);
    }
    let refuse = |reason: String| {
        IoError::invalid(
            &mat,
            format!(
                "SPM's orientation file beside {}: {reason}",
                path.file_name().unwrap_or_default().to_string_lossy()
            ),
        )
    };
    if len > MAX_BYTES as u64 {
        return Err(refuse(format!(
            "{len} bytes, more than the {MAX_BYTES} an affine and a few other matrices need"
        )));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    std::io::Read::read_to_end(&mut std::io::Read::take(file, len), &mut bytes)
        .map_err(|e| IoError::os(&mat, "read", e))?;
    let matrices = matlab::matrices(&bytes).map_err(refuse)?;
    let find = |name: &str| matrices.iter().find(|(n, _)| n == name).map(|(_, m)| m);
    let (affine, which) = match (find("mat"), find("M")) {
        (Some(m), _) => (
            affine(m).map_err(|e| refuse(format!("its \"mat\" {e}")))?,
            "mat",
        ),
        (None, Some(m)) => {
            let mut a = affine(m).map_err(|e| refuse(format!("its \"M\" {e}")))?;
            // diag(-1, 1, 1, 1) · M: the first row negated.
            a[0] = a[0].map(|v| -v);
            (a, "M, x flipped")
        }
        (None, None) => {
            let names: Vec<_> = matrices.iter().map(|(n, _)| n.as_str()).collect();
            return Err(refuse(format!(
                "holds neither \"mat\" nor \"M\" (its matrices: {})",
                if names.is_empty() {
                    "none".into()
                } else {
                    names.join(", ")
                }
            )));
        }
    };
    let steps = [0, 1, 2].map(|c| DVec3::new(affine[0][c], affine[1][c], affine[2][c]));
    let translation = DVec3::new(affine[0][3], affine[1][3], affine[2][3]);
    let origin = translation + steps[0] + steps[1] + steps[2];
    let det = steps[0].dot(steps[1].cross(steps[2]));
    if !(det.is_finite() && det != 0.0) {
        return Err(refuse(format!(
            "its \"{}\" is not an invertible affine (determinant {det})",
            &which[..which.find(',').unwrap_or(which.len())]
        )));
    }
    info.notes.push(format!(
        "orientation from SPM's {} ({which}; voxel indices counted from 1), as nibabel reads it: the header's is not used",
        mat.file_name().unwrap_or_default().to_string_lossy()
    ));
    Ok(Some((steps, origin)))
}

/// The first 4×4 page of `m` as rows, or what is wrong with it.
fn affine(m: &Matrix) -> Result<[[f64; 4]; 4], String> {
    if m.dims.len() < 2 || m.dims[0] != 4 || m.dims[1] != 4 {
        return Err(format!("is {:?}, not a 4x4 matrix", m.dims));
    }
    let mut a = [[0.0; 4]; 4];
    for (r, row) in a.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = m.at(r, c);
            if !v.is_finite() {
                return Err(format!("holds {v} at row {}, column {}", r + 1, c + 1));
            }
        }
    }
    Ok(a)
}
