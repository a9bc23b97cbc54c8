//! `volray render` of a chunked HDF5 dataset and a NetCDF-4 variable that
//! `--max-memory` will not let it read whole: rendered piece by piece,
//! each piece read from the chunks it touches (`volray_io::open_lazy`),
//! the same picture as the dataset read whole, within 1/255. Also one
//! frame of an LZF-compressed (t, z, y, x) series, and a NetCDF-4 variable
//! along a decreasing latitude (ERA5's order), each flipped box by box; and
//! the dataset as HDF5 2.0 writes it (`libver='latest'`, a version 2 B-tree
//! chunk index), the same picture as the older file's. The files
//! are written here by h5py and netCDF4 in `target/pyenv` (which `.ci/run`
//! installs); without them these tests fail under `CI=true` and are
//! skipped elsewhere.

mod common;

use common::{Picture, render};

/// Two blobs over a ramp, u16, a[x, y, z] of (48, 40, 36) in 16³ chunks
/// (deflate and shuffle), as `vol.h5:/data` and as `vol.nc:/rho` (f32).
const WRITE: &str = r#"
import sys
import numpy as np
import h5py
import netCDF4
x, y, z = np.meshgrid(np.arange(48.0), np.arange(40.0), np.arange(36.0), indexing="ij")
def blob(c, r):
    return np.exp(-((x - c[0])**2 + (y - c[1])**2 + (z - c[2])**2) / (2 * r * r))
v = (30000 * blob((16, 14, 12), 6) + 20000 * blob((32, 26, 24), 5) + 40 * z).astype("<u2")
with h5py.File(sys.argv[1] + "/vol.h5", "w") as f:
    f.create_dataset("data", data=v, chunks=(16, 16, 16), compression="gzip", shuffle=True)
# The same as HDF5 2.0 writes it with libver="latest" and two unlimited
# axes: layout message 5, a version 2 B-tree chunk index (hdf5-reader's).
with h5py.File(sys.argv[1] + "/latest.h5", "w", libver="latest") as f:
    f.create_dataset("data", data=v, chunks=(16, 16, 16), compression="gzip", shuffle=True,
                     maxshape=(None, None, 36))
with netCDF4.Dataset(sys.argv[1] + "/vol.nc", "w", format="NETCDF4") as nc:
    for name, n in zip("xyz", v.shape):
        nc.createDimension(name, n)
    r = nc.createVariable("rho", "f4", ("x", "y", "z"), zlib=True, chunksizes=(16, 16, 16))
    r[:] = v.astype("f4")
# Three frames (t, z, y, x) in LZF chunks of one frame each: the blobs
# moved 4 samples along x per frame.
s = np.stack([np.roll(v, 4 * t, axis=0) for t in range(3)]).astype("<f4").transpose(0, 3, 2, 1)
with h5py.File(sys.argv[1] + "/series.h5", "w") as f:
    d = f.create_dataset("s", data=s, chunks=(1, 12, 16, 16), compression="lzf")
    d.attrs["axes"] = "tzyx"
# rho(z, latitude, longitude), latitude from north to south: flipped, the
# volume is v again.
with netCDF4.Dataset(sys.argv[1] + "/latdown.nc", "w", format="NETCDF4") as nc:
    for name, n in [("z", 36), ("latitude", 40), ("longitude", 48)]:
        nc.createDimension(name, n)
    for name, values, units in [("z", np.arange(36.0), "km"),
                                ("latitude", 39.0 - np.arange(40.0), "degrees_north"),
                                ("longitude", np.arange(48.0), "degrees_east")]:
        c = nc.createVariable(name, "f8", (name,))
        c[:] = values
        c.units = units
    r = nc.createVariable("rho", "f4", ("z", "latitude", "longitude"), zlib=True,
                          chunksizes=(12, 16, 16))
    r[:] = v.astype("f4").transpose(2, 1, 0)[:, ::-1, :]
"#;

/// The directory holding the files, or `None` where the writers are
/// missing outside CI.
fn files() -> Option<tempfile::TempDir> {
    common::written_by_python(&["h5py", "netCDF4", "numpy"], &[], WRITE)
}

const LOOK: [&str; 6] = ["--preset", "mr", "--range", "0,32000", "--size", "40x36"];

#[test]
fn a_chunked_hdf5_dataset_over_max_memory_renders_piece_by_piece_as_it_would_whole() {
    let Some(dir) = files() else { return };
    for spec in ["vol.h5:/data", "vol.nc:/rho", "latdown.nc:/rho"] {
        let input = format!("{}/{spec}", dir.path().display());
        let (whole, pieces) = (dir.path().join("whole.png"), dir.path().join("pieces.png"));
        let said = render(&[&[input.as_str()], &LOOK[..]].concat(), &whole);
        assert!(!said.contains("pieces"), "{spec}: {said}");
        // 48·40·36 u16 voxels take 138 kB (f32: 276 kB): 100 kB cannot
        // hold them whole, but it holds pieces of them and their frames.
        let said = render(
            &[&[input.as_str(), "--max-memory", "100K"], &LOOK[..]].concat(),
            &pieces,
        );
        assert!(said.contains("in pieces"), "{spec}: {said}");
        let picture = Picture::read(&whole);
        assert!(picture.rgb.iter().any(|p| *p != picture.rgb[0]), "blank");
        let diff = Picture::read(&pieces).max_diff(&picture);
        assert!(diff <= 1, "{spec}: {diff}");
        // The value range found piece by piece: --tf auto.
        let args = [input.as_str(), "--size", "40x36", "--tf", "auto"];
        render(&args, &whole);
        let said = render(&[&args[..], &["--max-memory", "100K"]].concat(), &pieces);
        assert!(said.contains("in pieces"), "{spec}: {said}");
        let diff = Picture::read(&pieces).max_diff(&Picture::read(&whole));
        assert!(diff <= 1, "{spec} --tf auto: {diff}");
    }
}

#[test]
fn a_dataset_hdf5_2_writes_renders_whole_and_in_pieces_as_the_same_data_written_for_older_readers()
{
    let Some(dir) = files() else { return };
    let d = dir.path();
    let input = format!("{}/latest.h5:/data", d.display());
    let older = format!("{}/vol.h5:/data", d.display());
    let (whole, pieces, before) = (
        d.join("l_whole.png"),
        d.join("l_pieces.png"),
        d.join("old.png"),
    );
    render(&[&[older.as_str()], &LOOK[..]].concat(), &before);
    let said = render(&[&[input.as_str()], &LOOK[..]].concat(), &whole);
    assert!(!said.contains("pieces"), "{said}");
    let said = render(
        &[&[input.as_str(), "--max-memory", "100K"], &LOOK[..]].concat(),
        &pieces,
    );
    assert!(said.contains("in pieces"), "{said}");
    let picture = Picture::read(&before);
    assert!(picture.rgb.iter().any(|p| *p != picture.rgb[0]), "blank");
    assert_eq!(Picture::read(&whole).max_diff(&picture), 0);
    assert!(Picture::read(&pieces).max_diff(&picture) <= 1);
}

#[test]
fn one_frame_of_an_lzf_series_over_max_memory_renders_piece_by_piece_as_it_would_whole() {
    let Some(dir) = files() else { return };
    let input = format!("{}/series.h5:/s", dir.path().display());
    let (whole, pieces) = (dir.path().join("whole.png"), dir.path().join("pieces.png"));
    let args = [&[input.as_str(), "--frame", "2"], &LOOK[..]].concat();
    let said = render(&args, &whole);
    assert!(!said.contains("pieces"), "{said}");
    // One frame is 276 kB as f32: 100 kB renders it in pieces, each
    // decoding only the LZF chunks of frame 2 it touches.
    let said = render(&[&args[..], &["--max-memory", "100K"]].concat(), &pieces);
    assert!(said.contains("in pieces"), "{said}");
    let picture = Picture::read(&whole);
    assert!(picture.rgb.iter().any(|p| *p != picture.rgb[0]), "blank");
    let diff = Picture::read(&pieces).max_diff(&picture);
    assert!(diff <= 1, "{diff}");
    // Frame 2 is not frame 0.
    let other = dir.path().join("frame0.png");
    render(
        &[&[input.as_str(), "--frame", "0"], &LOOK[..]].concat(),
        &other,
    );
    assert!(Picture::read(&other).max_diff(&picture) > 1);
}
