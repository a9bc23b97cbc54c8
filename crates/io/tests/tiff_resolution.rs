//! Plain TIFF stacks (no ImageJ or OME metadata) whose resolution tags
//! give the pixel size, written at test time by tifffile
//! (`tests/tiff_resolution/write_files.py`): pixels per centimetre or per
//! inch become the spacing in mm, with z taken equal to x; a print
//! default (72 dpi) or a unit of "none" keeps spacing 1. Every stack holds
//! `v = x + 10y + 100z`, so the samples' places are checked too.
//!
//! The writer runs in `target/pyenv` (which `.ci/run` installs); without
//! tifffile these tests fail under `CI=true` and are skipped elsewhere.

mod common;

use std::path::Path;
use std::sync::OnceLock;

use common::{assert_note, check_voxels, ramp};
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["tifffile", "numpy"],
        "tests/tiff_resolution/write_files.py",
    )
}

fn load(dir: &Path, name: &str) -> Loaded {
    let l = read(&dir.join(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    check_voxels(name, &l.volume, [4, 3, 5], |x, y, z| ramp(x, y, z) as f32);
    l
}

#[test]
fn pixels_per_centimetre_give_the_spacing_in_mm_with_z_as_x() {
    let Some(dir) = files() else { return };
    let l = load(dir, "cm.tif");
    // tifffile: 20 and 40 pixels per cm are 0.5 and 0.25 mm.
    assert_eq!(l.volume.spacing(), DVec3::new(0.5, 0.25, 0.5));
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
    assert_note(
        &l,
        "from the resolution tags (20, 40 pixels per centimetre)",
    );
    assert_note(&l, "z taken equal to x, give --spacing");
}

#[test]
fn pixels_per_inch_give_the_spacing_in_mm() {
    let Some(dir) = files() else { return };
    let l = load(dir, "inch.tif");
    let s = l.volume.spacing();
    assert!((s - DVec3::splat(0.5)).abs().max_element() < 1e-9, "{s}");
    assert_eq!(l.info.length_unit.as_deref(), Some("mm"));
}

#[test]
fn a_print_default_or_no_unit_keeps_spacing_one() {
    let Some(dir) = files() else { return };
    let l = load(dir, "dpi72.tif");
    assert_eq!(l.volume.spacing(), DVec3::ONE);
    assert_eq!(l.info.length_unit, None);
    assert_note(&l, "72 pixels per inch are a print default");
    let l = load(dir, "no_unit.tif");
    assert_eq!(l.volume.spacing(), DVec3::ONE);
    assert_note(&l, "the resolution tags name no unit");
}
