//! DICOM file-sets and segmentations through the binary: `volray info`
//! on a CD's folder (`dicom/cd`: a DICOMDIR and two series, written by
//! pydicom's FileSet) and on a highdicom Segmentation (`dicom/seg.dcm`),
//! `--series`, and the overwrite check seeing the files a folder's
//! subfolders hold (`fixtures/make_dicom_cd_fixtures.py`).

use std::fs;

mod common;
use common::{stderr, stdout, volray};

const CD: &str = "crates/io/tests/fixtures/dicom/cd";
const SEG: &str = "crates/io/tests/fixtures/dicom/seg.dcm";

#[test]
fn info_on_a_cd_reads_the_largest_series_and_lists_the_other() {
    let out = volray(&["info", CD]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for expect in [
        "dims:      4 x 3 x 5",
        "read through crates/io/tests/fixtures/dicom/cd/DICOMDIR (2 series listed)",
        "2 series; read the largest, 2: SeriesNumber 1, CT, 5 file(s), 4 x 3, UID",
        "the others: 1: SeriesNumber 1, CT \"series B\", 2 file(s), 4 x 3, UID",
        "--series N|UID",
        // Series of their own grids: neither time points nor channels.
        "series:    2 (read: 2, counted from 1; --series N or a SeriesInstanceUID picks another",
    ] {
        assert!(text.contains(expect), "missing {expect:?} in\n{text}");
    }
    assert!(!text.contains("time points:"), "{text}");
    let dicomdir = format!("{CD}/DICOMDIR");
    let out = volray(&["info", &dicomdir, "--series", "1", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["dims"], serde_json::json!([4, 3, 2]));
    assert_eq!(
        (v["frames"].clone(), v["frame"].clone()),
        (2.into(), 0.into())
    );
}

#[test]
fn a_series_the_cd_lacks_is_refused_in_one_line_naming_the_choices() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let out = volray(&["render", CD, "--series", "7", "-o", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains(
            "no series \"7\": name one by its number (1 to 2) or its UID: 1: SeriesNumber 1"
        ),
        "{err}"
    );
    assert!(!png.exists());
    let out = volray(&["info", "sphere:8", "--series", "1"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
}

#[test]
fn a_segmentation_renders_as_labels_and_info_names_its_segments() {
    let out = volray(&["info", SEG]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for expect in [
        "dims:      4 x 3 x 5",
        "segments:  1 \"bone\" #FF0000, 2 \"vessel\" #0000FF",
        "DICOM Segmentation: a label volume",
    ] {
        assert!(text.contains(expect), "missing {expect:?} in\n{text}");
    }
    let out = volray(&["info", SEG, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["segments"][1]["name"], "vessel");
    assert_eq!(v["segments"][1]["color"], "0000FF");
    // --labels takes the segments' colours: "bone" red and "vessel" blue,
    // which neither palette colour of labels 1 and 2 (orange, green) is.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("seg.png");
    let out = volray(&[
        "render",
        SEG,
        "--labels",
        "--size",
        "48",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let pixels = rgb_pixels(&png);
    // The vessel is one voxel column at the grid's edge, seen partly
    // mixed with the red: more blue than red and green is enough.
    let bluish = |&[r, g, b]: &[u8; 3]| b > 40 && b > r.max(g).saturating_add(10);
    let reddish = |&[r, g, b]: &[u8; 3]| r > 40 && u16::from(r) > 2 * u16::from(g.max(b));
    assert!(
        pixels.iter().any(bluish),
        "no blue pixel: the file's colours unused"
    );
    assert!(
        pixels.iter().any(reddish),
        "no red pixel: the file's colours unused"
    );
}

/// The RGB pixels of an 8-bit PNG.
fn rgb_pixels(path: &std::path::Path) -> Vec<[u8; 3]> {
    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(
        (info.color_type, info.bit_depth),
        (png::ColorType::Rgb, png::BitDepth::Eight)
    );
    buf[..info.buffer_size()]
        .chunks(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

#[test]
fn the_output_may_not_be_a_file_of_a_searched_subfolder() {
    let dir = tempfile::tempdir().unwrap();
    let series = dir.path().join("study/a/b");
    fs::create_dir_all(&series).unwrap();
    for e in fs::read_dir("crates/io/tests/fixtures/dicom/ct").unwrap() {
        let p = e.unwrap().path();
        fs::copy(&p, series.join(p.file_name().unwrap())).unwrap();
    }
    let png = series.join("preview.png");
    fs::write(&png, b"not yet a picture").unwrap();
    let study = dir.path().join("study");
    let out = volray(&[
        "render",
        study.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("refusing to overwrite"),
        "{}",
        stderr(&out)
    );
    assert_eq!(fs::read(&png).unwrap(), b"not yet a picture");
}
