//! The chemistry grids volray reads beside cube and CHGCAR (OpenDX, XSF,
//! gOpenMol plt), NumPy `.npz` archives, GIPL and MRtrix images, and text formats behind gzip,
//! bzip2 or xz: `volray info`
//! names the format and geometry, and `volray render` with no options
//! draws a picture that is not blank. The files are small ones made here
//! after each format's layout (crates/io/tests/chem_grids.rs checks the
//! readers against files the formats' own tools write).

mod common;

use std::io::Write;
use std::path::Path;

use common::{Picture, render, stderr, stdout, volray, written_by_python};

/// A ball of density on an n³ grid, x fastest: exp(-r²/4), r in voxels
/// from the centre.
fn ball(n: usize) -> Vec<f32> {
    let c = (n as f32 - 1.0) / 2.0;
    let mut v = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let r2 = [i, j, k]
                    .iter()
                    .map(|&a| (a as f32 - c).powi(2))
                    .sum::<f32>();
                v.push((-r2 / 4.0).exp());
            }
        }
    }
    v
}

fn text(values: impl Iterator<Item = f32>) -> String {
    values
        .map(|v| format!("{v:.6}"))
        .collect::<Vec<_>>()
        .join("\n")
}

fn dx(n: usize) -> Vec<u8> {
    let b = ball(n);
    // z fastest in the file: the ball is symmetric, so any order holds it.
    format!(
        "# made by hand\nobject 1 class gridpositions counts {n} {n} {n}\norigin 0 0 0\ndelta 0.5 0 0\ndelta 0 0.5 0\ndelta 0 0 0.5\nobject 2 class gridconnections counts {n} {n} {n}\nobject 3 class array type double rank 0 items {} data follows\n{}\nattribute \"dep\" string \"positions\"\n",
        n * n * n,
        text(b.into_iter())
    )
    .into_bytes()
}

fn xsf(n: usize) -> Vec<u8> {
    format!(
        "CRYSTAL\nPRIMVEC\n 4 0 0\n 0 4 0\n 0 0 4\nBEGIN_BLOCK_DATAGRID_3D\n rho\n BEGIN_DATAGRID_3D_rho\n {n} {n} {n}\n 0 0 0\n 4 0 0\n 0 4 0\n 0 0 4\n{}\n END_DATAGRID_3D\nEND_BLOCK_DATAGRID_3D\n",
        text(ball(n).into_iter())
    )
    .into_bytes()
}

fn plt(n: usize) -> Vec<u8> {
    let mut out: Vec<u8> = [3i32, 200, n as i32, n as i32, n as i32]
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect();
    out.extend(
        [0.0f32, 3.0, 0.0, 3.0, 0.0, 3.0]
            .iter()
            .flat_map(|f| f.to_le_bytes()),
    );
    out.extend(ball(n).iter().flat_map(|f| f.to_le_bytes()));
    out
}

fn mif(n: usize) -> Vec<u8> {
    let mut out = format!(
        "mrtrix image\ndim: {n},{n},{n}\nvox: 1,1,1\nlayout: +0,+1,+2\ndatatype: Float32LE\nfile: . 128\nEND\n"
    )
    .into_bytes();
    out.resize(128, 0);
    out.extend(ball(n).iter().flat_map(|f| f.to_le_bytes()));
    out
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// `volray info FILE --json`, asserting success.
fn info(path: &Path) -> serde_json::Value {
    let out = volray(&["info", path.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn opendx_xsf_plt_and_compressed_text_render_with_no_options() {
    let dir = tempfile::tempdir().unwrap();
    let cube = std::fs::read("crates/io/tests/fixtures/cube/ramp_bohr.cube").unwrap();
    let cases: [(&str, Vec<u8>, &str, [usize; 3]); 7] = [
        ("ball.mif", mif(9), "MRtrix image", [9, 9, 9]),
        ("ball.dx", dx(9), "OpenDX field", [9, 9, 9]),
        ("ball.xsf", xsf(9), "XCrySDen XSF grid", [9, 9, 9]),
        ("ball.plt", plt(9), "gOpenMol plt grid", [9, 9, 9]),
        ("ball.dx.gz", gzip(&dx(9)), "OpenDX field", [9, 9, 9]),
        ("ramp.cube.gz", gzip(&cube), "Gaussian cube", [4, 3, 5]),
        ("data", gzip(&xsf(9)), "XCrySDen XSF grid", [9, 9, 9]),
    ];
    for (name, bytes, format, dims) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let v = info(&path);
        assert_eq!(v["format"], format, "{name}");
        assert_eq!(v["dims"], serde_json::json!(dims), "{name}");
        let png = dir.path().join(format!("{name}.png"));
        render(&[path.to_str().unwrap(), "--size", "32"], &png);
        let picture = Picture::read(&png);
        assert!(
            picture.rgb.iter().any(|p| *p != picture.rgb[0]),
            "{name}: blank"
        );
    }
    // The text info says how a compressed file was read.
    let out = volray(&["info", dir.path().join("ramp.cube.gz").to_str().unwrap()]);
    assert!(
        stdout(&out).contains("read through gzip decompression"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn a_compressed_file_of_a_format_read_plain_only_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let mha = std::fs::read("crates/io/tests/fixtures/metaimage/f32.mha").unwrap();
    let path = dir.path().join("f32.mha.gz");
    std::fs::write(&path, gzip(&mha)).unwrap();
    let png = dir.path().join("out.png");
    let out = volray(&[
        "render",
        path.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("a gzip-compressed MetaImage file, which volray reads uncompressed only: decompress it first (gunzip -k FILE)"), "{err}");
}

#[test]
fn a_numpy_npz_archive_renders_with_no_options() {
    let script = "import sys, numpy as np\n\
i, j, k = np.indices((9, 8, 7))\n\
r2 = (i - 4) ** 2 + (j - 3.5) ** 2 + (k - 3) ** 2\n\
np.savez_compressed(sys.argv[1] + '/ball.npz', ball=np.exp(-r2 / 4.0).astype(np.float32), other=np.zeros((2, 2, 2)))\n";
    let Some(dir) = written_by_python(&["numpy"], &[], script) else {
        return;
    };
    let path = dir.path().join("ball.npz");
    let v = info(&path);
    assert_eq!(v["format"], "NumPy .npz");
    assert_eq!(v["dims"], serde_json::json!([9, 8, 7]));
    let png = dir.path().join("ball.png");
    render(&[path.to_str().unwrap(), "--size", "32"], &png);
    let picture = Picture::read(&png);
    assert!(picture.rgb.iter().any(|p| *p != picture.rgb[0]), "blank");
    let text = stdout(&volray(&["info", path.to_str().unwrap()]));
    assert!(
        text.contains("array \"ball\" (the first) of the 2 the archive holds"),
        "{text}"
    );
}

#[test]
fn a_gipl_image_from_simpleitk_renders_with_no_options() {
    let script = "import sys, numpy as np, SimpleITK as sitk\n\
k, j, i = np.indices((7, 8, 9))\n\
r2 = (i - 4) ** 2 + (j - 3.5) ** 2 + (k - 3) ** 2\n\
image = sitk.GetImageFromArray((1000 * np.exp(-r2 / 4.0)).astype(np.int16))\n\
image.SetSpacing((1.0, 1.0, 1.5))\n\
sitk.WriteImage(image, sys.argv[1] + '/ball.gipl')\n";
    let Some(dir) = written_by_python(&["numpy", "SimpleITK"], &[], script) else {
        return;
    };
    let path = dir.path().join("ball.gipl");
    let v = info(&path);
    assert_eq!(v["format"], "GIPL image");
    assert_eq!(v["dims"], serde_json::json!([9, 8, 7]));
    let png = dir.path().join("ball.png");
    render(&[path.to_str().unwrap(), "--size", "32"], &png);
    let picture = Picture::read(&png);
    assert!(picture.rgb.iter().any(|p| *p != picture.rgb[0]), "blank");
}
