//! `volray info`, the reader options (--format, --frame, --array) and the
//! OpenEXR output, as a user meets them.

use std::fs;
use std::path::Path;

mod common;
use common::{stderr, stdout, volray};

const C_F4: &str = "crates/io/tests/fixtures/c_f4.npy";

#[test]
fn info_describes_a_file_and_what_its_header_said() {
    let out = volray(&["info", C_F4, "--bins", "3"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for expect in [
        "format:    NumPy .npy",
        "stored as: <f4",
        "dims:      2 x 3 x 4 (24 points)",
        "fortran_order: False",
        "transposed to x fastest",
        "(3 bins)",
    ] {
        assert!(text.contains(expect), "missing {expect:?} in\n{text}");
    }
}

#[test]
fn info_json_has_the_values_histogram() {
    // The fixture holds a[x, y, z] = x + 10y + 100z (make_npy_fixtures.py).
    let out = volray(&["info", C_F4, "--json", "--bins", "4"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["dims"], serde_json::json!([2, 3, 4]));
    assert_eq!(v["values"]["min"], 0.0);
    assert_eq!(v["values"]["max"], 321.0);
    let counts: Vec<u64> = serde_json::from_value(v["values"]["counts"].clone()).unwrap();
    assert_eq!(counts.len(), 4);
    assert_eq!(counts.iter().sum::<u64>(), 24);
    // Mean of x + 10y + 100z over x<2, y<3, z<4: 0.5 + 10 + 150.
    assert!((v["values"]["mean"].as_f64().unwrap() - 160.5).abs() < 1e-9);
    assert_eq!(v["format"], "NumPy .npy");
}

#[test]
fn info_on_a_built_in_source() {
    let out = volray(&["info", "sphere:9"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("format:    built-in source"), "{text}");
    assert!(text.contains("spacing:   0.25, 0.25, 0.25"), "{text}");
}

#[test]
fn format_frame_and_array_options() {
    let dir = tempfile::tempdir().unwrap();
    // A .npy file under a name that says nothing is known by its magic,
    // and --format npy reads it too.
    let renamed = dir.path().join("volume.dat");
    fs::copy(C_F4, &renamed).unwrap();
    let r = renamed.to_str().unwrap();
    for args in [vec!["info", r], vec!["info", r, "--format", "npy"]] {
        let out = volray(&args);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        assert!(stdout(&out).contains("2 x 3 x 4"));
    }
    let refused = |args: &[&str], expect: &str| {
        let out = volray(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        let err = stderr(&out);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(expect), "{args:?}: {err}");
    };
    refused(&["info", r, "--format", "jpeg"], "unknown format 'jpeg'");
    refused(
        &["info", C_F4, "--frame", "1"],
        "--frame does not apply to NumPy .npy files",
    );
    refused(
        &["info", C_F4, "--array", "rho"],
        "--array applies to VTK files and OME-Zarr plates and collections only",
    );
    refused(
        &["info", "sphere:9", "--format", "npy"],
        "apply to files only",
    );
    let unknown = dir.path().join("noise.dat");
    fs::write(&unknown, [1u8; 64]).unwrap();
    refused(
        &["info", unknown.to_str().unwrap()],
        "unknown volume format",
    );
}

/// Reads an RGBA OpenEXR file: (width, height, pixels row-major from the top).
fn read_exr(path: &Path) -> (usize, usize, Vec<[f32; 4]>) {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0f32; 4]; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<[f32; 4]>), Vec2(x, y), (r, g, b, a): (f32, f32, f32, f32)| {
            px[y * *w + x] = [r, g, b, a]
        },
    )
    .unwrap();
    let size = image.layer_data.size;
    (
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    )
}

#[test]
fn exr_output_holds_the_unquantised_frame() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("f.exr");
    let png = dir.path().join("f.png");
    let common = ["render", "sphere:16", "--size", "24x20"];
    for (out, extra) in [(&exr, vec![]), (&png, vec!["--bit-depth", "16"])] {
        let mut args: Vec<&str> = common.to_vec();
        args.extend(["-o", out.to_str().unwrap()]);
        args.extend(extra);
        let o = volray(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let (w, h, px) = read_exr(&exr);
    assert_eq!((w, h), (24, 20));
    // The 16-bit PNG is the same frame rounded to 1/65535.
    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    let mut covered = 0;
    for (n, p) in px.iter().enumerate() {
        for (c, value) in p[..3].iter().enumerate() {
            let b = 2 * (3 * n + c);
            let q = f32::from(u16::from_be_bytes([buf[b], buf[b + 1]])) / 65535.0;
            assert!(
                (value.clamp(0.0, 1.0) - q).abs() <= 0.5 / 65535.0 + 1e-7,
                "pixel {n}"
            );
        }
        assert!((0.0..=1.0).contains(&p[3]));
        if p[3] > 0.5 {
            covered += 1;
        }
    }
    // The ball covers the middle of the picture, not the corners.
    assert!(covered > 20 && px[0][3] < 1e-6, "{covered}");

    let o = volray(&[
        "render",
        "sphere:8",
        "-o",
        dir.path().join("g.exr").to_str().unwrap(),
        "--bit-depth",
        "16",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("--bit-depth applies to PNG output"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("g.exr").exists());
}

/// Writes an `n`³ raw f32 volume of `f(i, j, k)` and returns its path.
fn raw_volume(dir: &Path, name: &str, n: usize, f: impl Fn(usize, usize, usize) -> f32) -> String {
    let mut bytes = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                bytes.extend(f(i, j, k).to_le_bytes());
            }
        }
    }
    let p = dir.join(name);
    fs::write(&p, bytes).unwrap();
    p.to_str().unwrap().to_string()
}

/// Renders and returns the 8-bit RGB of the centre pixel and of a corner.
fn centre_and_corner(args: &[&str], dir: &Path) -> ([u8; 3], [u8; 3]) {
    let out = dir.join("c.png");
    let mut a = args.to_vec();
    a.extend(["--size", "17", "-o", out.to_str().unwrap()]);
    let o = volray(&a);
    assert!(o.status.success(), "{a:?}: {}", stderr(&o));
    let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(&out).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    let px = |x: usize, y: usize| {
        let b = 3 * (y * 17 + x);
        [buf[b], buf[b + 1], buf[b + 2]]
    };
    (px(8, 8), px(0, 0))
}

#[test]
fn colormap_and_range_set_the_material_colour() {
    let dir = tempfile::tempdir().unwrap();
    // A uniform medium of value 5 with a constant opacity: the pixel colour
    // is the material colour times a factor that depends only on opacity.
    let v = raw_volume(dir.path(), "u.raw", 8, |_, _, _| 5.0);
    let tf = dir.path().join("flat.json");
    fs::write(&tf, r#"{"opacity": [[0, 0.6], [1, 0.6]]}"#).unwrap();
    let base = [
        "render",
        &v,
        "--dims",
        "8,8,8",
        "--no-shading",
        "--tf",
        tf.to_str().unwrap(),
    ];
    let with = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend(extra);
        centre_and_corner(&a, dir.path()).0
    };
    // grey at t = 0.5 (range 0..10) is twice grey at t = 0.25 (range 0..20).
    let half = with(&["--colormap", "grey", "--range", "0,10"]);
    let quarter = with(&["--colormap", "grey", "--range", "0,20"]);
    for c in 0..3 {
        assert!(
            (i32::from(half[c]) - 2 * i32::from(quarter[c])).abs() <= 2,
            "{half:?} {quarter:?}"
        );
    }
    assert!(half[0] > 60, "{half:?}");
    // viridis at 0.5 is #21918c: the channels keep its proportions.
    let v5 = with(&["--colormap", "viridis", "--range", "0,10"]);
    let scale = f64::from(half[0]) / (0.5 * 255.0);
    for (c, want) in [33.0, 145.0, 140.0].into_iter().enumerate() {
        assert!(
            (f64::from(v5[c]) - want * scale).abs() <= 3.0,
            "{v5:?} vs {want} * {scale}"
        );
    }
    // Values above the window clamp to its top: viridis(1) is #fde725.
    let top = with(&["--colormap", "viridis", "--range", "0,2"]);
    assert!(top[0] > top[2] && top[1] > top[2], "{top:?}");
}

#[test]
fn ct_presets_show_bone_and_hide_air() {
    let dir = tempfile::tempdir().unwrap();
    // Air (−1000 HU) around a ball of cortical bone (1200 HU).
    let n = 12;
    let c = (n - 1) as f32 / 2.0;
    let v = raw_volume(dir.path(), "ct.raw", n, |i, j, k| {
        let r2 = (i as f32 - c).powi(2) + (j as f32 - c).powi(2) + (k as f32 - c).powi(2);
        if r2 < 16.0 { 1200.0 } else { -1000.0 }
    });
    for preset in ["ct-bone", "ct-soft-tissue"] {
        let (centre, corner) = centre_and_corner(
            &["render", &v, "--dims", "12,12,12", "--preset", preset],
            dir.path(),
        );
        assert!(centre.iter().all(|&x| x > 100), "{preset}: {centre:?}");
        assert_eq!(corner, [0, 0, 0], "{preset}");
    }
    let refused = |args: &[&str], expect: &str| {
        let o = volray(args);
        assert_eq!(o.status.code(), Some(1), "{args:?}");
        assert!(stderr(&o).contains(expect), "{args:?}: {}", stderr(&o));
    };
    let out = dir.path().join("x.png");
    let o = out.to_str().unwrap();
    refused(
        &["render", "sphere:8", "-o", o, "--preset", "ct-lung"],
        "unknown preset 'ct-lung'",
    );
    refused(
        &["render", "sphere:8", "-o", o, "--colormap", "jet"],
        "unknown colour map 'jet'",
    );
    refused(
        &[
            "render", "sphere:8", "-o", o, "--preset", "ct-bone", "--range", "0,1",
        ],
        "--range conflicts with the value domain fixed by --preset",
    );
    refused(
        &[
            "render",
            "sphere:8",
            "-o",
            o,
            "--preset",
            "mr",
            "--opacity",
            "0,1",
        ],
        "--opacity conflicts with the opacity function in --preset",
    );
    refused(
        &["render", "sphere:8", "-o", o, "--range", "3,1"],
        "must be below",
    );
    assert!(!out.exists());
}

#[test]
fn every_reader_feeds_the_renderer() {
    let dir = tempfile::tempdir().unwrap();
    // One fixture per format (written by the independent tools named in
    // crates/io/tests/fixtures/make_*_fixtures.py) with its dims and unit.
    let cases = [
        ("nrrd/f32_lps.nrrd", "NRRD", [4, 3, 5], "mm"),
        ("metaimage/f32.mha", "MetaImage", [4, 3, 5], ""),
        ("nifti/f32.nii.gz", "NIfTI", [4, 3, 5], "um"),
        (
            "vtk/legacy_f32.vtk",
            "legacy VTK structured points",
            [4, 3, 5],
            "",
        ),
        (
            "vtk/vti_appended_raw.vti",
            "VTK XML image data",
            [4, 3, 5],
            "",
        ),
        ("dicom/ct", "DICOM", [4, 3, 5], "mm"),
        ("tiff/imagej_u16.tif", "TIFF stack", [4, 3, 5], "um"),
        ("cube/ramp_bohr.cube", "Gaussian cube", [4, 3, 5], "bohr"),
        ("mrc/mode2_f32.mrc", "CCP4/MRC map", [4, 3, 5], "angstrom"),
        (
            "chgcar/CHGCAR_ortho",
            "VASP CHGCAR/CHG",
            [5, 4, 6],
            "angstrom",
        ),
    ];
    for (file, format, dims, unit) in cases {
        let path = format!("crates/io/tests/fixtures/{file}");
        let out = volray(&["info", &path, "--json"]);
        assert!(out.status.success(), "{file}: {}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["format"], format, "{file}");
        assert_eq!(v["dims"], serde_json::json!(dims), "{file}");
        assert_eq!(v["length_unit"].as_str().unwrap_or(""), unit, "{file}");
        let png = dir.path().join("r.png");
        let out = volray(&["render", &path, "--size", "16", "-o", png.to_str().unwrap()]);
        assert!(out.status.success(), "{file}: {}", stderr(&out));
        assert!(fs::metadata(&png).unwrap().len() > 0);
    }
}

#[test]
fn info_describes_a_2d_image_that_render_refuses() {
    // A 5 x 4 float image x + 10y + 0.5, spacing 0.5, 0.25, from (1, 2)
    // (crates/io/tests/fixtures/make_flat_fixtures.py, written by pynrrd).
    let image = "crates/io/tests/fixtures/flat/image.nrrd";
    let out = volray(&["info", image]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for expect in [
        "format:    NRRD",
        "dims:      5 x 4 x 1 (20 points: an image, not a volume)",
        "spacing:   0.5, 0.25, 1",
        "origin:    1, 2, 0",
        "values:    min 0.5, max 34.5, mean 1.750000e1",
        "render:    refused: a 2-D image (5 x 4 samples), not a volume",
        "space directions: (0.5,0) (0,0.25)",
    ] {
        assert!(text.contains(expect), "missing {expect:?} in\n{text}");
    }
    let out = volray(&["info", image, "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["volume"], false);
    assert_eq!(v["dims"], serde_json::json!([5, 4, 1]));
    assert_eq!(v["values"]["max"], 34.5);

    // render refuses with the reason, exit 1, one line.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let out = volray(&["render", image, "-o", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains(&format!(
            "{image}: a 2-D image (5 x 4 samples), not a volume: volray renders volumes of at least 2 points along each axis"
        )),
        "{err}"
    );
    assert!(!png.exists());

    // A single DICOM slice names the directory to pass instead.
    let slice = "crates/io/tests/fixtures/dicom/single.dcm";
    let text = stdout(&volray(&["info", slice]));
    assert!(
        text.contains("render:    refused: a single DICOM slice (4 x 3), not a volume: pass the directory of the series (crates/io/tests/fixtures/dicom)"),
        "{text}"
    );
    let out = volray(&["render", slice, "-o", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("pass the directory of the series"));
}

#[test]
fn a_skewed_map_of_part_of_a_cell_renders_with_empty_space_around_its_box() {
    // A monoclinic (beta 110) map of 4 x 3 x 5 points of an 8 x 9 x 10 cell
    // (crates/io/tests/fixtures/make_crystal_map_fixtures.py): resampled,
    // NaN outside the map's box, which renders as empty space without
    // --nonfinite.
    let map = "crates/io/tests/fixtures/mrc/part_monoclinic.ccp4";
    let out = volray(&["info", map]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for expect in [
        "NaN: no value (outside the file's grid, or fill or blank values; see the notes), rendered as empty",
        "not periodic, so only its own box is resampled",
    ] {
        assert!(text.contains(expect), "missing {expect:?} in\n{text}");
    }
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("map.png");
    let out = volray(&["render", map, "--size", "32", "-o", png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(fs::metadata(&png).unwrap().len() > 0);
}

#[test]
fn info_names_a_format_it_does_not_read_and_the_tool_that_converts_it() {
    // Fixtures: crates/io/tests/fixtures/make_not_read_fixtures.py.
    let dir = "crates/io/tests/fixtures/not_read";
    let out_dir = tempfile::tempdir().unwrap();
    let png = out_dir.path().join("never.png");
    let png = png.to_str().unwrap();
    for (file, expect) in [
        (
            "T1.PAR",
            "Philips PAR/REC is not read by volray; convert it to NIfTI with nibabel's parrec2nii",
        ),
        (
            "tinypet.v",
            "ECAT 7 is not read by volray; convert it to NIfTI with nibabel",
        ),
        (
            "scaled+tlrc.HEAD",
            "AFNI BRIK/HEAD is not read by volray; convert it to NIfTI with AFNI's 3dAFNItoNIFTI",
        ),
        (
            "grid.vdb",
            "OpenVDB is not read by volray; copy the grid to a dense array",
        ),
        ("n5", "N5 is not read by volray; convert it to Zarr"),
    ] {
        let path = format!("{dir}/{file}");
        for args in [vec!["info", &path], vec!["render", &path, "-o", png]] {
            let out = volray(&args);
            assert_eq!(out.status.code(), Some(1), "{path}: {}", stderr(&out));
            let err = stderr(&out);
            assert_eq!(err.lines().count(), 1, "{err}");
            assert!(err.contains(&format!("{path}: {expect}")), "{err}");
            assert!(!err.contains("DICOM"), "{err}");
        }
    }
}
