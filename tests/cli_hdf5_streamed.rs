//! `volray render` of a chunked HDF5 dataset and a NetCDF-4 variable that
//! `--max-memory` will not let it read whole: rendered piece by piece,
//! each piece read from the chunks it touches (`volray_io::open_lazy`),
//! the same picture as the dataset read whole, within 1/255. The files
//! are written here by h5py and netCDF4 in `target/pyenv` (which `.ci/run`
//! installs); without them these tests fail under `CI=true` and are
//! skipped elsewhere.

mod common;

use std::process::Command;

use common::{Picture, pyenv_with, render};

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
with netCDF4.Dataset(sys.argv[1] + "/vol.nc", "w", format="NETCDF4") as nc:
    for name, n in zip("xyz", v.shape):
        nc.createDimension(name, n)
    r = nc.createVariable("rho", "f4", ("x", "y", "z"), zlib=True, chunksizes=(16, 16, 16))
    r[:] = v.astype("f4")
"#;

/// The directory holding the files, or `None` where the writers are
/// missing outside CI.
fn files() -> Option<tempfile::TempDir> {
    let python = pyenv_with(&["h5py", "netCDF4", "numpy"])?;
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(&python)
        .args(["-c", WRITE, dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(dir)
}

const LOOK: [&str; 6] = ["--preset", "mr", "--range", "0,32000", "--size", "40x36"];

#[test]
fn a_chunked_hdf5_dataset_over_max_memory_renders_piece_by_piece_as_it_would_whole() {
    let Some(dir) = files() else { return };
    for spec in ["vol.h5:/data", "vol.nc:/rho"] {
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
