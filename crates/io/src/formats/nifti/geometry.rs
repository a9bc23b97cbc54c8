//! Where a NIfTI volume lies in the world: the sform, else the qform
//! quaternion, else `pixdim` alone (nifti1.h methods 3, 2 and 1), and the
//! length unit of `xyzt_units`; an Analyze 7.5 grid's from SPM's `.mat`
//! beside it (`spm.rs`), else as nibabel places a header without one.

use std::path::Path;

use volray_core::glam::{DMat3, DVec3};

use super::header::Header;
use super::spm::spm_geometry;
use crate::FileInfo;
use crate::error::IoError;

/// The world step per index axis and the world position of voxel (0, 0, 0).
pub(super) fn geometry(
    path: &Path,
    h: &Header,
    info: &mut FileInfo,
) -> Result<([DVec3; 3], DVec3), IoError> {
    if let Some(originator) = h.analyze {
        if let Some(geometry) = spm_geometry(path, info)? {
            return Ok(geometry);
        }
        return analyze_geometry(path, h, originator, info);
    }
    if h.sform_code > 0 {
        let steps = [0, 1, 2].map(|a| DVec3::new(h.srow[0][a], h.srow[1][a], h.srow[2][a]));
        let origin = DVec3::new(h.srow[0][3], h.srow[1][3], h.srow[2][3]);
        info.notes.push(format!(
            "world coordinates (RAS+) from the sform (sform_code {} = {}){}",
            h.sform_code,
            xform_name(h.sform_code),
            if h.qform_code > 0 {
                "; the qform was not used"
            } else {
                ""
            }
        ));
        return Ok((steps, origin));
    }
    let zooms = pixdims(path, h)?;
    if h.qform_code > 0 {
        let [b, c, d] = h.quatern;
        if !(b.is_finite() && c.is_finite() && d.is_finite()) {
            return Err(IoError::invalid(
                path,
                format!("NIfTI qform quaternion (b, c, d) = ({b}, {c}, {d}) is not finite"),
            ));
        }
        let rotation = quaternion_rotation(b, c, d);
        // pixdim[0] is qfac: -1 mirrors the k axis (nifti1_io treats any
        // negative value as -1 and anything else as 1).
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let steps = [
            rotation.x_axis * zooms[0],
            rotation.y_axis * zooms[1],
            rotation.z_axis * (zooms[2] * qfac),
        ];
        let origin = DVec3::from(h.qoffset);
        info.notes.push(format!(
            "world coordinates (RAS+) from the qform quaternion (qform_code {} = {}; sform_code 0)",
            h.qform_code,
            xform_name(h.qform_code)
        ));
        return Ok((steps, origin));
    }
    info.notes.push(
        "no sform or qform (both codes 0): voxel sizes from pixdim, origin at 0 (NIfTI method 1)"
            .to_string(),
    );
    Ok((
        [
            DVec3::X * zooms[0],
            DVec3::Y * zooms[1],
            DVec3::Z * zooms[2],
        ],
        DVec3::ZERO,
    ))
}

/// An Analyze 7.5 grid, which carries voxel sizes but no orientation:
/// nibabel's affine for it (`AnalyzeHeader.get_base_affine`, i.e.
/// `shape_zoom_affine` with `x_flip`; SPM's `get_origin_affine`):
///
/// ```text
/// steps  = diag(-pixdim[1], pixdim[2], pixdim[3])       (x flipped: radiological)
/// origin = -steps · c,  c = originator - 1  if SPM's originator is set and
///                          within (-dim, 2·dim) on every axis,
///                       c = (dim - 1) / 2   else (the centre voxel)
/// ```
fn analyze_geometry(
    path: &Path,
    h: &Header,
    originator: [i64; 3],
    info: &mut FileInfo,
) -> Result<([DVec3; 3], DVec3), IoError> {
    for a in 1..=3 {
        let p = h.pixdim[a];
        if !(p.is_finite() && p != 0.0) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"pixdim[{a}]\" is {p}: voxel sizes must be finite and non-zero"
                ),
            ));
        }
    }
    let zooms = [-h.pixdim[1], h.pixdim[2], h.pixdim[3]];
    let dims = [1, 2, 3].map(|a| {
        if a as i64 <= h.dim[0] {
            h.dim[a] as f64
        } else {
            1.0
        }
    });
    let spm = originator.iter().any(|&o| o != 0)
        && (0..3)
            .all(|a| (originator[a] as f64) > -dims[a] && (originator[a] as f64) < 2.0 * dims[a]);
    let centre = if spm {
        originator.map(|o| o as f64 - 1.0)
    } else {
        dims.map(|n| (n - 1.0) / 2.0)
    };
    info.notes.push(format!(
        "Analyze 7.5 carries no orientation: taken as nibabel does, x flipped (radiological), {}",
        if spm {
            format!(
                "origin at voxel ({}, {}, {}) from SPM's originator {} {} {} (counted from 1)",
                centre[0], centre[1], centre[2], originator[0], originator[1], originator[2]
            )
        } else {
            format!(
                "origin at the centre voxel ({}, {}, {})",
                centre[0], centre[1], centre[2]
            )
        }
    ));
    let steps = [
        DVec3::X * zooms[0],
        DVec3::Y * zooms[1],
        DVec3::Z * zooms[2],
    ];
    let origin = -DVec3::new(
        zooms[0] * centre[0],
        zooms[1] * centre[1],
        zooms[2] * centre[2],
    );
    Ok((steps, origin))
}

/// `|pixdim[1..=3]|`, which must be finite and non-zero.
fn pixdims(path: &Path, h: &Header) -> Result<[f64; 3], IoError> {
    let mut zooms = [0.0; 3];
    for (a, zoom) in zooms.iter_mut().enumerate() {
        let p = h.pixdim[a + 1];
        if !(p.is_finite() && p != 0.0) {
            return Err(IoError::invalid(
                path,
                format!(
                    "NIfTI field \"pixdim[{}]\" is {p}: voxel sizes must be finite and non-zero",
                    a + 1
                ),
            ));
        }
        *zoom = p.abs();
    }
    Ok(zooms)
}

/// The rotation of the unit quaternion (a, b, c, d), a = √(1 − b² − c² − d²)
/// (nifti1.h, "METHOD 2"; as nifti1_io, a vector part longer than 1 is
/// normalised and a taken as 0: a 180° rotation).
fn quaternion_rotation(b: f64, c: f64, d: f64) -> DMat3 {
    let norm2 = b * b + c * c + d * d;
    let (a, b, c, d) = if 1.0 - norm2 < 1e-7 {
        let n = norm2.sqrt();
        (0.0, b / n, c / n, d / n)
    } else {
        ((1.0 - norm2).sqrt(), b, c, d)
    };
    DMat3::from_cols(
        DVec3::new(
            a * a + b * b - c * c - d * d,
            2.0 * (b * c + a * d),
            2.0 * (b * d - a * c),
        ),
        DVec3::new(
            2.0 * (b * c - a * d),
            a * a + c * c - b * b - d * d,
            2.0 * (c * d + a * b),
        ),
        DVec3::new(
            2.0 * (b * d + a * c),
            2.0 * (c * d - a * b),
            a * a + d * d - c * c - b * b,
        ),
    )
}

/// The name of an sform/qform code (nifti1.h `NIFTI_XFORM_*`).
fn xform_name(code: i64) -> &'static str {
    match code {
        1 => "scanner",
        2 => "aligned",
        3 => "talairach",
        4 => "mni_152",
        5 => "template",
        _ => "unknown code",
    }
}

/// The length unit of `xyzt_units` (its low 3 bits, nifti1.h `XYZT_TO_SPACE`).
pub(super) fn length_unit(xyzt_units: i64) -> Option<&'static str> {
    match xyzt_units & 0x07 {
        1 => Some("m"),
        2 => Some("mm"),
        3 => Some("um"),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternions_give_the_rotations_of_nifti1_h() {
        // Identity.
        let r = quaternion_rotation(0.0, 0.0, 0.0);
        assert!((r - DMat3::IDENTITY).abs_diff_eq(DMat3::ZERO, 1e-12));
        // 90 degrees about z: b = c = 0, d = sin 45°: x -> y, y -> -x.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let r = quaternion_rotation(0.0, 0.0, s);
        assert!((r * DVec3::X - DVec3::Y).length() < 1e-12);
        assert!((r * DVec3::Y + DVec3::X).length() < 1e-12);
        // 180 degrees about x (a = 0): y -> -y, z -> -z.
        let r = quaternion_rotation(1.0, 0.0, 0.0);
        assert!((r * DVec3::Y + DVec3::Y).length() < 1e-12);
        assert!((r * DVec3::Z + DVec3::Z).length() < 1e-12);
        // Any quaternion gives a proper rotation.
        let r = quaternion_rotation(0.3, -0.2, 0.5);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
        assert!((r * r.transpose()).abs_diff_eq(DMat3::IDENTITY, 1e-12));
    }

    #[test]
    fn units() {
        assert_eq!(length_unit(2 | 8), Some("mm"));
        assert_eq!(length_unit(3), Some("um"));
        assert_eq!(length_unit(1), Some("m"));
        assert_eq!(length_unit(0), None);
    }
}
