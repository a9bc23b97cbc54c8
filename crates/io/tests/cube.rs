//! Reads Gaussian cube files written by ASE and by hand in Gaussian's own
//! layout (see `fixtures/make_cube_fixtures.py`) and checks every voxel
//! against the formula the fixture was made from, the geometry against
//! the header, and what `FileInfo` reports. Malformed variants are made
//! here from the fixtures.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_frame_out_of_range, check_resampled, check_voxels, refused_file, with_frame};
use volray_core::glam::{DMat3, DVec3};
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("cube", name)
}

fn load(path: &Path, frame: Option<usize>) -> Result<Loaded, IoError> {
    read(path, &with_frame(frame))
}

fn ramp(i1: usize, i2: usize, i3: usize) -> f32 {
    (i1 + 10 * i2 + 100 * i3) as f32
}

fn assert_close(a: DVec3, b: DVec3) {
    assert!((a - b).length() < 1e-9, "{a} vs {b}");
}

#[test]
fn ase_ramp_in_bohr() {
    let l = load(&fixture("ramp_bohr.cube"), None).unwrap();
    assert_eq!(l.format, VolumeFormat::Cube);
    let v = &l.volume;
    // Axis 1 (slowest in the file) runs along x: a[i1, i2, i3] at (i1, i2, i3).
    assert_eq!(v.dims(), [4, 3, 5]);
    assert_close(v.spacing(), DVec3::new(0.5, 0.25, 0.75));
    assert_close(v.origin(), DVec3::new(-1.0, 2.0, 0.5));
    check_voxels("", v, [4, 3, 5], ramp);
    let info = &l.info;
    assert_eq!(info.length_unit.as_deref(), Some("bohr"));
    assert_eq!((info.frames, info.frame), (1, 0));
    assert_eq!(info.stored_type, "decimal text");
    let keys: Vec<&str> = info.header.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        keys,
        [
            "comment 1",
            "comment 2",
            "NAtoms",
            "origin",
            "axis 1",
            "axis 2",
            "axis 3",
            "atom 1",
            "atom 2",
            "atom 3"
        ]
    );
    assert_eq!(info.header[0].1, "volray ramp fixture");
    assert_eq!(info.header[2].1, "3");
    assert_eq!(info.header[4].1, "4 0.500000 0.000000 0.000000");
    assert!(
        info.header[8]
            .1
            .starts_with("Z 1 charge 0.000000 at (1.430523")
    );
    assert!(
        info.notes.iter().any(|n| n.contains("in bohr")),
        "{:?}",
        info.notes
    );
    // Axis 3 is volray's index axis 0, so the samples were turned to x, y, z.
    assert!(info.notes.iter().any(|n| n.contains("index axis 0 -> +z")));
}

#[test]
fn ase_permuted_and_flipped_axes_keep_world_positions() {
    let l = load(&fixture("permuted.cube"), None).unwrap();
    let v = &l.volume;
    // File axes: 1 (3 points) along -z by 0.5, 2 (4 points) along +x by
    // 0.25, 3 (2 points) along +y by 0.75, from (1, 2, 3).
    assert_eq!(v.dims(), [4, 2, 3]);
    assert_close(v.spacing(), DVec3::new(0.25, 0.75, 0.5));
    assert_close(v.origin(), DVec3::new(1.0, 2.0, 2.0));
    for i1 in 0..3 {
        for i2 in 0..4 {
            for i3 in 0..2 {
                let world = DVec3::new(1.0, 2.0, 3.0)
                    + DVec3::new(0.0, 0.0, -0.5) * i1 as f64
                    + DVec3::new(0.25, 0.0, 0.0) * i2 as f64
                    + DVec3::new(0.0, 0.75, 0.0) * i3 as f64;
                let (i, j, k) = (i2, i3, 2 - i1);
                assert_close(v.world_position(i, j, k), world);
                assert_eq!(v.get(i, j, k), ramp(i1, i2, i3));
            }
        }
    }
}

#[test]
fn gaussian_orbitals_in_angstrom_are_frames() {
    for (frame, mo) in [(0usize, 5), (1, 6), (2, 7)] {
        let opt = if frame == 0 { None } else { Some(frame) };
        let l = load(&fixture("orbitals_angstrom.cube"), opt).unwrap();
        let v = &l.volume;
        assert_eq!(v.dims(), [4, 3, 5]);
        assert_close(v.spacing(), DVec3::new(0.4, 0.5, 0.25));
        assert_close(v.origin(), DVec3::new(-1.0, -2.0, -3.0));
        let sign = if frame % 2 == 0 { 1.0 } else { -1.0 };
        check_voxels(&format!("frame {frame}"), v, [4, 3, 5], |i, j, k| {
            1000.0 * (frame + 1) as f32 + sign * ramp(i, j, k)
        });
        let info = &l.info;
        assert_eq!((info.frames, info.frame), (3, frame));
        assert_eq!(info.length_unit.as_deref(), Some("angstrom"));
        assert!(
            info.notes
                .iter()
                .any(|n| n.contains(&format!("molecular orbital {mo} ")))
                && info.notes.iter().any(|n| n.contains("orbitals 5, 6, 7")),
            "{:?}",
            info.notes
        );
        assert!(info.notes.iter().any(|n| n.contains("in angstrom")));
        assert!(
            info.header
                .iter()
                .any(|(k, val)| k == "DSET_IDS" && val == "3: 5 6 7")
        );
        assert!(info.header.iter().any(|(k, val)| k == "NVal" && val == "1"));
    }
    let err = load(&fixture("orbitals_angstrom.cube"), Some(3)).unwrap_err();
    assert_frame_out_of_range(
        &err,
        3,
        "the file holds 3 orbital(s) per point (frames 0 to 2)",
    );
}

#[test]
fn fortran_exponent_forms() {
    let l = load(&fixture("fortran_exponents.cube"), None).unwrap();
    check_voxels("", &l.volume, [2, 2, 3], |i, j, k| {
        let base = 1.0 + f64::from(ramp(i, j, k));
        // Even parity: 0.ddddd-ee (below f32's range, so 0); odd: D exponent.
        if (i + j + k) % 2 == 0 {
            (base * 1e-100) as f32
        } else {
            base as f32
        }
    });
}

/// A hexagonal cell is resampled as one periodic cell: every output
/// sample whose grid coordinates fall inside the file's grid (no wrap)
/// equals the trilinear ramp at those coordinates.
#[test]
fn skewed_hexagonal_cell_is_resampled_periodically() {
    let l = load(&fixture("hexagonal.cube"), None).unwrap();
    // Steps as the file writes them (6 decimals), axis 3 first.
    let steps = [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(-0.25, 0.433013, 0.0),
        DVec3::new(0.5, 0.0, 0.0),
    ];
    let dims = [4usize, 6, 6];
    let to_grid = DMat3::from_cols(steps[0], steps[1], steps[2]).inverse();
    let v = &l.volume;
    // The bounding box of the cell: x from -1.5 to 3, y to 2.598, z to 4.
    let (lo, hi) = v.bounds();
    assert_close(lo, DVec3::new(-1.5, 0.0, 0.0));
    assert!(
        (hi - DVec3::new(3.0, 6.0 * 0.433013, 4.0)).length() < 1e-9,
        "{hi}"
    );
    let last = dims.map(|n| (n - 1) as f64);
    // Index axis 0 is file axis 3 (the ramp's 100s).
    let inside = check_resampled(v, to_grid, last, 1e-3, |g| {
        100.0 * g[0] + 10.0 * g[1] + g[2]
    });
    assert!(inside > 50, "{inside}");
    let note = l
        .info
        .notes
        .iter()
        .find(|n| n.contains("periodic"))
        .unwrap();
    assert!(
        note.contains("angle(axis 2, axis 1) 120.000, angle(axis 3, axis 1) 90.000, angle(axis 3, axis 2) 90.000 degrees"),
        "{note}"
    );
    assert!(
        note.contains("cell of 4 x 6 x 6 points (axis 3 x axis 2 x axis 1)"),
        "{note}"
    );
}

/// Writes `text` as a .cube file in a temporary directory and reads it,
/// expecting a refusal; returns the message.
fn error_of(text: &str) -> String {
    refused_file("bad.cube", text.as_bytes(), &ReadOptions::default())
}

#[test]
fn malformed_variants_of_a_real_file() {
    let good = std::fs::read_to_string(fixture("ramp_bohr.cube")).unwrap();
    let lines: Vec<&str> = good.lines().collect();

    // Truncated in the data.
    let cut = lines[..lines.len() - 3].join("\n");
    let msg = error_of(&cut);
    assert!(
        msg.contains("after 57 of the 60 values of the grid"),
        "{msg}"
    );

    // A lying point count: N1 = 40000 on each axis needs far more bytes.
    let mut lying = lines.clone();
    lying[3] = "40000    0.500000    0.000000    0.000000";
    lying[4] = "40000    0.000000    0.250000    0.000000";
    let msg = error_of(&lying.join("\n"));
    assert!(
        msg.contains("40000x40000x5 points with 1 value(s) each, more than a"),
        "{msg}"
    );

    // More atoms declared than there are atom lines: a data line is read
    // as an atom.
    let mut atoms = lines.clone();
    atoms[2] = "    4   -1.000000    2.000000    0.500000";
    let msg = error_of(&atoms.join("\n"));
    assert!(
        msg.contains("line 10: atom 4: expected atomic number"),
        "{msg}"
    );

    // A non-numeric value.
    let mut bad = lines.clone();
    bad[20] = "1.0e+0x";
    let msg = error_of(&bad.join("\n"));
    assert!(
        msg.contains("line 21: grid value: \"1.0e+0x\" is not a number"),
        "{msg}"
    );

    // An empty file and a binary one.
    let msg = error_of("");
    assert!(msg.contains("comment line 1"), "{msg}");
    let msg = refused_file(
        "b.cube",
        &[0x93, 0xff, 0xfe, b'\n', 0, 1, 2],
        &ReadOptions::default(),
    );
    assert!(msg.contains("line 1: not UTF-8 text"), "{msg}");
}

/// Truncations and single-byte corruptions of every fixture: each read
/// either succeeds or fails with a one-line error naming the file; none
/// panics.
#[test]
fn corrupted_files_never_panic() {
    common::text_edits_never_panic(&fixture(""), "fuzzed.cube");
}
