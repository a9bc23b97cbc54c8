//! OpenDX, XSF/BXSF and gOpenMol plt grids (formats/opendx.rs, xsf.rs,
//! plt.rs), written at test time by their fields' own tools
//! (`chem_grids/write_files.py`: GridDataFormats, ASE, the documented
//! layouts) and checked against what those tools read back: values at
//! every point, origin and spacing, the arrays and frames a file holds;
//! then lying, truncated and mangled files, refused in one line.

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::{check_resampled, mutations_never_panic, read_or_refuse, refused, truncations};
use volray_core::Volume;
use volray_core::glam::{DMat3, DVec3};
use volray_io::{IoError, Loaded, ReadOptions, VolumeFormat, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["numpy", "gridData", "ase"],
        "tests/chem_grids/write_files.py",
    )
}

fn load_with(path: &Path, opts: &ReadOptions) -> Loaded {
    read(path, opts).unwrap_or_else(|e| panic!("{e}"))
}

fn load(path: &Path) -> Loaded {
    load_with(path, &ReadOptions::default())
}

/// What the writing tool read back (`NAME.json`).
fn oracle(dir: &Path, name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join(format!("{name}.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn vec3(v: &serde_json::Value) -> DVec3 {
    DVec3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

fn close(a: DVec3, b: DVec3) {
    assert!((a - b).length() < 1e-6, "{a} vs {b}");
}

/// Every voxel (x, y, z) holds the oracle's `values` (a[x, y, z] raveled
/// x fastest) within `tol`.
fn same_values(vol: &Volume, want: &serde_json::Value, tol: f32) {
    let shape: Vec<usize> = (want["shape"].as_array().unwrap().iter())
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(vol.dims().to_vec(), shape);
    let values = want["values"].as_array().unwrap();
    let [nx, ny, nz] = vol.dims();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let w = values[i + nx * (j + ny * k)].as_f64().unwrap() as f32;
                let got = vol.get(i, j, k);
                assert!((got - w).abs() <= tol, "({i}, {j}, {k}): {got} vs {w}");
            }
        }
    }
}

#[test]
fn opendx_from_griddata_reads_with_its_origin_deltas_and_values() {
    let Some(dir) = files() else { return };
    let want = oracle(dir, "ramp.dx");
    for name in ["ramp.dx", "ramp_dx.gz"] {
        let l = load(&dir.join(name));
        assert_eq!(l.format, VolumeFormat::Dx, "{name}");
        same_values(&l.volume, &want, 0.0);
        close(l.volume.origin(), vec3(&want["origin"]));
        let delta = &want["delta"];
        let spacing = DVec3::new(
            delta[0][0].as_f64().unwrap(),
            delta[1][1].as_f64().unwrap(),
            delta[2][2].as_f64().unwrap(),
        );
        close(l.volume.spacing(), spacing);
        // GridDataFormats names a float64 array's type "double".
        assert_eq!(l.info.stored_type, "decimal text (double)");
        assert_eq!(l.info.length_unit, None);
    }
    // Known by content under a name that says nothing.
    let renamed = dir.join("potential.data");
    std::fs::copy(dir.join("ramp.dx"), &renamed).unwrap();
    assert_eq!(load(&renamed).format, VolumeFormat::Dx);
}

#[test]
fn an_apbs_style_opendx_file_reads_past_its_comments_and_trailer() {
    let Some(dir) = files() else { return };
    let l = load(&dir.join("apbs.dx"));
    same_values(&l.volume, &oracle(dir, "apbs.dx"), 1e-5);
    close(l.volume.spacing(), DVec3::new(1.5, 1.0, 1.0));
    close(l.volume.origin(), DVec3::new(-1.5, -2.0, -0.5));
    assert_eq!(l.info.stored_type, "decimal text (double)");
}

#[test]
fn xsf_from_ase_reads_as_ase_reads_it_back() {
    let Some(dir) = files() else { return };
    let want = oracle(dir, "ramp.xsf");
    let l = load(&dir.join("ramp.xsf"));
    assert_eq!(l.format, VolumeFormat::Xsf);
    same_values(&l.volume, &want, 1e-6);
    close(l.volume.origin(), vec3(&want["origin"]));
    // A general grid: point i of n at i/(n-1) of the spanning vector.
    let spans = &want["spans"];
    let steps = DVec3::new(
        spans[0][0].as_f64().unwrap() / 3.0,
        spans[1][1].as_f64().unwrap() / 2.0,
        spans[2][2].as_f64().unwrap() / 4.0,
    );
    close(l.volume.spacing(), steps);
    assert_eq!(l.info.length_unit.as_deref(), Some("angstrom"));
    assert_eq!(l.info.arrays, ["grid#1"]);
}

#[test]
fn a_skewed_xsf_cell_is_resampled_as_one_periodic_cell() {
    let Some(dir) = files() else { return };
    let want = oracle(dir, "hexagonal.xsf");
    let l = load(&dir.join("hexagonal.xsf"));
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("periodic cell") && n.contains("6 x 6 x 4 points make the cell")),
        "{:?}",
        l.info.notes
    );
    // The file's function of the grid coordinates (write_files.py), at
    // every voxel inside the cell's first period.
    let spans = &want["spans"];
    let steps = DMat3::from_cols(
        vec3(&spans[0]) / 6.0,
        vec3(&spans[1]) / 6.0,
        vec3(&spans[2]) / 4.0,
    );
    let tau = std::f64::consts::TAU;
    let f = |g: DVec3| (tau * g.x / 6.0).cos() + (tau * g.y / 6.0).sin() + g.z;
    let checked = check_resampled(&l.volume, steps.inverse(), [5.0, 5.0, 3.0], 0.35, f);
    assert!(checked > 50, "{checked}");
}

#[test]
fn several_xsf_grids_are_arrays_and_band_grids_hold_bands_as_frames() {
    let Some(dir) = files() else { return };
    let two = dir.join("two.xsf");
    let l = load(&two);
    assert_eq!(l.info.arrays, ["density", "potential"]);
    assert_eq!(l.info.array.as_deref(), Some("density"));
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("read the grid \"density\" (the first) of the 2"))
    );
    assert_eq!(l.volume.get(2, 3, 4), 432.0);
    let opts = ReadOptions {
        array: Some("potential".into()),
        ..ReadOptions::default()
    };
    assert_eq!(load_with(&two, &opts).volume.get(2, 3, 4), -432.0);
    let opts = ReadOptions {
        array: Some("spin".into()),
        ..ReadOptions::default()
    };
    let err = read(&two, &opts).unwrap_err();
    assert!(matches!(err, IoError::NoSuchArray { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("the file holds the grids \"density\", \"potential\""),
        "{err}"
    );

    let fermi = dir.join("fermi.bxsf");
    let band = |f: usize| load_with(&fermi, &common::frame(f));
    let l = band(1);
    assert_eq!((l.info.frames, l.info.frame), (2, 1));
    assert!((l.volume.get(2, 1, 3) - (312.0 * 0.1 + 5.0)).abs() < 1e-4);
    assert!((band(0).volume.get(2, 1, 3) - 31.2).abs() < 1e-4);
    close(l.volume.spacing(), DVec3::new(0.5, 0.5, 0.5));
    assert_eq!(l.info.length_unit, None);
    let err = read(&fermi, &common::frame(2)).unwrap_err();
    common::assert_frame_out_of_range(
        &err,
        2,
        "the band grid \"BANDS\" holds 2 band(s) (frames 0 to 1)",
    );
}

#[test]
fn gopenmol_plt_in_either_byte_order_holds_what_griddata_reads() {
    let Some(dir) = files() else { return };
    for name in ["little.plt", "big.plt"] {
        let want = oracle(dir, name);
        let l = load(&dir.join(name));
        assert_eq!(l.format, VolumeFormat::Plt);
        same_values(&l.volume, &want, 0.0);
        let h = &want["header"];
        let f = |k: &str| h[k].as_f64().unwrap();
        // min to max inclusive along each axis.
        close(
            l.volume.origin(),
            DVec3::new(f("xmin"), f("ymin"), f("zmin")),
        );
        let spacing = DVec3::new(
            (f("xmax") - f("xmin")) / 3.0,
            (f("ymax") - f("ymin")) / 2.0,
            (f("zmax") - f("zmin")) / 4.0,
        );
        close(l.volume.spacing(), spacing);
        assert!(
            l.info
                .stored_type
                .contains(if name == "big.plt" { "big" } else { "little" })
        );
        let renamed = dir.join(format!("{name}.bin"));
        std::fs::copy(dir.join(name), &renamed).unwrap();
        assert_eq!(
            load(&renamed).format,
            VolumeFormat::Plt,
            "{name} by content"
        );
    }
}

/// Writes `text` as `name` in a new directory and expects a refusal
/// containing `want`.
fn refuse_text(name: &str, text: &[u8], want: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    let msg = refused(&path, &ReadOptions::default());
    assert!(msg.contains(want), "{msg}\n  wanted: {want}");
}

const DX_HEAD: &str = "object 1 class gridpositions counts 2 2 2\norigin 0 0 0\ndelta 1 0 0\ndelta 0 1 0\ndelta 0 0 1\n";

#[test]
fn lying_and_broken_opendx_files_are_refused_in_one_line() {
    let array = "object 3 class array type double rank 0 items 8 data follows\n";
    let good = format!("{DX_HEAD}{array}1 2 3 4 5 6 7 8\n");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ok.dx");
    std::fs::write(&path, &good).unwrap();
    assert_eq!(load(&path).volume.get(1, 1, 1), 8.0);
    let huge = "object 1 class gridpositions counts 100000 100000 100000\norigin 0 0 0\ndelta 1 0 0\ndelta 0 1 0\ndelta 0 0 1\nobject 3 class array type double rank 0 items 1000000000000000 data follows\n1\n";
    refuse_text("huge.dx", huge.as_bytes(), "more values than a");
    refuse_text(
        "items.dx",
        format!("{DX_HEAD}object 3 class array type double rank 0 items 9 data follows\n")
            .as_bytes(),
        "holds 9 items but the grid 2 x 2 x 2 has 8 points",
    );
    refuse_text(
        "short.dx",
        format!("{DX_HEAD}{array}1 2 3\n").as_bytes(),
        "after 3 of the 8 values of the data array",
    );
    refuse_text(
        "word.dx",
        format!("{DX_HEAD}{array}1 2 3 x 5 6 7 8\n").as_bytes(),
        "data value: \"x\" is not a number",
    );
    refuse_text(
        "binary.dx",
        format!("{DX_HEAD}object 3 class array type float rank 0 items 8 msb ieee data 0\n")
            .as_bytes(),
        "volray reads OpenDX values written as text",
    );
    refuse_text(
        "vector.dx",
        format!("{DX_HEAD}object 3 class array type float rank 1 shape 3 items 8 data follows\n")
            .as_bytes(),
        "rank 1 (shape 3)",
    );
    refuse_text("two_deltas.dx", b"object 1 class gridpositions counts 2 2 2\norigin 0 0 0\ndelta 1 0 0\ndelta 0 1 0\nobject 3 class array type double rank 0 items 8 data follows\n", "2 delta line(s)");
    refuse_text(
        "no_grid.dx",
        b"object 1 class gridpositions counts 2 2\n",
        "volray reads 3-D grids",
    );
    refuse_text(
        "nan.dx",
        b"object 1 class gridpositions counts 2 2 2\norigin 0 nan 0\n",
        "origin",
    );
}

#[test]
fn lying_and_broken_xsf_and_plt_files_are_refused_in_one_line() {
    let grid = |counts: &str, values: &str| {
        format!(
            "BEGIN_BLOCK_DATAGRID_3D\n c\n BEGIN_DATAGRID_3D_rho\n {counts}\n 0 0 0\n 1 0 0\n 0 1 0\n 0 0 1\n{values}\n END_DATAGRID_3D\nEND_BLOCK_DATAGRID_3D\n"
        )
    };
    refuse_text(
        "huge.xsf",
        grid("100000 100000 100000", "1").as_bytes(),
        "holds more values than a",
    );
    refuse_text(
        "short.xsf",
        grid("2 2 2", "1 2 3").as_bytes(),
        "END_DATAGRID_3D after 3 of the 8 values of the grid \"rho\"",
    );
    refuse_text(
        "long.xsf",
        grid("2 2 2", "1 2 3 4 5 6 7 8\n 9").as_bytes(),
        "where END_DATAGRID_3D should end the grid \"rho\"",
    );
    refuse_text(
        "counts.xsf",
        grid("2 2", "1").as_bytes(),
        "expected the point counts nx ny nz",
    );
    refuse_text(
        "none.xsf",
        b"CRYSTAL\nPRIMVEC\n 1 0 0\n 0 1 0\n 0 0 1\n",
        "no 3-D data grid",
    );

    let plt = |words: [i32; 5], bounds: [f32; 6], values: usize| {
        let mut out: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        out.extend(bounds.iter().flat_map(|b| b.to_le_bytes()));
        out.extend(std::iter::repeat_n(0u8, 4 * values));
        out
    };
    let b = [0.0, 1.0, 0.0, 1.0, 0.0, 1.0];
    refuse_text(
        "huge.plt",
        &plt([3, 200, 100000, 100000, 100000], b, 8),
        "but the file holds 76 bytes",
    );
    refuse_text(
        "short.plt",
        &plt([3, 200, 2, 2, 2], b, 7),
        "the header declares 2 x 2 x 2 float32 values (76 bytes with the header), but the file holds 72 bytes",
    );
    refuse_text(
        "rank.plt",
        &plt([4, 200, 2, 2, 2], b, 8),
        "not a gOpenMol plt file (rank 3)",
    );
    refuse_text(
        "text.plt",
        b"3 2\n65 65 65\n-3.3e+01 3.2e+01 -3.3e+01 3.2e+01 -3.3e+01 3.2e+01\n",
        "a formatted (text) plt file",
    );
    refuse_text(
        "flat.plt",
        &plt([3, 200, 2, 2, 2], [0.0, 1.0, 0.5, 0.5, 0.0, 1.0], 8),
        "ymin = ymax = 0.5",
    );
    refuse_text(
        "count.plt",
        &plt([3, 200, 2, -2, 2], b, 8),
        "-2 is not a count",
    );
}

#[test]
fn truncated_and_mangled_fixtures_never_panic() {
    let Some(dir) = files() else { return };
    let scratch = tempfile::tempdir().unwrap();
    let names = [
        "ramp.dx",
        "apbs.dx",
        "ramp.xsf",
        "two.xsf",
        "fermi.bxsf",
        "hexagonal.xsf",
        "little.plt",
        "big.plt",
    ];
    for name in names {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let path = scratch.path().join(name);
        for cut in truncations(&bytes, 97) {
            std::fs::write(&path, cut).unwrap();
            read_or_refuse(&path, &ReadOptions::default());
        }
    }
    let files: Vec<PathBuf> = names.iter().map(|n| dir.join(n)).collect();
    mutations_never_panic(&files[..2], "m.dx", 7);
    mutations_never_panic(&files[2..6], "m.xsf", 8);
    mutations_never_panic(&files[6..], "m.plt", 9);
}
