//! Every fixture volray reads renders a picture with no options (issue
//! 43 item 8: "no file volray reads renders blank by default"): each file
//! and directory fixture under `crates/io/tests/fixtures/` and
//! `fuzz/seeds/` is rendered by `volray render FIXTURE --size 24`, and the
//! picture must have a pixel that differs from the background. The
//! fixtures refused on purpose are listed below ([`REFUSED`]) with the
//! reason, and must be refused with a one-line error and exit 1 or 2,
//! never a panic; a listed fixture that renders fails the test too, so
//! that the list stays true.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::Picture;

/// The fixtures refused on purpose: a path relative to the repository,
/// a folder (ending in `/`: everything under it), or `*` and a file
/// name's ending; and why.
const REFUSED: &[(&str, &str)] = &[
    (
        "crates/io/tests/fixtures/dicom/*/",
        "a slice of a DICOM series: the series is its directory",
    ),
    (
        "crates/io/tests/fixtures/dicom/single.dcm",
        "a single DICOM slice",
    ),
    (
        "crates/io/tests/fixtures/dicom/gap/",
        "a series with uneven slice gaps, refused",
    ),
    (
        "crates/io/tests/fixtures/dicom/j2k/",
        "JPEG 2000 frames the decoder refuses, said",
    ),
    (
        "crates/io/tests/fixtures/fuzz/",
        "hostile files: fuzz regressions",
    ),
    ("crates/io/tests/fixtures/flat/", "2-D images, not volumes"),
    (
        "crates/io/tests/fixtures/tiff/single_page.tif",
        "a 2-D image, not a volume",
    ),
    (
        "crates/io/tests/fixtures/tiff/mixed_sizes.tif",
        "pages of different sizes, refused",
    ),
    (
        "crates/io/tests/fixtures/tiff/rgb_u8.tif",
        "RGB pages: greyscale stacks only",
    ),
    (
        "crates/io/tests/fixtures/not_read/",
        "formats volray names and does not read",
    ),
    (
        "crates/io/tests/fixtures/hdf5/axes.h5",
        "several datasets: needs FILE:/path",
    ),
    (
        "crates/io/tests/fixtures/hdf5/latest.h5",
        "several datasets: needs FILE:/path",
    ),
    (
        "crates/io/tests/fixtures/hdf5/many.h5",
        "several datasets: needs FILE:/path",
    ),
    (
        "crates/io/tests/fixtures/netcdf/classic.nc",
        "several variables: needs --array",
    ),
    (
        "crates/io/tests/fixtures/netcdf/data64.nc",
        "several variables: needs --array",
    ),
    (
        "crates/io/tests/fixtures/netcdf/offset64.nc",
        "several variables: needs --array",
    ),
    (
        "crates/io/tests/fixtures/netcdf4/cf_packed.nc",
        "several variables: needs --array",
    ),
    (
        "crates/io/tests/fixtures/netcdf/uneven.nc",
        "an unevenly spaced coordinate, refused",
    ),
    (
        "crates/io/tests/fixtures/nifti/complex64.nii",
        "complex values: scalar volumes only",
    ),
    ("fuzz/seeds/raw/", "raw seeds without a header: need --dims"),
    (
        "fuzz/seeds/zarr/",
        "the Zarr fuzz target's seeds: a store serialised into one file, not a store",
    ),
    (
        "*.img",
        "the data of a header (Analyze .hdr, NIfTI pair): the header is the volume",
    ),
    ("*.raw", "the data of a header (NRRD, MetaImage)"),
    ("*.zraw", "the data of a header (MetaImage)"),
    ("*.dat", "the data of a header (NRRD)"),
    ("*.raw.gz", "the data of a header (NRRD)"),
    ("*.raw.bz2", "the data of a header (NRRD)"),
];

/// The entry of [`REFUSED`] that says why `path` (relative to the
/// repository) is refused on purpose, if one does.
fn refused(path: &str, is_dir: bool) -> Option<&'static (&'static str, &'static str)> {
    let shown = if is_dir {
        format!("{path}/")
    } else {
        path.to_string()
    };
    REFUSED.iter().find(|&&(pattern, _)| {
        if let Some(end) = pattern.strip_prefix('*') {
            !is_dir && path.ends_with(end)
        } else if let Some((folder, rest)) = pattern.split_once("/*/") {
            // Any file in a subfolder of `folder` (not the subfolders),
            // but a DICOMDIR, which names its series.
            rest.is_empty()
                && !is_dir
                && !path.ends_with("/DICOMDIR")
                && path
                    .strip_prefix(folder)
                    .and_then(|p| p.strip_prefix('/'))
                    .is_some_and(|p| p.contains('/'))
        } else if pattern.ends_with('/') {
            shown.starts_with(pattern)
        } else {
            path == pattern
        }
    })
}

/// The fixtures: every file but the notes and scripts beside them, and
/// every directory that holds a DICOM file or is a chunked store.
fn fixtures(root: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if p.is_dir() {
            if is_volume_dir(&p) {
                out.push(p.clone());
            }
            fixtures(&p, out);
        } else if !(name.starts_with("README")
            || [".md", ".txt", ".py"].iter().any(|e| name.ends_with(e)))
        {
            out.push(p);
        }
    }
}

/// A directory volray reads as one input: it holds a DICOM file (the
/// `DICM` prefix at byte 128), or a store's metadata.
fn is_volume_dir(dir: &Path) -> bool {
    std::fs::read_dir(dir).unwrap().any(|e| {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        let store = [".zarray", ".zgroup", "zarr.json", "attributes.json"];
        p.is_file()
            && (store.contains(&name.as_str())
                || std::fs::read(&p).is_ok_and(|b| b.get(128..132) == Some(b"DICM")))
    })
}

/// What went wrong with one fixture, if anything.
fn check(path: &Path, dir: &Path) -> Option<String> {
    let shown = path.to_string_lossy().to_string();
    let out_png = dir.join("out.png");
    let out = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(["render", &shown, "--size", "24", "-o"])
        .arg(&out_png)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    if stderr.contains("panicked") {
        return Some(format!("{shown}: panicked: {stderr}"));
    }
    match (refused(&shown, path.is_dir()), out.status.code()) {
        (Some((_, why)), Some(0)) => Some(format!(
            "{shown}: listed as refused ({why}) but renders: take it off the list"
        )),
        (Some(_), Some(1 | 2)) => {
            let errors: Vec<&str> = (stderr.lines())
                .filter(|l| l.starts_with("volray: error:"))
                .collect();
            (errors.len() != 1 || !errors[0].contains(&shown))
                .then(|| format!("{shown}: not one line naming the file: {stderr}"))
        }
        (_, Some(0)) => {
            let picture = Picture::read(&out_png);
            let background = picture.rgb[0];
            (!picture.rgb.iter().any(|p| *p != background))
                .then(|| format!("{shown}: renders blank with no options"))
        }
        (_, code) => Some(format!("{shown}: exit {code:?}: {stderr}")),
    }
}

#[test]
fn every_fixture_renders_non_blank_with_no_options_or_is_refused_on_purpose() {
    let mut all = Vec::new();
    for root in ["crates/io/tests/fixtures", "fuzz/seeds"] {
        fixtures(Path::new(root), &mut all);
    }
    assert!(all.len() > 400, "{} fixtures found", all.len());
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let chunks: Vec<Vec<PathBuf>> = all
        .chunks(all.len().div_ceil(threads))
        .map(<[PathBuf]>::to_vec)
        .collect();
    let failures: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = chunks
            .iter()
            .map(|chunk| {
                s.spawn(move || {
                    let dir = tempfile::tempdir().unwrap();
                    chunk
                        .iter()
                        .filter_map(|p| check(p, dir.path()))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The list holds what is refused, no more: every entry is used.
    for (pattern, _) in REFUSED {
        let used = (all.iter())
            .any(|p| refused(&p.to_string_lossy(), p.is_dir()).is_some_and(|(q, _)| q == pattern));
        assert!(used, "{pattern} matches no fixture");
    }
}

#[test]
fn the_refused_list_reads_as_written() {
    let slice = "crates/io/tests/fixtures/dicom/ct/IM1007";
    assert!(refused(slice, false).unwrap().1.starts_with("a slice"));
    // The series directory itself is read.
    assert_eq!(refused("crates/io/tests/fixtures/dicom/ct", true), None);
    assert_eq!(
        refused("crates/io/tests/fixtures/dicom/enhanced_ct.dcm", false),
        None
    );
    assert!(refused("crates/io/tests/fixtures/dicom/gap", true).is_some());
    assert!(refused("crates/io/tests/fixtures/analyze/u8.img", false).is_some());
    assert_eq!(
        refused("crates/io/tests/fixtures/netcdf/packed.nc", false),
        None
    );
}
