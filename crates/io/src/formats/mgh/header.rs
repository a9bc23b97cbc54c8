//! The 284-byte FreeSurfer MGH header and the voxel-to-RAS affine it
//! gives, as nibabel reads them (`nibabel/freesurfer/mghformat.py`, the
//! reference; FreeSurfer's wiki page "MghFormat" describes the layout).
//!
//! All fields are big-endian. `Mdc` holds the direction cosines of the
//! voxel axes as rows (the transpose of FreeSurfer's matrix), `delta` the
//! voxel sizes in mm and `Pxyz_c` the RAS position of the volume's centre
//! voxel, `dims / 2` in voxel coordinates.

use std::path::Path;

use volray_core::glam::DVec3;

use crate::dtype::DType;
use crate::error::IoError;

/// Bytes before the samples (nibabel's `DATA_OFFSET`): the 90 bytes of
/// fields, then zero padding.
pub(super) const HEADER_LEN: usize = 284;

/// The header fields, decoded.
#[derive(Debug, Clone)]
pub(super) struct Header {
    pub(super) version: i32,
    /// width, height, depth, nframes.
    pub(super) dims: [i32; 4],
    pub(super) type_code: i32,
    pub(super) dof: i32,
    pub(super) good_ras: i16,
    pub(super) delta: [f64; 3],
    /// Row `c` is the direction of voxel axis `c`.
    pub(super) mdc: [[f64; 3]; 3],
    pub(super) pxyz_c: [f64; 3],
}

/// Decodes the first [`HEADER_LEN`] bytes of an MGH file.
pub(super) fn parse(bytes: &[u8; HEADER_LEN]) -> Header {
    let i32_at =
        |at: usize| i32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let f32_at = |at: usize| {
        f64::from(f32::from_be_bytes([
            bytes[at],
            bytes[at + 1],
            bytes[at + 2],
            bytes[at + 3],
        ]))
    };
    let floats3 = |at: usize| [0, 1, 2].map(|n| f32_at(at + 4 * n));
    Header {
        version: i32_at(0),
        dims: [0, 1, 2, 3].map(|n| i32_at(4 + 4 * n)),
        type_code: i32_at(20),
        dof: i32_at(24),
        good_ras: i16::from_be_bytes([bytes[28], bytes[29]]),
        delta: floats3(30),
        mdc: [0, 1, 2].map(|r| floats3(42 + 12 * r)),
        pxyz_c: floats3(78),
    }
}

/// Whether `head` (a file's first bytes, inflated if it was gzip) starts
/// like an MGH header: version 1, four positive dimensions and a known
/// type code, all big-endian.
pub(crate) fn sniff(head: &[u8]) -> bool {
    let Some(bytes) = head.get(..24) else {
        return false;
    };
    let int =
        |at: usize| i32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    int(0) == 1 && (1..5).all(|n| int(4 * n) >= 1) && sample_type(int(20)).is_ok()
}

/// The sample type of MGH type code `code` (nibabel's `_dtdefs`, after
/// FreeSurfer's `load_mgh.m`), or why it is refused.
pub(super) fn sample_type(code: i32) -> Result<(DType, &'static str), String> {
    Ok(match code {
        0 => (DType::U8, "uint8 (MRI_UCHAR)"),
        1 => (DType::I32, "int32 (MRI_INT)"),
        3 => (DType::F32, "float32 (MRI_FLOAT)"),
        4 => (DType::I16, "int16 (MRI_SHORT)"),
        10 => (DType::U16, "uint16 (MRI_USHRT)"),
        2 => return Err("MGH field \"type\" is 2 (MRI_LONG): not read by nibabel or FreeSurfer's load_mgh.m, nor by volray".into()),
        _ => return Err(format!(
            "MGH field \"type\" is {code}: expected 0 (uchar), 1 (int), 3 (float), 4 (short) or 10 (ushort)"
        )),
    })
}

impl Header {
    /// The header as written, for `volray info`.
    pub(super) fn fields(&self) -> Vec<(String, String)> {
        let join = |v: &[f64]| {
            v.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        vec![
            ("version".into(), self.version.to_string()),
            ("dims".into(), self.dims.map(|d| d.to_string()).join(" ")),
            ("type".into(), self.type_code.to_string()),
            ("dof".into(), self.dof.to_string()),
            ("goodRASFlag".into(), self.good_ras.to_string()),
            ("delta".into(), join(&self.delta)),
            ("Mdc".into(), join(&self.mdc.concat())),
            ("Pxyz_c".into(), join(&self.pxyz_c)),
        ]
    }

    /// The world step per voxel axis and the world (RAS, mm) position of
    /// voxel (0, 0, 0), as nibabel's `MGHHeader.get_affine`:
    ///
    /// ```text
    /// MdcD = Mdc.T * delta                 (column c = Mdc[c] · delta[c])
    /// origin = Pxyz_c - MdcD · dims[:3] / 2
    /// ```
    ///
    /// With `goodRASFlag` 0 nibabel replaces delta, Mdc and Pxyz_c by its
    /// defaults (1 mm, coronal LIA-like `[[-1,0,0],[0,0,1],[0,-1,0]]`, 0);
    /// so does volray, and says so in the returned note.
    pub(super) fn affine(
        &self,
        path: &Path,
    ) -> Result<([DVec3; 3], DVec3, Option<String>), IoError> {
        let (delta, mdc, centre, note) = if self.good_ras == 0 {
            (
                [1.0; 3],
                [[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
                [0.0; 3],
                Some(
                    "goodRASFlag is 0: delta, Mdc and Pxyz_c replaced by nibabel's defaults (1 mm voxels, Mdc [[-1,0,0],[0,0,1],[0,-1,0]], centre at 0)".to_string(),
                ),
            )
        } else {
            (self.delta, self.mdc, self.pxyz_c, None)
        };
        for (name, values) in [
            ("delta", &delta[..]),
            ("Pxyz_c", &centre[..]),
            ("Mdc", &mdc.concat()[..]),
        ] {
            if values.iter().any(|v| !v.is_finite()) {
                return Err(IoError::invalid(
                    path,
                    format!("MGH field \"{name}\" holds a value that is not finite"),
                ));
            }
        }
        if let Some(d) = delta.iter().find(|&&d| d <= 0.0) {
            return Err(IoError::invalid(
                path,
                format!("MGH field \"delta\" holds {d}: voxel sizes must be positive"),
            ));
        }
        let steps = [0, 1, 2].map(|c| DVec3::from(mdc[c]) * delta[c]);
        let half = [0, 1, 2].map(|c| f64::from(self.dims[c]) / 2.0);
        let origin =
            DVec3::from(centre) - steps[0] * half[0] - steps[1] * half[1] - steps[2] * half[2];
        Ok((steps, origin, note))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(dims: [i32; 4], code: i32) -> [u8; HEADER_LEN] {
        let mut b = [0u8; HEADER_LEN];
        b[..4].copy_from_slice(&1i32.to_be_bytes());
        for (n, d) in dims.iter().enumerate() {
            b[4 + 4 * n..8 + 4 * n].copy_from_slice(&d.to_be_bytes());
        }
        b[20..24].copy_from_slice(&code.to_be_bytes());
        b
    }

    #[test]
    fn sniffing_wants_version_1_positive_dims_and_a_known_type() {
        assert!(sniff(&header([4, 3, 2, 1], 3)));
        assert!(!sniff(&header([4, 3, 0, 1], 3)));
        assert!(!sniff(&header([4, 3, 2, 1], 7)));
        assert!(!sniff(&header([4, 3, 2, 1], 3)[..20]));
        let mut le = header([4, 3, 2, 1], 3);
        le[..4].copy_from_slice(&1i32.to_le_bytes());
        assert!(!sniff(&le));
    }

    #[test]
    fn affine_centres_pxyz_c_at_half_the_dims() {
        let mut b = header([4, 2, 6, 1], 0);
        b[28..30].copy_from_slice(&1i16.to_be_bytes());
        let floats = [
            2.0f32, 1.0, 0.5, 0., 0., -1., 1., 0., 0., 0., 1., 0., 10., 20., 30.,
        ];
        for (n, f) in floats.iter().enumerate() {
            b[30 + 4 * n..34 + 4 * n].copy_from_slice(&f.to_be_bytes());
        }
        let (steps, origin, note) = parse(&b).affine(Path::new("a.mgh")).unwrap();
        assert_eq!(
            steps,
            [
                DVec3::new(0., 0., -2.),
                DVec3::new(1., 0., 0.),
                DVec3::new(0., 0.5, 0.)
            ]
        );
        // Pxyz_c - (0,0,-2)*2 - (1,0,0)*1 - (0,0.5,0)*3
        assert_eq!(origin, DVec3::new(9.0, 18.5, 34.0));
        assert!(note.is_none());
    }
}
