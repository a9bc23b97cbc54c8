//! The volume file formats volray reads: one module per format.
//!
//! Each module turns a file of its format into a [`Volume`](volray_core::Volume)
//! and a [`FileInfo`](crate::FileInfo); formats volray also writes (raw,
//! `.npy`, NRRD) keep their writer beside their reader. What the readers
//! share lives in [`crate::shared`].

pub(crate) mod chgcar;
pub(crate) mod cube;
pub(crate) mod dicom;
#[cfg(feature = "hdf5")]
pub(crate) mod hdf5;
pub(crate) mod metaimage;
pub(crate) mod mrc;
pub(crate) mod nifti;
pub(crate) mod npy;
pub(crate) mod nrrd;
pub(crate) mod raw;
pub(crate) mod tiff;
pub(crate) mod vti;
pub(crate) mod vtk_legacy;
