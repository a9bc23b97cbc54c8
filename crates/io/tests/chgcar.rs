//! Reads VASP CHGCAR/CHG files written by ASE and by hand in VASP's own
//! layouts (see `fixtures/make_chgcar_fixtures.py`) and checks every
//! voxel against the density the fixture was made from (the file stores
//! density times cell volume), the periodic wrap-around planes, the
//! geometry, the frames and what `FileInfo` reports. Malformed variants
//! are made here from the fixtures.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_frame_out_of_range, check_resampled, has_note, refused_file, with_frame};
use volray_core::Volume;
use volray_core::glam::{DMat3, DVec3};
use volray_io::{IoError, Loaded, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("chgcar", name)
}

fn load(path: &Path, frame: Option<usize>) -> Result<Loaded, IoError> {
    read(path, &with_frame(frame))
}

fn ramp(i: usize, j: usize, k: usize) -> f64 {
    (i + 10 * j + 100 * k) as f64
}

fn close(a: f32, b: f64) -> bool {
    (f64::from(a) - b).abs() <= 1e-6 * b.abs().max(1.0)
}

/// Every point of the closed periodic grid (NG + 1 per axis) against
/// `rho` of the wrapped indices.
fn check_periodic(v: &Volume, ng: [usize; 3], rho: impl Fn(usize, usize, usize) -> f64) {
    assert_eq!(v.dims(), [ng[0] + 1, ng[1] + 1, ng[2] + 1]);
    for k in 0..=ng[2] {
        for j in 0..=ng[1] {
            for i in 0..=ng[0] {
                let want = rho(i % ng[0], j % ng[1], k % ng[2]);
                let got = v.get(i, j, k);
                assert!(close(got, want), "({i}, {j}, {k}): {got} vs {want}");
            }
        }
    }
}

#[test]
fn ase_chgcar_is_divided_by_the_cell_volume_and_closed() {
    let l = load(&fixture("CHGCAR_ortho"), None).unwrap();
    assert_eq!(l.format, VolumeFormat::Chgcar);
    check_periodic(&l.volume, [4, 3, 5], |i, j, k| 1.0 + ramp(i, j, k));
    assert!((l.volume.spacing() - DVec3::new(0.75, 4.0 / 3.0, 1.0)).length() < 1e-12);
    assert_eq!(l.volume.origin(), DVec3::ZERO);
    // The closed grid spans the whole cell.
    assert!((l.volume.extent() - DVec3::new(3.0, 4.0, 5.0)).length() < 1e-12);
    let info = &l.info;
    assert_eq!(info.length_unit.as_deref(), Some("angstrom"));
    assert_eq!((info.frames, info.frame), (1, 0));
    let keys: Vec<&str> = info.header.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(
        keys,
        [
            "system",
            "scale",
            "lattice a",
            "lattice b",
            "lattice c",
            "species",
            "counts",
            "coordinates",
            "atom 1",
            "atom 2",
            "atom 3",
            "NGX NGY NGZ"
        ]
    );
    assert_eq!(info.header[5].1, "Si  O");
    assert_eq!(info.header[11].1, "4 3 5");
    assert!(
        has_note(&l, "divided by the cell volume 60.000000 cubic angstrom"),
        "{:?}",
        info.notes
    );
    assert!(has_note(&l, "wrap-around plane was appended"));
    assert!(has_note(&l, "frame 0 of 1 is the only block"));
}

#[test]
fn spin_polarised_frames() {
    let total = load(&fixture("CHGCAR_spin"), None).unwrap();
    check_periodic(&total.volume, [4, 3, 5], |i, j, k| 1.0 + ramp(i, j, k));
    assert_eq!((total.info.frames, total.info.frame), (2, 0));
    assert!(has_note(&total, "the total density (spin up + spin down)"));
    let mag = load(&fixture("CHGCAR_spin"), Some(1)).unwrap();
    check_periodic(&mag.volume, [4, 3, 5], |i, j, k| {
        (i as f64 - j as f64 + k as f64) / 2.0
    });
    assert_eq!((mag.info.frames, mag.info.frame), (2, 1));
    assert!(has_note(
        &mag,
        "frame 1 of 2 is the magnetisation density (spin up - spin down)"
    ));
    let err = load(&fixture("CHGCAR_spin"), Some(2)).unwrap_err();
    assert_frame_out_of_range(&err, 2, "the file holds 2 density block(s) (frames 0 to 1)");
}

#[test]
fn non_collinear_blocks_with_augmentation_between() {
    for b in 0..4 {
        let l = load(&fixture("CHGCAR_noncollinear"), Some(b)).unwrap();
        check_periodic(&l.volume, [2, 2, 3], |i, j, k| {
            (b + 1) as f64 * (1.0 + ramp(i, j, k))
        });
        assert_eq!(l.info.frames, 4);
        if b > 0 {
            let axis = ["x", "y", "z"][b - 1];
            assert!(
                has_note(&l, &format!("m_{axis} (non-collinear)")),
                "{:?}",
                l.info.notes
            );
        }
    }
}

#[test]
fn chg_with_two_ionic_steps() {
    for (frame, a, offset) in [(0, 2.0, 1.0), (1, 2.2, 2.0)] {
        let l = load(&fixture("CHG_md"), Some(frame)).unwrap();
        check_periodic(&l.volume, [2, 3, 2], |i, j, k| offset + ramp(i, j, k));
        assert!((l.volume.spacing().x - a / 2.0).abs() < 1e-12);
        assert_eq!(l.info.frames, 2);
        assert!(
            has_note(&l, &format!("of ionic step {} of the 2 stored", frame + 1)),
            "{:?}",
            l.info.notes
        );
    }
}

#[test]
fn vasp4_header_negative_scale_selective_dynamics() {
    let l = load(&fixture("CHGCAR_vasp4"), None).unwrap();
    // Scale -27 makes the unit lattice a 3 Å cube: V = 27.
    check_periodic(&l.volume, [2, 2, 2], |i, j, k| 1.0 + ramp(i, j, k));
    assert!((l.volume.spacing() - DVec3::splat(1.5)).length() < 1e-12);
    let keys: Vec<&str> = l.info.header.iter().map(|(k, _)| k.as_str()).collect();
    assert!(
        keys.contains(&"selective dynamics") && !keys.contains(&"species"),
        "{keys:?}"
    );
    assert!(has_note(&l, "cell volume 27.000000"));
}

#[test]
fn locpot_is_not_scaled() {
    let l = load(&fixture("LOCPOT"), None).unwrap();
    check_periodic(&l.volume, [4, 3, 5], |i, j, k| -ramp(i, j, k) / 10.0);
    assert!(
        has_note(&l, "not divided by the cell volume"),
        "{:?}",
        l.info.notes
    );
}

/// CHG stores 1 + ramp on a hexagonal cell: the resampled volume's
/// samples inside the file's grid (no wrap) equal the trilinear ramp / V.
#[test]
fn hexagonal_chg_is_resampled_periodically() {
    let l = load(&fixture("CHG_hexagonal"), None).unwrap();
    let a = DVec3::new(3.0, 0.0, 0.0);
    let b = DVec3::new(-1.5, 2.598_076_211_353_316, 0.0);
    let c = DVec3::new(0.0, 0.0, 4.0);
    let volume = DMat3::from_cols(a, b, c).determinant();
    let to_grid = DMat3::from_cols(a / 6.0, b / 6.0, c / 4.0).inverse();
    let inside = check_resampled(&l.volume, to_grid, [5.0, 5.0, 3.0], 1e-5, |g| {
        (1.0 + g.x + 10.0 * g.y + 100.0 * g.z) / volume
    });
    assert!(inside > 50, "{inside}");
    assert!(has_note(&l, "angle(a, b) 120.000"), "{:?}", l.info.notes);
    assert!(has_note(&l, "periodic images"));
}

/// Writes `text` under `name` in a temporary directory and reads it,
/// expecting a refusal; returns the message.
fn error_of(name: &str, text: &str, frame: Option<usize>) -> String {
    refused_file(name, text.as_bytes(), &with_frame(frame))
}

#[test]
fn malformed_variants_of_a_real_file() {
    let good = std::fs::read_to_string(fixture("CHGCAR_ortho")).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    let with = |n: usize, line: &str| {
        let mut l = lines.clone();
        l[n] = line;
        l.join("\n")
    };

    // Truncated in the data.
    let e = error_of("CHGCAR", &lines[..16].join("\n"), None);
    assert!(
        e.contains("after 15 of the 60 values of density block 1"),
        "{e}"
    );
    // A lying grid size.
    let e = error_of("CHGCAR", &with(12, "  400  300  500"), None);
    assert!(
        e.contains("line 13: grid size 400 x 300 x 500: more values than a"),
        "{e}"
    );
    // A grid line with two numbers.
    let e = error_of("CHGCAR", &with(12, "    4    3"), None);
    assert!(
        e.contains("line 13: grid size: expected NGX NGY NGZ, found \"4    3\""),
        "{e}"
    );
    // More atoms than position lines: the blank line is read as an atom.
    let e = error_of("CHGCAR", &with(6, "   1   3"), None);
    assert!(
        e.contains("line 12: atom position 4: expected three numbers"),
        "{e}"
    );
    // A bad value.
    let e = error_of(
        "CHGCAR",
        &with(14, " 7.2E+02 7.8E+02 x 8.4E+02 1.26E+03"),
        None,
    );
    assert!(
        e.contains("line 15: grid value: \"x\" is not a number"),
        "{e}"
    );
    // Extra values on the last data line.
    let e = error_of("CHGCAR", &with(24, &format!("{} 9.9", lines[24])), None);
    assert!(
        e.contains("line 25: \"9.9\" follows the last of the 60 values"),
        "{e}"
    );
    // Not a VASP file at all.
    let e = error_of("CHGCAR", "hello\nworld\n", None);
    assert!(
        e.contains("line 2: scale factor: expected one number or three"),
        "{e}"
    );
    let e = error_of("CHG", "", None);
    assert!(e.contains("where the system name should be"), "{e}");
    // A frame past the end.
    let e = error_of("CHGCAR", &good, Some(1));
    assert!(
        e.ends_with("frame 1 is out of range: the file holds 1 density block(s) (frames 0 to 0)"),
        "{e}"
    );
}

/// Truncations and single-byte corruptions of every fixture: each read
/// either succeeds or fails with a one-line error naming the file; none
/// panics.
#[test]
fn corrupted_files_never_panic() {
    common::text_edits_never_panic(&fixture(""), "CHGCAR_fuzzed");
}
