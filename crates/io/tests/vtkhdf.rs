//! VTKHDF image data written at test time by VTK's own `vtkHDFWriter`
//! (`tests/vtkhdf/write_files.py`, which checks VTK's reader agrees on
//! where the first point lies): point and cell arrays by name, the active
//! scalars by default, components by `--channel`, the extent's offset in
//! the origin, an HDF5 file told as VTKHDF by its `/VTKHDF` group, read
//! whole and box by box; other dataset types, rotated image data and
//! arrays whose shape disagrees with the extent refused in one line.
//!
//! The writer runs in `target/pyenv` (which `.ci/run` installs); without
//! VTK these tests fail under `CI=true` and are skipped elsewhere.

mod common;

use std::path::Path;
use std::sync::OnceLock;

use common::{Grid, assert_note, check_world, refused};
use volray_core::glam::DVec3;
use volray_io::{ReadOptions, VolumeFormat, open_lazy, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["vtk", "h5py", "numpy"],
        "tests/vtkhdf/write_files.py",
    )
}

fn array(name: &str) -> ReadOptions {
    ReadOptions {
        array: Some(name.into()),
        ..ReadOptions::default()
    }
}

/// The points of image.vtkhdf: extent (1..4, 0..2, 2..6) from origin
/// (10, 20, 30) by spacing (0.5, 2, 1.5).
fn points() -> Grid {
    Grid {
        n: [4, 3, 5],
        steps: [DVec3::X * 0.5, DVec3::Y * 2.0, DVec3::Z * 1.5],
        origin: DVec3::new(10.5, 20.0, 33.0),
    }
}

fn ramp(i: usize, j: usize, k: usize) -> f32 {
    (i + 10 * j + 100 * k) as f32
}

#[test]
fn the_active_scalars_lie_where_vtk_puts_them() {
    let Some(dir) = files() else { return };
    for name in ["image.vtkhdf", "image.h5"] {
        let l = read(&dir.join(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(l.format, VolumeFormat::Vtkhdf, "{name}");
        check_world(name, &l.volume, &points(), 1e-9, ramp);
        assert_note(&l, "VTKHDF ImageData: point array \"density\"");
        assert_note(&l, "--array picks one");
    }
}

#[test]
fn other_arrays_are_picked_by_name_and_components_by_channel() {
    let Some(dir) = files() else { return };
    let path = dir.join("image.vtkhdf");
    let l = read(&path, &array("twice")).unwrap();
    check_world("twice", &l.volume, &points(), 1e-9, |i, j, k| {
        2.0 * ramp(i, j, k)
    });
    for (channel, f) in [(1usize, -1.0f32), (2, 1.0)] {
        let opts = ReadOptions {
            channel: Some(channel),
            ..array("PointData/vector")
        };
        let l = read(&path, &opts).unwrap();
        let add = if channel == 2 { 1000.0 } else { 0.0 };
        check_world("vector", &l.volume, &points(), 1e-9, |i, j, k| {
            add + f * ramp(i, j, k)
        });
    }
    // Cells: 3 x 2 x 4, their centres half a step in.
    let l = read(&path, &array("cells")).unwrap();
    let cells = Grid {
        n: [3, 2, 4],
        origin: DVec3::new(10.75, 21.0, 33.75),
        ..points()
    };
    check_world("cells", &l.volume, &cells, 1e-9, ramp);
    let e = refused(&path, &array("nothing"));
    assert!(
        e.contains("no array \"nothing\"; its arrays: PointData/density, PointData/twice, PointData/vector, CellData/cells"),
        "{e}"
    );
}

#[test]
fn a_box_read_by_itself_holds_what_the_whole_read_holds() {
    let Some(dir) = files() else { return };
    let path = dir.join("image.vtkhdf");
    let whole = read(&path, &ReadOptions::default()).unwrap().volume;
    let lazy = open_lazy(&path, &ReadOptions::default())
        .unwrap()
        .expect("a source of boxes");
    let part = lazy.source.read_box([1, 0, 2], [4, 3, 5]).unwrap();
    for z in 2..5 {
        for y in 0..3 {
            for x in 1..4 {
                assert_eq!(
                    part.get(x - 1, y, z - 2),
                    whole.get(x, y, z),
                    "({x}, {y}, {z})"
                );
            }
        }
    }
}

#[test]
fn what_is_not_image_data_on_the_grid_is_refused_in_one_line() {
    let Some(dir) = files() else { return };
    for (name, want) in [
        (
            "grid.vtkhdf",
            "VTKHDF: Type \"UnstructuredGrid\" is not read",
        ),
        (
            "rotated.vtkhdf",
            "is not the identity: rotated or flipped image data is not read yet",
        ),
        (
            "short.vtkhdf",
            "array \"PointData/density\": shape [4, 3, 4], but WholeExtent",
        ),
    ] {
        let e = refused(&dir.join(name), &ReadOptions::default());
        assert!(e.contains(want), "{name}: {e}");
    }
}
