//! DICOM file-sets as discs and archives lay them out (a DICOMDIR at the
//! top, series in subfolders; several series) and DICOM Segmentation
//! objects, written at test time by pydicom and highdicom
//! (`dicom_cd/make_fixtures.py`, which describes each), read through
//! `volray_io::read`.

mod common;

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::{assert_note, refused};
use volray_core::Volume;
use volray_core::glam::DVec3;
use volray_io::{Loaded, ReadOptions, VolumeFormat, read};

static FIXTURES: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();

/// The fixtures' folder, or `None` (skipped) without pydicom and highdicom.
fn fixtures() -> Option<&'static Path> {
    common::written_by_python(
        &FIXTURES,
        &["pydicom", "highdicom"],
        "tests/dicom_cd/make_fixtures.py",
    )
}

fn load(path: &Path, opts: &ReadOptions) -> Loaded {
    let l = read(path, opts).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::Dicom);
    l
}

fn series(s: &str) -> ReadOptions {
    ReadOptions {
        series: Some(s.to_string()),
        ..ReadOptions::default()
    }
}

/// Checks that `volume` is series A: v - 1000 at pixel (x, y) of slice
/// z, which lies at (-10, 20, 30) + (0.6x, 0.8y, 2.5z).
fn assert_series_a(volume: &Volume) {
    assert_eq!(volume.dims(), [4, 3, 5]);
    for z in 0..5 {
        for y in 0..3 {
            for x in 0..4 {
                let v = (x + 10 * y + 100 * z) as f32 - 1000.0;
                assert_eq!(volume.get(x, y, z), v, "({x}, {y}, {z})");
                let want = DVec3::new(
                    -10.0 + 0.6 * x as f64,
                    20.0 + 0.8 * y as f64,
                    30.0 + 2.5 * z as f64,
                );
                assert!((volume.world_position(x, y, z) - want).length() < 1e-9);
            }
        }
    }
}

/// Checks that `volume` is series B: v + 7, unit spacing from the origin.
fn assert_series_b(volume: &Volume) {
    assert_eq!(volume.dims(), [4, 3, 2]);
    for z in 0..2 {
        for y in 0..3 {
            for x in 0..4 {
                assert_eq!(volume.get(x, y, z), (x + 10 * y + 100 * z + 7) as f32);
            }
        }
    }
    assert_eq!(volume.world_position(3, 2, 1), DVec3::new(3.0, 2.0, 1.0));
}

#[test]
fn a_dicomdir_reads_to_the_same_samples_and_geometry_as_the_flat_folder() {
    let Some(dir) = fixtures() else { return };
    let flat = load(&dir.join("flat"), &ReadOptions::default());
    assert_series_a(&flat.volume);
    for input in [dir.join("cd"), dir.join("cd/DICOMDIR")] {
        let cd = load(&input, &ReadOptions::default());
        assert_series_a(&cd.volume);
        assert_eq!(cd.volume.spacing(), flat.volume.spacing());
        assert_eq!(cd.volume.origin(), flat.volume.origin());
        assert_note(&cd, "read through");
        assert_eq!((cd.info.frames, cd.info.frame), (2, 1));
    }
}

#[test]
fn of_two_series_the_largest_is_read_with_a_note_naming_the_other_and_how_to_pick() {
    let Some(dir) = fixtures() else { return };
    let cd = load(&dir.join("cd"), &ReadOptions::default());
    assert_series_a(&cd.volume);
    let note = (cd.info.notes.iter())
        .find(|n| n.starts_with("2 series; read the largest"))
        .unwrap_or_else(|| panic!("{:?}", cd.info.notes));
    assert!(
        note.contains(
            "2: SeriesNumber 3, CT \"chest\", 5 file(s), 4 x 3, UID 1.2.826.0.1.3680043.10.1234.2"
        ),
        "{note}"
    );
    assert!(
        note.contains("the others: 1: SeriesNumber 1, MR \"scout\", 2 file(s)"),
        "{note}"
    );
    assert!(note.contains("--series"), "{note}");
}

#[test]
fn a_series_is_picked_by_its_number_or_its_uid_and_a_bad_one_names_the_choices() {
    let Some(dir) = fixtures() else { return };
    let cd = dir.join("cd");
    assert_series_b(&load(&cd, &series("1")).volume);
    assert_series_a(&load(&cd, &series("2")).volume);
    let by_uid = load(&cd, &series("1.2.826.0.1.3680043.10.1234.3"));
    assert_series_b(&by_uid.volume);
    assert_note(&by_uid, "series 1 of 2 read, as named");
    // --frame keeps numbering series from 0.
    assert_series_b(&load(&cd, &common::frame(0)).volume);
    for bad in ["3", "0", "1.2.3"] {
        let msg = refused(&cd, &series(bad));
        assert!(
            msg.contains(&format!("no series \"{bad}\": name one by its number (1 to 2) or its UID: 1: SeriesNumber 1, MR")),
            "{msg}"
        );
        assert!(msg.contains("; 2: SeriesNumber 3, CT"), "{msg}");
    }
    // A series of a file that is not DICOM is refused by name.
    let npy = dir.join("a.npy");
    volray_io::write_npy(&npy, &Volume::new([2, 2, 2], vec![0.0; 8]).unwrap()).unwrap();
    let msg = refused(&npy, &series("1"));
    assert!(msg.contains("series selection applies to DICOM"), "{msg}");
}

#[test]
fn subfolders_are_searched_without_a_dicomdir_and_a_link_loop_is_passed_once() {
    let Some(dir) = fixtures() else { return };
    let tree = load(&dir.join("tree"), &ReadOptions::default());
    assert_series_a(&tree.volume);
    assert_note(&tree, "1 file(s) not DICOM (README.txt)");
    assert_note(&tree, "reached a second time through a link");
}

#[test]
fn a_folder_with_no_image_anywhere_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    fs::create_dir_all(dir.path().join("a/b")).unwrap();
    fs::write(dir.path().join("a/b/notes.txt"), "x").unwrap();
    let msg = refused(dir.path(), &ReadOptions::default());
    assert!(
        msg.contains("no DICOM image files in this directory or its subfolders (skipped 1 file(s) not DICOM (a/b/notes.txt))"),
        "{msg}"
    );
}

/// A copy of the fixture `cd` in a new folder, its DICOMDIR replaced by
/// `edit` of its bytes.
fn cd_with(edit: impl FnOnce(&mut Vec<u8>)) -> (tempfile::TempDir, PathBuf) {
    let dir = fixtures().unwrap();
    let copy = tempfile::tempdir().unwrap();
    let cd = copy.path().join("cd");
    copy_tree(&dir.join("cd"), &cd);
    let mut bytes = fs::read(cd.join("DICOMDIR")).unwrap();
    edit(&mut bytes);
    fs::write(cd.join("DICOMDIR"), bytes).unwrap();
    (copy, cd)
}

fn copy_tree(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for e in fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_dir() {
            copy_tree(&e.path(), &to.join(e.file_name()));
        } else {
            fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// Where `needle` first occurs in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len())
        .position(|w| w == needle)
        .expect("present")
}

/// The offset (0004,1200) names: the root's first record.
const ROOT_OFFSET: &[u8] = &[0x04, 0x00, 0x00, 0x12, b'U', b'L', 4, 0];
/// OffsetOfTheNextDirectoryRecord.
const NEXT_OFFSET: &[u8] = &[0x04, 0x00, 0x00, 0x14, b'U', b'L', 4, 0];

fn set_u32(bytes: &mut [u8], at: usize, value: u32) {
    bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
}

/// A change of a DICOMDIR's bytes.
type Edit = Box<dyn FnOnce(&mut Vec<u8>)>;

#[test]
fn malformed_dicomdirs_are_refused_in_one_line_naming_the_dicomdir() {
    if fixtures().is_none() {
        return;
    }
    let cases: Vec<(&str, Edit)> = vec![
        (
            "past the end of its container",
            Box::new(|b: &mut Vec<u8>| {
                let n = b.len() - 7;
                b.truncate(n)
            }),
        ),
        (
            "where no directory record starts",
            Box::new(|b: &mut Vec<u8>| {
                let at = find(b, ROOT_OFFSET) + ROOT_OFFSET.len();
                set_u32(b, at, 0x7FFF_0000)
            }),
        ),
        (
            "the directory records loop",
            Box::new(|b: &mut Vec<u8>| {
                // The first record (the PATIENT) names itself as the next.
                let root = find(b, ROOT_OFFSET) + ROOT_OFFSET.len();
                let first = u32::from_le_bytes(b[root..root + 4].try_into().unwrap());
                let at = find(b, NEXT_OFFSET) + NEXT_OFFSET.len();
                set_u32(b, at, first)
            }),
        ),
        (
            "a DICOMDIR is written in explicit VR little endian",
            Box::new(|b: &mut Vec<u8>| {
                let at = find(b, b"1.2.840.10008.1.2.1");
                b[at + 18] = b'2';
            }),
        ),
    ];
    for (want, edit) in cases {
        let (_keep, cd) = cd_with(edit);
        let err = common::error_about(&cd, &ReadOptions::default(), &cd.join("DICOMDIR"));
        let msg = err.to_string();
        assert!(msg.contains(want), "{msg}\n  wanted: {want}");
        assert!(!err.is_io_failure(), "{msg}");
    }
}

#[test]
fn a_file_the_dicomdir_lists_but_the_disc_lacks_is_named() {
    if fixtures().is_none() {
        return;
    }
    let (_keep, cd) = cd_with(|_| {});
    fs::remove_file(cd.join("PT000000/ST000000/SE000001/IM000003")).unwrap();
    let err = common::error_about(&cd, &ReadOptions::default(), &cd.join("DICOMDIR"));
    assert!(
        err.to_string().contains(
            "DICOMDIR lists file PT000000\\ST000000\\SE000001\\IM000003 (series record at byte"
        ),
        "{err}"
    );
    assert!(err.to_string().contains("which is missing"), "{err}");
}

#[test]
fn lower_case_names_as_a_mounted_disc_shows_them_are_found() {
    if fixtures().is_none() {
        return;
    }
    let (_keep, cd) = cd_with(|_| {});
    let pt = cd.join("PT000000");
    fs::rename(&pt, cd.join("pt000000")).unwrap();
    let series = cd.join("pt000000/ST000000/SE000001");
    fs::rename(series.join("IM000002"), series.join("im000002;1")).unwrap();
    assert_series_a(&load(&cd, &ReadOptions::default()).volume);
}

#[test]
fn every_truncation_of_a_dicomdir_is_refused_or_read_without_panic() {
    let Some(dir) = fixtures() else { return };
    let bytes = fs::read(dir.join("cd/DICOMDIR")).unwrap();
    let (_keep, cd) = cd_with(|_| {});
    for n in (0..bytes.len()).step_by(7) {
        fs::write(cd.join("DICOMDIR"), &bytes[..n]).unwrap();
        if let Err(e) = read(&cd, &ReadOptions::default()) {
            assert!(!e.to_string().contains('\n'), "{e}");
        }
    }
}

/// The label highdicom was given at (x, y, z) (see the fixture script).
fn seg_label(x: usize, y: usize, z: usize) -> f32 {
    if (x, y, z) == (3, 2, 4) {
        3.0
    } else if (1..=2).contains(&x) && y >= 1 && (1..=3).contains(&z) {
        2.0
    } else if x == 0 {
        1.0
    } else {
        0.0
    }
}

#[test]
fn a_segmentation_is_a_label_volume_on_its_source_series_grid() {
    let Some(dir) = fixtures() else { return };
    let source = load(&dir.join("flat"), &ReadOptions::default()).volume;
    for name in ["seg.dcm", "seg_omitted.dcm"] {
        let seg = load(&dir.join(name), &ReadOptions::default());
        let v = &seg.volume;
        assert_eq!(v.dims(), [4, 3, 5], "{name}");
        for z in 0..5 {
            for y in 0..3 {
                for x in 0..4 {
                    assert_eq!(v.get(x, y, z), seg_label(x, y, z), "{name} ({x}, {y}, {z})");
                    assert!(
                        (v.world_position(x, y, z) - source.world_position(x, y, z)).length()
                            < 1e-6,
                        "{name} ({x}, {y}, {z})"
                    );
                }
            }
        }
        let names: Vec<(i64, &str, Option<[u8; 3]>)> = (seg.info.segments.iter())
            .map(|s| (s.label, s.name.as_str(), s.colour))
            .collect();
        let near = |c: Option<[u8; 3]>, want: [u8; 3]| {
            c.is_some_and(|c| (0..3).all(|i| c[i].abs_diff(want[i]) <= 1))
        };
        assert_eq!(names.len(), 3, "{names:?}");
        assert_eq!((names[0].0, names[0].1), (1, "left"));
        assert_eq!((names[1].0, names[1].1), (2, "block"));
        assert_eq!((names[2].0, names[2].1), (3, "corner"));
        assert!(near(names[0].2, [255, 0, 0]), "{names:?}");
        assert!(near(names[1].2, [0, 0, 255]), "{names:?}");
        assert!(near(names[2].2, [128, 64, 200]), "{names:?}");
        assert_note(&seg, "DICOM Segmentation: a label volume");
    }
}

#[test]
fn a_fractional_segmentation_paints_where_the_fraction_exceeds_one_half() {
    let Some(dir) = fixtures() else { return };
    let seg = load(&dir.join("seg_fractional.dcm"), &ReadOptions::default());
    let v = &seg.volume;
    assert_eq!(v.dims(), [4, 3, 5]);
    for z in 0..5 {
        for y in 0..3 {
            for x in 0..4 {
                let want = match (x, y) {
                    (0, _) => 1.0,
                    (3, 2) => 2.0,
                    _ => 0.0,
                };
                assert_eq!(v.get(x, y, z), want, "({x}, {y}, {z})");
            }
        }
    }
    assert_note(&seg, "exceeds half of MaximumFractionalValue 200");
}

#[test]
fn a_segmentation_with_a_short_pixel_data_or_no_segment_is_refused_in_one_line() {
    let Some(dir) = fixtures() else { return };
    let bytes = fs::read(dir.join("seg.dcm")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    // Every truncation: refused (or read), never a panic.
    for n in (0..bytes.len()).step_by(97) {
        let path = tmp.path().join("cut.dcm");
        fs::write(&path, &bytes[..n]).unwrap();
        if let Err(e) = read(&path, &ReadOptions::default()) {
            assert!(!e.to_string().contains('\n'), "{e}");
        }
    }
    // A frame naming segment 0, which no segment can have.
    let mut zero = bytes.clone();
    let tag = [0x62, 0x00, 0x0B, 0x00, b'U', b'S', 2, 0];
    let at = find(&zero, &tag) + tag.len();
    zero[at..at + 2].copy_from_slice(&0u16.to_le_bytes());
    let path = tmp.path().join("zero.dcm");
    fs::write(&path, &zero).unwrap();
    let msg = refused(&path, &ReadOptions::default());
    assert!(
        msg.contains("DICOM Segmentation: frame 0 names segment 0, outside 1..65535"),
        "{msg}"
    );
}

#[test]
fn a_segmentation_in_a_dicomdir_series_is_picked_like_any_series() {
    let Some(dir) = fixtures() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let folder = tmp.path().join("study");
    copy_tree(&dir.join("flat"), &folder);
    fs::copy(dir.join("seg.dcm"), folder.join("seg.dcm")).unwrap();
    // Two series: the CT by default (a segmentation, though it holds more
    // frames, is read only when named), the SEG by its number.
    assert_series_a(&load(&folder, &ReadOptions::default()).volume);
    let seg = load(&folder, &series("2"));
    assert_eq!(seg.volume.get(0, 0, 0), 1.0);
    assert_eq!(seg.info.segments.len(), 3);
}
