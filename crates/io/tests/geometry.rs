//! Geometry that real files get right: vertical coordinates that point
//! down (pressure levels, ocean depth: CF `positive = "down"`) placed so
//! that up in the world is up in the atmosphere or ocean, and axes in
//! several length units brought to one, the finest (OME-Zarr 0.4 and 0.5,
//! NRRD `space units`, CF coordinate units). The files are written at
//! test time by netCDF4-python, ome-zarr-py and pynrrd
//! (`tests/geometry/write_files.py`); every voxel's value names the file
//! index it came from (`i + 10 j + 100 k`), so each test checks where
//! every stored sample lands in the world.
//!
//! The writers run in `target/pyenv` (which `.ci/run` installs); without
//! them these tests fail under `CI=true` and are skipped elsewhere.

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::{Grid, assert_note, check_world};
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, open_lazy, read};

/// The directory the writers filled, or `None` (with the reason printed)
/// where they are missing outside CI.
fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["netCDF4", "zarr", "ome_zarr", "nrrd", "numpy"],
        "tests/geometry/write_files.py",
    )
}

fn load(path: &Path) -> Loaded {
    read(path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn ramp(i: usize, j: usize, k: usize) -> f32 {
    (i + 10 * j + 100 * k) as f32
}

/// The file grid of the pressure files: lon 0, 10, … 40 (x), lat 0, 10,
/// 20, 30 (y), and z = −p of level p, from `first` hPa by `step` hPa per
/// file index.
fn pressure_grid(first: f64, step: f64) -> Grid {
    Grid {
        n: [5, 4, 5],
        steps: [DVec3::X * 10.0, DVec3::Y * 10.0, DVec3::Z * -step],
        origin: DVec3::new(0.0, 0.0, -first),
    }
}

#[test]
fn pressure_levels_stored_from_the_ground_up_put_1000_hpa_lowest() {
    let Some(dir) = files() else { return };
    for name in ["pressure.nc", "pressure3.nc"] {
        let l = load(&dir.join(name));
        // 1000, 850, … 400 hPa at z = −1000, −850, … −400.
        check_world(name, &l.volume, &pressure_grid(1000.0, -150.0), 1e-9, ramp);
        assert_eq!(l.volume.origin(), DVec3::new(0.0, 0.0, -1000.0), "{name}");
        assert_eq!(l.volume.spacing(), DVec3::new(10.0, 10.0, 150.0), "{name}");
        // The ground (file level 0) is the lowest slice, 400 hPa the highest.
        assert_eq!(l.volume.get(2, 1, 0), ramp(2, 1, 0), "{name}");
        assert_eq!(l.volume.world_position(0, 0, 4).z, -400.0, "{name}");
        assert_note(&l, "z (level) points down (positive = \"down\")");
        assert_note(&l, "level 1000 lowest, 400 highest");
        assert_note(&l, "z (level) in hPa: not length units");
        assert_eq!(l.info.length_unit, None, "{name}");
    }
}

#[test]
fn pressure_levels_stored_from_the_top_down_land_in_the_same_place() {
    let Some(dir) = files() else { return };
    // Stored 400 … 1000 hPa, with units only: a pressure points down too.
    let l = load(&dir.join("pressure_up.nc"));
    check_world(
        "pressure_up.nc",
        &l.volume,
        &pressure_grid(400.0, 150.0),
        1e-9,
        ramp,
    );
    assert_eq!(l.volume.origin(), DVec3::new(0.0, 0.0, -1000.0));
    assert_eq!(l.volume.get(2, 1, 0), ramp(2, 1, 4), "1000 hPa lowest");
    assert_note(&l, "z (level) points down (units = \"hPa\", a pressure)");
}

#[test]
fn ocean_depth_puts_the_surface_on_top_and_km_become_m() {
    let Some(dir) = files() else { return };
    let l = load(&dir.join("ocean.nc"));
    // Depth 0, 25, 50, 75 m at z = 0, −25, −50, −75: the surface (file
    // index 0) on top, the seabed the lowest; x, y in km are m × 1000.
    let grid = Grid {
        n: [5, 3, 4],
        steps: [DVec3::X * 1000.0, DVec3::Y * 2000.0, DVec3::Z * -25.0],
        origin: DVec3::ZERO,
    };
    check_world("ocean.nc", &l.volume, &grid, 1e-9, ramp);
    assert_eq!(l.volume.origin(), DVec3::new(0.0, 0.0, -75.0));
    assert_eq!(l.volume.world_position(0, 0, 3).z, 0.0);
    assert_eq!(l.volume.get(1, 2, 3), ramp(1, 2, 0), "the surface on top");
    assert_eq!(l.info.length_unit.as_deref(), Some("m"));
    assert_note(
        &l,
        "x (x)/y (y) in km, z (depth) in m: spacing in m (x (x) × 1000, y (y) × 1000)",
    );
    assert_note(&l, "depth 75 lowest, 0 highest");
}

#[test]
fn box_by_box_reads_of_oriented_variables_agree_with_the_whole() {
    let Some(dir) = files() else { return };
    // pressure.nc runs forward once placed at z = −p: read box by box.
    // The others run backward along z (or x): box by box where the lazy
    // path flips them, else read whole; either way the same samples.
    for (name, must_be_lazy) in [
        ("pressure.nc", true),
        ("pressure_up.nc", false),
        ("ocean.nc", false),
    ] {
        let path = dir.join(name);
        let whole = load(&path).volume;
        let Some(lazy) = open_lazy(&path, &ReadOptions::default()).unwrap() else {
            assert!(!must_be_lazy, "{name}: not opened box by box");
            continue;
        };
        let grid = lazy.source.grid();
        assert_eq!(grid.dims, whole.dims(), "{name}");
        assert_eq!(grid.origin, whole.origin(), "{name}");
        assert_eq!(grid.spacing, whole.spacing(), "{name}");
        let dims = whole.dims();
        let part = lazy.source.read_box([1, 1, 1], dims).unwrap();
        for k in 1..dims[2] {
            for j in 1..dims[1] {
                for i in 1..dims[0] {
                    assert_eq!(
                        part.get(i - 1, j - 1, k - 1),
                        whole.get(i, j, k),
                        "{name} at ({i}, {j}, {k})"
                    );
                }
            }
        }
    }
}

#[test]
fn ome_zarr_axes_in_micrometer_and_nanometer_meet_in_nanometer() {
    let Some(dir) = files() else { return };
    for name in ["mixed04.zarr", "mixed05.zarr"] {
        let path: PathBuf = dir.join(name);
        let l = load(&path);
        // scale [1, 100, 100]: z 1 µm = 1000 nm, y and x 100 nm; the
        // translation [2, 50, 0]: z 2 µm = 2000 nm.
        assert_eq!(
            l.volume.spacing(),
            DVec3::new(100.0, 100.0, 1000.0),
            "{name}"
        );
        assert_eq!(l.volume.origin(), DVec3::new(0.0, 50.0, 2000.0), "{name}");
        let s = l.volume.spacing();
        assert_eq!((s.z / s.x, s.y / s.x), (10.0, 1.0), "{name}: exact ratios");
        assert_eq!(l.info.length_unit.as_deref(), Some("nanometer"), "{name}");
        assert_note(
            &l,
            "z in micrometer, y/x in nanometer: spacing in nanometer (z × 1000)",
        );
        assert_eq!(l.info.levels[0].spacing, [100.0, 100.0, 1000.0], "{name}");
        let grid = Grid {
            n: [5, 4, 3],
            steps: [DVec3::X * 100.0, DVec3::Y * 100.0, DVec3::Z * 1000.0],
            origin: DVec3::new(0.0, 50.0, 2000.0),
        };
        check_world(name, &l.volume, &grid, 1e-9, ramp);
        // Read box by box, the same grid.
        let lazy = open_lazy(&path, &ReadOptions::default()).unwrap().unwrap();
        let g = lazy.source.grid();
        assert_eq!(
            (g.spacing, g.origin),
            (l.volume.spacing(), l.volume.origin())
        );
    }
}

#[test]
fn nrrd_space_units_meet_in_the_finest() {
    let Some(dir) = files() else { return };
    let l = load(&dir.join("mixed.nrrd"));
    // Space directions 0.5 mm, 0.5 mm, 2 µm from (1 mm, 2 mm, 3 µm): in µm.
    let grid = Grid {
        n: [5, 4, 3],
        steps: [DVec3::X * 500.0, DVec3::Y * 500.0, DVec3::Z * 2.0],
        origin: DVec3::new(1000.0, 2000.0, 3.0),
    };
    check_world("mixed.nrrd", &l.volume, &grid, 1e-9, ramp);
    assert_eq!(l.info.length_unit.as_deref(), Some("um"));
    assert_note(&l, "x/y in mm, z in um: spacing in um (x × 1000, y × 1000)");
}
