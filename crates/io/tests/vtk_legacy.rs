//! Reads legacy `.vtk` STRUCTURED_POINTS files written by VTK's own
//! vtkStructuredPointsWriter (see `fixtures/make_vtk_fixtures.py`) and
//! checks every value, the geometry, the array choice and `FileInfo`; then
//! checks that broken files made here are refused with specific messages.
//!
//! Every image has 4 x 3 x 5 points, spacing (0.5, 2, 1.5), origin
//! (-1, 2, 3); point arrays hold ramp(i, j, k) = i + 10j + 100k through the
//! script's per-type formula, cell arrays c = i + 10j + 100k + 0.5 on the
//! 3 x 2 x 4 cells.

mod common;

use std::path::PathBuf;

use common::{check_voxels, header_value, ramp, refused_file, typed, with_array};
use volray_core::glam::DVec3;
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn fixture(name: &str) -> PathBuf {
    common::fixture("vtk", name)
}

fn read_with(name: &str, array: Option<&str>) -> Result<Loaded, IoError> {
    read(&fixture(name), &with_array(array))
}

fn load(name: &str, array: Option<&str>) -> Loaded {
    let l = read_with(name, array).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.format, VolumeFormat::VtkLegacy);
    l
}

/// The point grid of every fixture, and every value against `want`.
fn check_points(name: &str, l: &Loaded, want: impl Fn(usize, usize, usize) -> f32) {
    let vol = &l.volume;
    assert_eq!(vol.dims(), [4, 3, 5], "{name}");
    assert_eq!(vol.spacing(), DVec3::new(0.5, 2.0, 1.5), "{name}");
    assert_eq!(vol.origin(), DVec3::new(-1.0, 2.0, 3.0), "{name}");
    check_voxels(name, vol, [4, 3, 5], want);
}

/// The cell-centre grid: 3 x 2 x 4 voxels half a step inside.
fn check_cells(name: &str, l: &Loaded) {
    let vol = &l.volume;
    assert_eq!(vol.dims(), [3, 2, 4], "{name}");
    assert_eq!(vol.spacing(), DVec3::new(0.5, 2.0, 1.5), "{name}");
    assert_eq!(vol.origin(), DVec3::new(-0.75, 3.0, 3.75), "{name}");
    check_voxels(name, vol, [3, 2, 4], |i, j, k| ramp(i, j, k) as f32 + 0.5);
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("3x2x4 cells") && n.contains("cell centres")),
        "{:?}",
        l.info.notes
    );
}

#[test]
fn every_sample_type_in_binary_files() {
    let types = [
        ("u8", "unsigned_char"),
        ("i8", "signed_char"),
        ("u16", "unsigned_short"),
        ("i16", "short"),
        ("u32", "unsigned_int"),
        ("i32", "int"),
        ("u64", "unsigned_long"),
        ("i64", "long"),
        ("f32", "float"),
        ("f64", "double"),
    ];
    for (name, vtk_type) in types {
        let file = format!("legacy_{name}.vtk");
        let l = load(&file, None);
        check_points(&file, &l, |i, j, k| typed(name, ramp(i, j, k)));
        assert_eq!(
            l.info.stored_type,
            format!("{vtk_type} (big-endian)"),
            "{file}"
        );
        assert_eq!(l.info.arrays, ["v"]);
        assert_eq!(l.info.array.as_deref(), Some("v"));
        assert_eq!((l.info.frames, l.info.frame), (1, 0));
        assert_eq!(header_value(&l, "version"), "5.1");
        assert_eq!(header_value(&l, "file type"), "BINARY");
        assert_eq!(header_value(&l, "DIMENSIONS"), "4 3 5");
        assert_eq!(header_value(&l, "SPACING"), "0.5 2 1.5");
        assert_eq!(header_value(&l, "ORIGIN"), "-1 2 3");
        assert_eq!(header_value(&l, "POINT_DATA"), "60");
        assert!(
            l.info
                .notes
                .iter()
                .any(|n| n.contains("\"v\" (the active scalars)")),
            "{:?}",
            l.info.notes
        );
    }
}

#[test]
fn ascii_files_of_several_versions() {
    for name in ["f32", "f64", "i16", "u8"] {
        let file = format!("legacy_{name}_ascii.vtk");
        let l = load(&file, None);
        check_points(&file, &l, |i, j, k| typed(name, ramp(i, j, k)));
        assert!(
            l.info.stored_type.ends_with("(ASCII)"),
            "{}",
            l.info.stored_type
        );
    }
    // unsigned_char scalars are written as COLOR_SCALARS: floats v/255 in
    // ASCII, turned back into the bytes.
    let l = load("legacy_u8_ascii.vtk", None);
    assert_eq!(header_value(&l, "COLOR_SCALARS"), "v 1");
    let l = load("legacy_v42_ascii.vtk", None);
    check_points("v42", &l, |i, j, k| typed("f32", ramp(i, j, k)));
    assert_eq!(header_value(&l, "version"), "4.2");
}

#[test]
fn several_arrays_default_and_by_name() {
    for file in ["legacy_multi_ascii.vtk", "legacy_multi_binary.vtk"] {
        // Default: the point SCALARS, although CELL_DATA comes first.
        let l = load(file, None);
        check_points(file, &l, |i, j, k| typed("f32", ramp(i, j, k)));
        assert_eq!(
            l.info.arrays,
            ["cells", "ramp", "velocity", "other", "pair a"]
        );
        assert_eq!(l.info.array.as_deref(), Some("ramp"));

        // A FIELD array after the VECTORS and before a METADATA block.
        let l = load(file, Some("other"));
        check_points(file, &l, |i, j, k| typed("u8", ramp(i, j, k)));
        assert!(
            l.info.stored_type.starts_with("unsigned_char"),
            "{}",
            l.info.stored_type
        );
        assert!(l.info.notes.iter().any(|n| n.contains("the one asked for")));

        // Cell data becomes a grid of cell centres.
        for name in ["cells", "cell:cells"] {
            let l = load(file, Some(name));
            check_cells(file, &l);
            assert_eq!(l.info.array.as_deref(), Some("cells"));
        }

        // Vectors and two-component arrays are refused, naming the scalars.
        for (name, n) in [("velocity", 3), ("pair a", 2)] {
            let msg = read_with(file, Some(name)).unwrap_err().to_string();
            assert!(
                msg.contains(&format!("point array \"{name}\" has {n} components"))
                    && msg.contains("(cells, ramp, other)"),
                "{msg}"
            );
        }
        for name in ["nope", "point:cells"] {
            let err = read_with(file, Some(name)).unwrap_err();
            assert!(!err.is_io_failure());
            assert!(matches!(&err, IoError::NoSuchArray { .. }), "{err}");
            let msg = err.to_string();
            assert!(
                msg.contains(&format!("no array named \"{name}\""))
                    && msg.contains("cell arrays \"cells\" (double)"),
                "{msg}"
            );
        }
    }
}

#[test]
fn cell_data_only() {
    let l = load("legacy_cells_only.vtk", None);
    check_cells("legacy_cells_only.vtk", &l);
    assert_eq!(l.info.stored_type, "double (big-endian)");
}

// ---- broken files ----

fn error_for(bytes: &[u8]) -> String {
    refused_file("bad.vtk", bytes, &ReadOptions::default())
}

const HEAD: &str =
    "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n";

fn ascii(body: &str) -> Vec<u8> {
    format!("{HEAD}{body}").into_bytes()
}

#[test]
fn hand_written_ascii_file_reads() {
    // No SPACING or ORIGIN (defaults 1 and 0), lower-case keywords, an
    // encoded name, extra whitespace, and a lookup table after the data.
    let text = ascii(
        "point_data 8\nscalars a%20b int\nlookup_table default\n 1 2 3 4\n\n5 6 7 8\nLOOKUP_TABLE default 2\n0 0 0 1 1 1 1 1\n",
    );
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("small.vtk");
    std::fs::write(&p, &text).unwrap();
    let l = read(&p, &ReadOptions::default()).unwrap();
    assert_eq!(*l.volume.values(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    assert_eq!(l.volume.spacing(), DVec3::ONE);
    assert_eq!(l.volume.origin(), DVec3::ZERO);
    assert_eq!(l.info.arrays, ["a b"]);

    // Negative spacing: the grid is flipped to run along +x, positions kept.
    let text = ascii(
        "SPACING -2 1 1\nPOINT_DATA 8\nSCALARS a float\nLOOKUP_TABLE default\n1 2 3 4 5 6 7 8\n",
    );
    std::fs::write(&p, &text).unwrap();
    let l = read(&p, &ReadOptions::default()).unwrap();
    assert_eq!(l.volume.origin(), DVec3::new(-2.0, 0.0, 0.0));
    assert_eq!(*l.volume.values(), [2.0, 1.0, 4.0, 3.0, 6.0, 5.0, 8.0, 7.0]);
}

#[test]
fn truncated_binary_data() {
    let bytes = std::fs::read(fixture("legacy_f64.vtk")).unwrap();
    let msg = error_for(&bytes[..bytes.len() - 20]);
    assert!(
        msg.contains(
            "BINARY data of array \"v\" (60 double values) needs 480 bytes, but only 461 are left"
        ),
        "{msg}"
    );
}

#[test]
fn lying_counts_are_refused_before_allocating() {
    // Huge DIMENSIONS with a matching POINT_DATA: the values cannot fit.
    let text = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 100000\nPOINT_DATA 1000000000000000\nSCALARS a double\nLOOKUP_TABLE default\n\0\0";
    let msg = error_for(text.as_bytes());
    assert!(
        msg.contains("needs 8000000000000000 bytes, but only 2 are left"),
        "{msg}"
    );
    let msg = error_for(text.replace("BINARY", "ASCII").as_bytes());
    assert!(msg.contains("cannot fit in the 3 bytes left"), "{msg}");
    // A FIELD array that claims more tuples than the file holds.
    let msg = error_for(&ascii(
        "POINT_DATA 8\nFIELD f 1\nx 1 99999999 float\n1 2 3\n",
    ));
    assert!(
        msg.contains("array \"x\" (99999999 values) cannot fit"),
        "{msg}"
    );
}

#[test]
fn malformed_files() {
    let cases: [(&[u8], &str); 14] = [
        (b"hello\n", "first line is \"hello\""),
        (b"# vtk DataFile Version 3.0\n", "where the title should be"),
        (
            b"# vtk DataFile Version 3.0\nt\nTEXT\n",
            "file type (third line) is \"TEXT\"",
        ),
        (
            b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n",
            "DATASET POLYDATA: volray reads STRUCTURED_POINTS",
        ),
        (
            &ascii("POINT_DATA 7\n"),
            "POINT_DATA 7, but DIMENSIONS 2 2 2 make 8 points",
        ),
        (
            &ascii("CELL_DATA 2\n"),
            "CELL_DATA 2, but DIMENSIONS 2 2 2 make 1 cells",
        ),
        (
            &ascii("SPACING 1 0 1\n"),
            "SPACING 1 0 1: spacings must be finite and non-zero",
        ),
        (&ascii("BOGUS 1\n"), "unexpected \"BOGUS\""),
        (
            &ascii("POINT_DATA 8\nWEIRD a\n"),
            "unknown keyword \"WEIRD\" in the POINT_DATA section",
        ),
        (
            &ascii("POINT_DATA 8\nSCALARS a strange\n"),
            "data type \"strange\"",
        ),
        (
            &ascii("POINT_DATA 8\nSCALARS a float\n1 2\n"),
            "followed by \"2\", not LOOKUP_TABLE",
        ),
        (
            &ascii("POINT_DATA 8\nSCALARS a float\nLOOKUP_TABLE default\n1 2 x 4 5 6 7 8\n"),
            "value 2 of array \"a\" is \"x\": not a valid float value",
        ),
        (
            &ascii("POINT_DATA 8\nSCALARS a float\nLOOKUP_TABLE default\n1 2 3 4 5 6 7\n"),
            "ends after 7 of 8 values",
        ),
        (
            &ascii("POINT_DATA 8\nFIELD f 1\nnames 1 8 string\n"),
            "holds string values",
        ),
    ];
    for (bytes, want) in cases {
        let msg = error_for(bytes);
        assert!(msg.contains(want), "{msg} (wanted {want})");
    }
    let msg = error_for(
        b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nPOINT_DATA 8\n",
    );
    assert!(msg.contains("POINT_DATA comes before DIMENSIONS"), "{msg}");
    for section in ["POINT_DATA", "CELL_DATA"] {
        let text = format!(
            "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4294967297 4294967297 4294967297\n{section} 5\n"
        );
        let msg = error_for(text.as_bytes());
        assert!(msg.contains("make too many"), "{msg}");
    }
    let msg = error_for(&ascii(""));
    assert!(
        msg.contains(
            "no one-component point or cell array to render: the file holds no point or cell arrays"
        ),
        "{msg}"
    );
    let msg = error_for(&ascii(
        "POINT_DATA 8\nVECTORS v float\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n",
    ));
    assert!(
        msg.contains("point arrays \"v\" (3 components, float)"),
        "{msg}"
    );
}

/// Deterministic byte flips and truncations of a few fixtures, each read
/// for its default, cell and field array: a volume or a one-line message,
/// never a panic.
#[test]
fn no_panic_on_truncation_or_corruption() {
    let fixtures = [
        "legacy_multi_binary.vtk",
        "legacy_multi_ascii.vtk",
        "legacy_u8.vtk",
    ]
    .map(fixture);
    common::byte_flips_never_panic(
        &fixtures,
        0x9e37_79b9_7f4a_7c15,
        &[
            ReadOptions::default(),
            with_array(Some("cells")),
            with_array(Some("other")),
        ],
    );
}
