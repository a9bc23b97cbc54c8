//! Readers keep 8- and 16-bit integer samples in their own type (a 1024³
//! 16-bit CT is 2 GiB in memory, not the 4 GiB of `f32`), rescaled values
//! in an integer type when they stay integers that one holds (a CT's
//! slope 1 and intercept −1024), and everything else as `f32`. The values
//! themselves are checked against independent writers in each format's
//! own tests; here, the type each fixture is kept in.

mod common;

use std::path::PathBuf;

use common::fixture;
use volray_core::SampleType::{self, F32, I8, I16, U8, U16};
use volray_io::{ReadOptions, read};

fn kept(path: PathBuf) -> SampleType {
    read(&path, &ReadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .volume
        .sample_type()
}

fn h5(dataset: &str) -> PathBuf {
    let file = fixture("hdf5", "many.h5");
    PathBuf::from(format!("{}:/{dataset}", file.display()))
}

#[test]
fn integer_samples_of_8_and_16_bits_are_kept_as_they_are() {
    let cases = [
        (fixture("", "u1.npy"), U8),
        (fixture("", "i2.npy"), I16),
        (fixture("", "le_u2.npy"), U16),
        (fixture("", "bool.npy"), U8),
        (fixture("nrrd", "u8_gzip.nrrd"), U8),
        (fixture("metaimage", "u8.mhd"), U8),
        (fixture("metaimage", "i8.mha"), I8),
        (fixture("metaimage", "i16_zlib.mha"), I16),
        (fixture("metaimage", "be_i16.mhd"), I16),
        (fixture("metaimage", "u16_zlib.mhd"), U16),
        (fixture("nifti", "i16.nii"), I16),
        (fixture("nifti", "i16_be.nii"), I16),
        (fixture("nifti", "i8.nii"), I8),
        (fixture("nifti", "u16.nii"), U16),
        (fixture("mrc", "mode0_i8.mrc"), I8),
        (fixture("mrc", "mode1_i16_be.mrc"), I16),
        (fixture("mrc", "mode6_u16_ext.mrc"), U16),
        (fixture("tiff", "pillow_lzw_u16.tif"), U16),
        (h5("u8"), U8),
        (h5("i16_be"), I16),
        (h5("gzip_u16"), U16),
    ];
    for (path, want) in cases {
        let name = path.display().to_string();
        assert_eq!(kept(path), want, "{name}");
    }
}

#[test]
fn wider_and_float_samples_are_kept_as_f32() {
    let cases = [
        fixture("", "fortran_f4.npy"),
        fixture("", "be_i8.npy"),
        fixture("", "le_f2.npy"),
        fixture("metaimage", "i32.mha"),
        fixture("metaimage", "u64.mha"),
        fixture("metaimage", "f64_permuted.mha"),
        // Numbers written as text are f32 whatever the header's type.
        fixture("metaimage", "text.mha"),
        fixture("nifti", "u32.nii"),
        fixture("nifti", "f64.nii"),
        fixture("mrc", "mode12_f16.mrc"),
        h5("u32"),
        h5("f64"),
        // MINC2's per-slice image-min/image-max scaling.
        fixture("minc", "ramp_i16.mnc"),
    ];
    for path in cases {
        let name = path.display().to_string();
        assert_eq!(kept(path), F32, "{name}");
    }
}

/// Rescaled values stay integers only where slope and intercept are
/// integers and the range fits: NIfTI's scl_slope 0.5 and a DICOM series
/// at slope 2 of 16 signed bits (beyond i16) are f32; 12 bits stored at
/// slope 1 are u16.
#[test]
fn rescaled_values_are_f32_unless_they_stay_small_integers() {
    assert_eq!(kept(fixture("nifti", "scaled_i16.nii")), F32);
    assert_eq!(kept(fixture("dicom", "ct")), F32);
    assert_eq!(kept(fixture("dicom", "sagittal")), U16);
}
