//! Formats volray recognises but does not read are refused by name, with a
//! hint naming a tool that converts them, recognised by their content
//! whatever the file is called; and a directory of Zarr or N5 metadata is
//! never taken for a DICOM series. The fixtures are the first bytes of
//! files written by the formats' own tools (nibabel's test data from the
//! Philips export tool, an ECAT scanner and AFNI; an N5 array by zarr 2's
//! N5Store), see `fixtures/make_not_read_fixtures.py`.

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use volray_io::{IoError, ReadOptions, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("not_read", name)
}

/// The refusal of `path`: a one-line, bad-input [`IoError::NotRead`]
/// naming `format`, whose message says "`format` is not read by volray"
/// and names the converter `tool`.
fn assert_not_read(path: &Path, format: &str, tool: &str) {
    let err = read(path, &ReadOptions::default()).expect_err("read, but should be refused");
    let msg = err.to_string();
    assert!(
        matches!(&err, IoError::NotRead { format: f, .. } if *f == format),
        "{msg}"
    );
    assert!(!err.is_io_failure(), "{msg}");
    assert_eq!(err.path(), path);
    assert!(!msg.contains('\n'), "{msg}");
    assert!(
        msg.starts_with(&format!(
            "{}: {format} is not read by volray; ",
            path.display()
        )),
        "{msg}"
    );
    assert!(msg.contains(tool), "{msg} (wanted {tool})");
    assert!(!msg.contains("DICOM"), "{msg}");
}

#[test]
fn par_rec_ecat_afni_and_openvdb_are_named_with_a_converter() {
    assert_not_read(&fixture("T1.PAR"), "Philips PAR/REC", "parrec2nii");
    assert_not_read(&fixture("T1.REC"), "Philips PAR/REC", "parrec2nii");
    assert_not_read(&fixture("tinypet.v"), "ECAT 7", "nibabel");
    assert_not_read(
        &fixture("scaled+tlrc.HEAD"),
        "AFNI BRIK/HEAD",
        "3dAFNItoNIFTI",
    );
    assert_not_read(
        &fixture("scaled+tlrc.BRIK"),
        "AFNI BRIK/HEAD",
        "3dAFNItoNIFTI",
    );
    assert_not_read(&fixture("grid.vdb"), "OpenVDB", "copyToArray");
}

#[test]
fn recognised_by_content_whatever_the_name() {
    let dir = tempfile::tempdir().unwrap();
    for (from, to, format) in [
        ("T1.PAR", "header.txt", "Philips PAR/REC"),
        ("tinypet.v", "pet_scan", "ECAT 7"),
        ("scaled+tlrc.HEAD", "anat.dat", "AFNI BRIK/HEAD"),
        ("grid.vdb", "smoke.bin", "OpenVDB"),
    ] {
        let p = dir.path().join(to);
        fs::copy(fixture(from), &p).unwrap();
        assert_not_read(&p, format, "");
    }
    // A .REC or .BRIK without its header is not named: nothing shows
    // what it is.
    let lone = dir.path().join("lone.REC");
    fs::write(&lone, [0u8; 64]).unwrap();
    let err = read(&lone, &ReadOptions::default()).unwrap_err();
    assert!(matches!(err, IoError::UnknownFormat { .. }), "{err}");
}

#[test]
fn an_n5_store_is_named_never_dicom() {
    assert_not_read(&fixture("n5"), "N5", "Zarr");
    // An N5 array's attributes without the container's version.
    let dir = tempfile::tempdir().unwrap();
    let arr = dir.path().join("raw");
    fs::create_dir(&arr).unwrap();
    fs::write(
        arr.join("attributes.json"),
        r#"{"dimensions":[4,3,5],"blockSize":[4,3,5],"dataType":"uint16","compression":{"type":"raw"}}"#,
    )
    .unwrap();
    assert_not_read(&arr, "N5", "Zarr");
}

/// The message reading the directory `dir` gives: bad input, one line,
/// not about DICOM.
fn dir_refusal(dir: &Path) -> String {
    let err = read(dir, &ReadOptions::default()).expect_err("read, but should be refused");
    let msg = err.to_string();
    assert!(!err.is_io_failure(), "{msg}");
    assert!(!msg.contains('\n'), "{msg}");
    assert!(!msg.contains("DICOM image"), "{msg}");
    msg
}

#[test]
fn directories_near_zarr_or_n5_stores_are_not_dicom_series() {
    // A directory of chunks inside the N5 store.
    let msg = dir_refusal(&fixture("n5").join("0"));
    assert!(msg.contains("lies inside the store"), "{msg}");
    assert!(msg.contains("n5"), "{msg}");

    // A directory holding a Zarr store and an N5 store.
    let dir = tempfile::tempdir().unwrap();
    let zarr = dir.path().join("a.zarr");
    fs::create_dir(&zarr).unwrap();
    fs::write(zarr.join(".zgroup"), r#"{"zarr_format": 2}"#).unwrap();
    let n5 = dir.path().join("b");
    fs::create_dir(&n5).unwrap();
    fs::copy(fixture("n5/attributes.json"), n5.join("attributes.json")).unwrap();
    let msg = dir_refusal(dir.path());
    assert!(
        msg.contains("holds Zarr or N5 stores, not a DICOM series: pass one of them (a.zarr, b)"),
        "{msg}"
    );
    // Inside the Zarr store.
    let chunks = zarr.join("0");
    fs::create_dir(&chunks).unwrap();
    let msg = dir_refusal(&chunks);
    assert!(msg.contains("lies inside the store"), "{msg}");

    // A directory with neither is still read as a DICOM series.
    let plain = tempfile::tempdir().unwrap();
    fs::write(plain.path().join("notes.txt"), "x").unwrap();
    let msg = read(plain.path(), &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(msg.contains("no DICOM image files"), "{msg}");
}
