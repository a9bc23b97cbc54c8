//! Files that hold one image, not a volume (`fixtures/make_flat_fixtures.py`,
//! written by pynrrd, nibabel, SimpleITK and tifffile, and the single
//! DICOM slice of `make_dicom_fixtures.py`): each is read and refused as a
//! volume with [`IoError::FlatImage`], which carries what was read.
//!
//! The images are 5 x 4 samples holding `x + 10y` (+ 0.5 in float ones);
//! the DICOM slice is 4 x 3 columns by rows.

mod common;

use volray_core::glam::DVec3;
use volray_io::{FlatImage, IoError, ReadOptions, VolumeFormat, read};

/// The image `rel` holds, checked to be refused as a volume with a reason
/// naming the file.
fn image(rel: &str) -> FlatImage {
    let path = common::fixture("", rel);
    let err = common::error_about(&path, &ReadOptions::default(), &path);
    assert!(!err.is_io_failure());
    match err {
        IoError::FlatImage { image, .. } => *image,
        other => panic!("{rel}: {other}"),
    }
}

/// Sample (x, y) of a `[nx, ny, 1]` image holds `want(x, y)` exactly.
fn assert_values(image: &FlatImage, nx: usize, ny: usize, want: impl Fn(usize, usize) -> f32) {
    assert_eq!(image.dims, [nx, ny, 1]);
    for y in 0..ny {
        for x in 0..nx {
            assert_eq!(image.values[x + nx * y], want(x, y), "({x}, {y})");
        }
    }
}

const REASON: &str = "a 2-D image (5 x 4 samples), not a volume: volray renders volumes of at least 2 points along each axis";

#[test]
fn a_2d_nrrd_image() {
    let i = image("flat/image.nrrd");
    assert_eq!(i.format, VolumeFormat::Nrrd);
    assert_values(&i, 5, 4, |x, y| (x + 10 * y) as f32 + 0.5);
    assert_eq!(i.spacing, DVec3::new(0.5, 0.25, 1.0));
    assert_eq!(i.origin, DVec3::new(1.0, 2.0, 0.0));
    assert!(
        i.info.stored_type.starts_with("float"),
        "{}",
        i.info.stored_type
    );
    assert_eq!(i.reason, REASON);
    assert_eq!(i.value_range(), (Some((0.5, 34.5, 17.5)), 0));
}

#[test]
fn a_2d_nifti_image() {
    let i = image("flat/image.nii");
    assert_eq!(i.format, VolumeFormat::Nifti);
    assert_values(&i, 5, 4, |x, y| (x + 10 * y) as f32);
    // nibabel's affine diag(0.5, 0.25, 2) from (1, 2, 3).
    assert_eq!(i.spacing, DVec3::new(0.5, 0.25, 2.0));
    assert_eq!(i.origin, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(i.reason, REASON);
}

#[test]
fn a_2d_metaimage() {
    let i = image("flat/image.mha");
    assert_eq!(i.format, VolumeFormat::MetaImage);
    assert_values(&i, 5, 4, |x, y| (x + 10 * y) as f32 + 0.5);
    assert_eq!(i.spacing, DVec3::new(0.5, 0.25, 1.0));
    assert_eq!(i.origin, DVec3::new(1.0, 2.0, 0.0));
}

#[test]
fn a_one_page_tiff() {
    let i = image("flat/page.tif");
    assert_eq!(i.format, VolumeFormat::Tiff);
    assert_values(&i, 5, 4, |x, y| (x + 10 * y) as f32);
    assert_eq!(i.reason, REASON);
}

#[test]
fn a_2d_hdf5_dataset() {
    // h5py's /meta/plane: 4 x 3 float64 zeros (make_hdf5_fixtures.py).
    let file = common::fixture("hdf5", "one.h5");
    let spec = std::path::PathBuf::from(format!("{}:/meta/plane", file.display()));
    let err = common::error_about(&spec, &ReadOptions::default(), &file);
    let IoError::FlatImage { image, .. } = err else {
        panic!("{err}")
    };
    assert_eq!(image.format, VolumeFormat::Hdf5);
    assert_values(&image, 4, 3, |_, _| 0.0);
    assert_eq!(image.info.stored_type, "float64 (little-endian)");
}

#[test]
fn a_single_dicom_slice_names_its_directory() {
    let i = image("dicom/single.dcm");
    assert_eq!(i.format, VolumeFormat::Dicom);
    // Columns x rows = 4 x 3, stored x + 10y, PixelSpacing 1, IPP 0.
    assert_values(&i, 4, 3, |x, y| (x + 10 * y) as f32);
    assert_eq!(i.spacing, DVec3::ONE);
    assert_eq!(i.origin, DVec3::ZERO);
    assert_eq!(i.info.length_unit.as_deref(), Some("mm"));
    let dir = common::fixture("dicom", "");
    let dir = dir.display().to_string();
    assert_eq!(
        i.reason,
        format!(
            "a single DICOM slice (4 x 3), not a volume: pass the directory of the series ({}) to read a volume",
            dir.trim_end_matches('/')
        )
    );
}

#[test]
fn volumes_are_still_volumes() {
    for rel in ["nifti/f32.nii", "dicom/ct"] {
        let path = common::fixture("", rel);
        let l = read(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert!(l.volume.dims().iter().all(|&n| n >= 2));
    }
}
