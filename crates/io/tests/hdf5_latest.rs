//! HDF5 files as HDF5 2.0 writes them (h5py 3.16, `libver='latest'`):
//! layout message version 5 for filtered chunks, chunk indexes by the
//! number of unlimited dimensions (a fixed array for none, an extensible
//! array for one, a version 2 B-tree for two, records of type 11 for
//! filtered and 10 for unfiltered chunks), which `hdf5-pure` 0.47 refuses
//! and volray lists through `hdf5-reader` (`shared/hdf5_index.rs`). Each
//! dataset read whole and box by box, sample for sample the array h5py
//! reads (`tests/hdf5_latest/write_files.py` saves it beside): gzip,
//! shuffle and gzip, Fletcher-32, unwritten chunks as the fill value. A
//! NetCDF-4 file as netCDF-C before `_Netcdf4Dimid` wrote it: its
//! dimensions through `DIMENSION_LIST`'s references, with the coordinates
//! netCDF4 (netCDF-C) reads. Then hostile files: a version 2 B-tree whose
//! record counts lie or whose node points at itself, a layout message of
//! an unknown index type or cut short, byte flips over every fixture:
//! one-line errors naming the file, the cause and `h5repack`, no panic.
//!
//! The writers run in `target/pyenv` (h5py, netCDF4 and numpy, which
//! `.ci/run` installs); without them these tests fail under `CI=true` and
//! are skipped elsewhere.

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use volray_core::{Volume, VolumeSource};
use volray_io::{ReadOptions, VolumeFormat, open_lazy, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["h5py", "netCDF4", "numpy"],
        "tests/hdf5_latest/write_files.py",
    )
}

fn spec(dir: &Path, file: &str, name: &str) -> PathBuf {
    PathBuf::from(format!("{}:/{name}", dir.join(file).display()))
}

/// Reads `spec` whole and checks it against `npy` sample for sample; then
/// box by box, each box against the same box of the whole. Returns the
/// notes of both reads.
fn check(spec: &Path, npy: &Path) -> Vec<String> {
    let o = ReadOptions::default();
    let eager = read(spec, &o).unwrap_or_else(|e| panic!("{}: {e}", spec.display()));
    let expected = read(npy, &o).unwrap().volume;
    assert_eq!(eager.volume.dims(), expected.dims(), "{}", spec.display());
    assert!(
        eager.volume.samples() == expected.samples(),
        "{}: the volume differs from h5py's array",
        spec.display()
    );
    let l = open_lazy(spec, &o)
        .unwrap_or_else(|e| panic!("{}: {e}", spec.display()))
        .unwrap_or_else(|| panic!("{}: not opened box by box", spec.display()));
    let dims = l.source.grid().dims;
    assert_eq!(dims, eager.volume.dims());
    assert_eq!(l.source.sample_type(), eager.volume.sample_type());
    let mut boxes = vec![
        ([0; 3], dims),
        ([0; 3], [8, 8, 8]),
        ([7, 7, 7], [17, 9, 18]),
    ];
    boxes.push((dims.map(|n| n - 3), dims));
    for corner in 0..8 {
        let lo: [usize; 3] =
            std::array::from_fn(|a| if corner >> a & 1 == 1 { dims[a] - 2 } else { 0 });
        boxes.push((lo, lo.map(|v| v + 2)));
    }
    for (lo, hi) in boxes {
        let got = l
            .source
            .read_box(lo, hi)
            .unwrap_or_else(|e| panic!("{} {lo:?}..{hi:?}: {e}", spec.display()));
        let want: Volume = VolumeSource::read_box(&eager.volume, lo, hi).unwrap();
        assert!(
            got == want,
            "{} box {lo:?}..{hi:?} differs from the whole",
            spec.display()
        );
    }
    let mut notes = eager.info.notes;
    notes.extend(l.info.notes);
    notes
}

#[test]
fn datasets_hdf5_2_writes_with_libver_latest_read_as_h5py_reads_them() {
    let Some(dir) = files() else { return };
    for (name, index) in [
        ("gzip", "a fixed array"),
        ("shuffle_gzip", "a fixed array"),
        ("fletcher", "a fixed array"),
        ("one_unlimited", "an extensible array"),
        ("two_unlimited", "a version 2 B-tree"),
        ("two_unlimited_plain", "a version 2 B-tree"),
        ("sparse", "a version 2 B-tree"),
        ("sparse_fixed", "a fixed array"),
        ("plain", ""),
    ] {
        let notes = check(
            &spec(dir, "latest.h5", name),
            &dir.join(format!("{name}.npy")),
        );
        if !index.is_empty() {
            let said = format!("its chunk index ({index}) listed through hdf5-reader");
            assert!(
                notes.iter().filter(|n| n.contains(&said)).count() == 2,
                "{name}: {notes:?}"
            );
        }
    }
}

#[test]
fn chunks_never_written_read_as_the_fill_value_box_by_box() {
    let Some(dir) = files() else { return };
    let l = open_lazy(&spec(dir, "latest.h5", "sparse"), &ReadOptions::default())
        .unwrap()
        .unwrap();
    // Only x < 16, y < 8 was written: 2 of the 5 × 4 × 3 chunks along x
    // and y, all 3 along z.
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n
                .contains("54 of its 60 chunks are not written and read as the fill value -7.5")),
        "{:?}",
        l.info.notes
    );
    let b = l.source.read_box([20, 20, 0], [22, 22, 2]).unwrap();
    assert!(b.samples().to_f32_vec().iter().all(|&v| v == -7.5));
}

#[test]
fn old_netcdf4_dimensions_come_from_the_dimension_list_references() {
    let Some(dir) = files() else { return };
    // temp(z, y, x), x and y both 6 long: x every 2.5 m from 10, y every
    // 0.5 m from -1, z every 3 m from 0 (netCDF4 reads the same).
    let path = spec(dir, "old_dims.nc", "temp");
    let l = read(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::Netcdf);
    let v = &l.volume;
    assert_eq!(v.dims(), [6, 6, 4]);
    assert_eq!(v.spacing().to_array(), [2.5, 0.5, 3.0]);
    assert_eq!(v.origin().to_array(), [10.0, -1.0, 0.0]);
    let expected = read(&dir.join("temp.npy"), &ReadOptions::default())
        .unwrap()
        .volume;
    assert!(v.samples() == expected.samples());
    common::assert_note(
        &l,
        "dimensions (z, y, x) from the DIMENSION_LIST references to its dimension scales",
    );
    // Box by box too.
    let lazy = open_lazy(&path, &ReadOptions::default()).unwrap().unwrap();
    let g = lazy.source.grid();
    assert_eq!((g.spacing, g.origin), (v.spacing(), v.origin()));
}

/// The one-line errors reading `path` gives, whole and box by box.
fn refused(path: &Path) -> [String; 2] {
    let o = ReadOptions::default();
    let whole = read(path, &o).map(|_| ()).unwrap_err().to_string();
    let boxed = match open_lazy(path, &o) {
        Err(e) => e.to_string(),
        Ok(Some(l)) => {
            l.source
                .read_box([0; 3], l.source.grid().dims)
                .map(|_| ())
                .unwrap_err()
                .message
        }
        Ok(None) => panic!("{}: not opened box by box", path.display()),
    };
    let file = path.to_string_lossy();
    let file = file.split(":/").next().unwrap();
    for err in [&whole, &boxed] {
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with(file), "{err}");
    }
    [whole, boxed]
}

#[test]
fn a_version_2_b_tree_whose_records_lie_or_loop_is_refused_in_one_line() {
    let Some(dir) = files() else { return };
    // libhdf5 2.0 itself crashes on the first (h5py: a segmentation fault).
    for file in ["btree_root_count.h5", "btree_loop.h5"] {
        for err in refused(&spec(dir, file, "v")) {
            assert!(
                err.contains("HDF5 dataset \"/v\": its layout message is of version 5 (HDF5 2.0), which hdf5-pure 0.47 cannot read, and its chunk index (a version 2 B-tree) is unreadable: ")
                    && err.ends_with(": rewrite it with a layout every reader takes, e.g. h5repack --low=0 --high=1 -l CHUNK=64x64x64 -f GZIP=4 in.h5 out.h5 (or write it with h5py's libver='earliest')"),
                "{err}"
            );
        }
    }
    // A total record count that lies is never used (nodes are walked by
    // their own counts): the file reads as h5py reads it.
    check(
        &spec(dir, "btree_total_lies.h5", "v"),
        &dir.join("btree.npy"),
    );
}

#[test]
fn a_damaged_layout_message_is_refused_in_one_line_naming_the_cause_and_h5repack() {
    let Some(dir) = files() else { return };
    for (file, cause) in [
        ("layout_index_type.h5", "unsupported chunk indexing type 9"),
        ("layout_cut.h5", "unexpected end of data"),
    ] {
        for err in refused(&spec(dir, file, "v")) {
            assert!(
                err.contains("HDF5 dataset \"/v\": its layout message is of version 5 (HDF5 2.0), which hdf5-pure 0.47 cannot read, and hdf5-reader cannot open it: ")
                    && err.contains(cause)
                    && err.contains("h5repack --low=0 --high=1"),
                "{err}"
            );
        }
    }
}

#[test]
fn damaged_copies_of_every_fixture_never_panic() {
    let Some(dir) = files() else { return };
    let scratch = tempfile::tempdir().unwrap();
    let mut rng = common::Lcg(0x5eed_4d5f);
    for (file, names) in [
        ("latest.h5", &["gzip", "two_unlimited", "one_unlimited"][..]),
        ("old_dims.nc", &["temp"][..]),
    ] {
        let bytes = std::fs::read(dir.join(file)).unwrap();
        for round in 0..40 {
            let damaged = common::mutate(&bytes, &mut rng, 1 + round % 4);
            let path = scratch.path().join(file);
            std::fs::write(&path, &damaged).unwrap();
            for name in names {
                let spec = PathBuf::from(format!("{}:/{name}", path.display()));
                // A damaged file may still read: only an error's form is checked.
                if let Err(e) = read(&spec, &ReadOptions::default()) {
                    assert_eq!(e.to_string().lines().count(), 1, "{e}");
                }
                if let Ok(Some(l)) = open_lazy(&spec, &ReadOptions::default()) {
                    let _ = l.source.read_box([0; 3], l.source.grid().dims);
                }
            }
        }
    }
}

/// A fixture's value at (x, y, z).
type Formula = dyn Fn(usize, usize, usize) -> f64;

#[test]
fn the_committed_libver_latest_fixture_holds_the_values_of_many_h5() {
    // make_hdf5_fixtures.py: latest.h5 holds many.h5's u8, u32, gzip_u16
    // and series under a version 2 B-tree (filtered and not), a fixed
    // array with layout message 5 and an extensible array; v = x + 10y +
    // 100z at a[x, y, z] of (4, 3, 5). No writer needed: this runs
    // everywhere.
    fn v(x: usize, y: usize, z: usize) -> f64 {
        (x + 10 * y + 100 * z) as f64
    }
    let cases: [(&str, Option<usize>, &Formula); 5] = [
        ("u8", None, &|x, y, z| (x + 2 * y + 6 * z) as f64),
        ("u32", None, &|x, y, z| f64::from((v(x, y, z) + 3e9) as f32)),
        ("gzip_u16", None, &v),
        ("series", Some(0), &v),
        ("series", Some(2), &|x, y, z| v(x, y, z) + 2000.0),
    ];
    for (name, frame, want) in cases {
        let path = PathBuf::from(format!(
            "{}:/{name}",
            common::fixture("hdf5", "latest.h5").display()
        ));
        let o = common::with_frame(frame);
        let whole = read(&path, &o).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(whole.volume.dims(), [4, 3, 5], "{name}");
        for z in 0..5 {
            for y in 0..3 {
                for x in 0..4 {
                    assert_eq!(
                        f64::from(whole.volume.get(x, y, z)),
                        want(x, y, z),
                        "{name} {frame:?} at ({x}, {y}, {z})"
                    );
                }
            }
        }
        let l = open_lazy(&path, &o).unwrap().unwrap();
        let b = l.source.read_box([1, 1, 2], [4, 3, 5]).unwrap();
        assert!(b == VolumeSource::read_box(&whole.volume, [1, 1, 2], [4, 3, 5]).unwrap());
    }
}
