//! BigDataViewer HDF5 datasets written at test time by npy2bdv
//! (`tests/bdv/write_files.py`): view setups as channels, time points,
//! levels, the voxel size and registration as geometry, uint16 kept in
//! int16 datasets read as unsigned, the `.h5` with or without its XML,
//! read whole and box by box; other loaders and rotated registrations
//! refused in one line.
//!
//! The writer runs in `target/pyenv` (which `.ci/run` installs); without
//! npy2bdv these tests fail under `CI=true` and are skipped elsewhere.

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
        &["npy2bdv", "h5py", "numpy"],
        "tests/bdv/write_files.py",
    )
}

fn at(t: usize, c: usize, level: Option<usize>) -> ReadOptions {
    ReadOptions {
        frame: Some(t),
        channel: Some(c),
        level,
        ..ReadOptions::default()
    }
}

/// Level 0: voxel size (0.5, 0.5, 2) µm; the shift (10, 20, 30) in
/// BigDataViewer's world units (0.5 µm each) puts voxel 0 at (5, 10, 15).
fn level0() -> Grid {
    Grid {
        n: [10, 6, 8],
        steps: [DVec3::X * 0.5, DVec3::Y * 0.5, DVec3::Z * 2.0],
        origin: DVec3::new(5.0, 10.0, 15.0),
    }
}

#[test]
fn setups_and_time_points_are_channels_and_frames_in_micrometres() {
    let Some(dir) = files() else { return };
    for name in ["dataset.xml", "dataset.h5"] {
        for (t, c) in [(0, 0), (1, 1), (0, 1)] {
            let l = read(&dir.join(name), &at(t, c, None)).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(l.format, VolumeFormat::Bdv);
            check_world(name, &l.volume, &level0(), 1e-9, |i, j, k| {
                (i + 10 * j + 100 * k + 40000 * c + 1000 * t) as f32
            });
            assert_eq!(l.info.length_unit.as_deref(), Some("um"));
            assert_eq!((l.info.time_points, l.info.channels), (2, 2));
            assert_eq!(l.info.levels.len(), 2);
            assert_note(&l, "read as unsigned 16-bit");
        }
    }
}

#[test]
fn a_coarser_level_lies_as_bigdataviewer_places_it() {
    let Some(dir) = files() else { return };
    let l = read(&dir.join("dataset.xml"), &at(1, 1, Some(1))).unwrap();
    let want = common_npy(&dir.join("level1_c1_t1.npy"));
    // Factors 2: spacing doubled, the first voxel's centre half a level-0
    // voxel further along each axis.
    let grid = Grid {
        n: [5, 3, 4],
        steps: [DVec3::X, DVec3::Y, DVec3::Z * 4.0],
        origin: DVec3::new(5.25, 10.25, 16.0),
    };
    check_world("level 1", &l.volume, &grid, 1e-9, |i, j, k| {
        want[(k * 3 + j) * 5 + i] as f32
    });
}

/// The uint16 samples of a small C-order `.npy` written by numpy.
fn common_npy(path: &Path) -> Vec<u16> {
    let bytes = std::fs::read(path).unwrap();
    let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + header..]
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect()
}

#[test]
fn the_h5_alone_reads_at_spacing_one_and_boxes_match_the_whole() {
    let Some(dir) = files() else { return };
    let l = read(&dir.join("alone.h5"), &ReadOptions::default()).unwrap();
    assert_eq!(l.volume.spacing(), DVec3::ONE);
    assert_note(&l, "without its XML");
    let path = dir.join("dataset.xml");
    let whole = read(&path, &at(1, 0, None)).unwrap().volume;
    let lazy = open_lazy(&path, &at(1, 0, None)).unwrap().expect("boxes");
    let part = lazy.source.read_box([2, 1, 3], [9, 6, 8]).unwrap();
    for z in 3..8 {
        for y in 1..6 {
            for x in 2..9 {
                assert_eq!(part.get(x - 2, y - 1, z - 3), whole.get(x, y, z));
            }
        }
    }
}

#[test]
fn other_loaders_and_rotated_views_are_refused() {
    let Some(dir) = files() else { return };
    for (name, want) in [
        ("n5.xml", "ImageLoader format \"bdv.n5\" is not read"),
        ("rotated.xml", "registered views are not read yet"),
    ] {
        let e = refused(&dir.join(name), &ReadOptions::default());
        assert!(e.contains(want), "{name}: {e}");
    }
}
