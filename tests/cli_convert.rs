//! `volray convert INPUT -o OUT`: a volume volray reads, written as NRRD,
//! `.npy` or raw in its own sample type, reads back as the same volume
//! (NRRD with its spacing and origin); numpy and pynrrd read what it
//! wrote as the same values; a file over `--max-memory` that maps
//! converts from its mapping; what cannot be converted is refused with a
//! one-line error and leaves no file.

mod common;

use common::{pyenv_with, stderr, volray};
use std::path::{Path, PathBuf};
use std::process::Command;
use volray_core::Volume;
use volray_io::{DType, RawOptions, ReadOptions, read};

fn fixture(dir: &str, name: &str) -> String {
    let p: PathBuf = [
        env!("CARGO_MANIFEST_DIR"),
        "crates/io/tests/fixtures",
        dir,
        name,
    ]
    .iter()
    .collect();
    p.to_str().unwrap().to_string()
}

fn read_volume(path: &Path) -> Volume {
    read(path, &ReadOptions::default()).unwrap().volume
}

fn convert(args: &[&str]) -> std::process::Output {
    let mut all = vec!["convert"];
    all.extend(args);
    volray(&all)
}

/// A `u16` NIfTI and an LPS NRRD (flipped axes, read reordered) to each
/// format: the same samples in the same type, NRRD keeping the geometry.
#[test]
fn a_converted_volume_reads_back_as_the_volume_read() {
    let dir = tempfile::tempdir().unwrap();
    for input in [
        fixture("nifti", "u16.nii"),
        fixture("nifti", "flipped.nii"),
        fixture("nrrd", "i8.nrrd"),
    ] {
        let original = read_volume(Path::new(&input));
        let nrrd = dir.path().join("v.nrrd");
        let run = convert(&[&input, "-o", nrrd.to_str().unwrap()]);
        assert!(run.status.success(), "{input}: {}", stderr(&run));
        assert!(stderr(&run).contains("wrote"), "{}", stderr(&run));
        assert_eq!(read_volume(&nrrd), original, "{input} as NRRD");

        let npy = dir.path().join("v.npy");
        assert!(
            convert(&[&input, "-o", npy.to_str().unwrap()])
                .status
                .success()
        );
        let back = read_volume(&npy);
        assert_eq!(
            back.sample_type(),
            original.sample_type(),
            "{input} as .npy"
        );
        assert_eq!(back.values(), original.values(), "{input} as .npy");

        let raw = dir.path().join("v.raw");
        let run = convert(&[&input, "-o", raw.to_str().unwrap()]);
        assert!(run.status.success());
        let t = original.sample_type().name();
        let [nx, ny, nz] = original.dims();
        let said = format!("--dims {nx},{ny},{nz} --dtype {t} --endian little");
        assert!(stderr(&run).contains(&said), "{}", stderr(&run));
        let opts = ReadOptions {
            raw: Some(RawOptions::new([nx, ny, nz], t.parse::<DType>().unwrap())),
            ..ReadOptions::default()
        };
        assert_eq!(
            read(&raw, &opts).unwrap().volume.values(),
            original.values()
        );
    }
}

/// numpy and pynrrd (target/pyenv, as `.ci/run` makes it) read volray's
/// `.npy` and NRRD as the voxels volray read: shape, dtype, every value
/// at `a[x, y, z]`, and NRRD's spacing and origin.
#[test]
fn numpy_and_pynrrd_read_what_convert_wrote() {
    let Some(python) = pyenv_with(&["numpy", "nrrd"]) else {
        return;
    };
    for name in ["flipped.nii", "u16.nii"] {
        python_reads(&python, &fixture("nifti", name));
    }
}

/// numpy and pynrrd read `input` converted as volray reads it.
fn python_reads(python: &Path, input: &str) {
    let dir = tempfile::tempdir().unwrap();
    let original = read_volume(Path::new(input));
    let npy = dir.path().join("v.npy");
    let nrrd = dir.path().join("v.nrrd");
    for out in [&npy, &nrrd] {
        assert!(
            convert(&[input, "-o", out.to_str().unwrap()])
                .status
                .success()
        );
    }
    // volray's own values, x fastest, for Python to compare with.
    let expect = dir.path().join("expect.txt");
    let text: Vec<String> = original.values().iter().map(|v| format!("{v}")).collect();
    std::fs::write(&expect, text.join("\n")).unwrap();
    let [nx, ny, nz] = original.dims();
    let (s, o) = (original.spacing(), original.origin());
    let script = format!(
        r#"
import sys, numpy as np, nrrd
expect = np.loadtxt(sys.argv[3]).reshape(({nz}, {ny}, {nx})).transpose(2, 1, 0)
a = np.load(sys.argv[1])
assert a.shape == ({nx}, {ny}, {nz}), a.shape
assert a.dtype == np.dtype("{dtype}"), a.dtype
assert np.array_equal(a.astype(np.float64), expect), "npy values"
b, h = nrrd.read(sys.argv[2])
assert b.shape == ({nx}, {ny}, {nz}), b.shape
assert b.dtype == np.dtype("{dtype}"), b.dtype
assert np.array_equal(b.astype(np.float64), expect), "nrrd values"
assert np.allclose(np.diag(h["space directions"]), [{sx}, {sy}, {sz}], rtol=0, atol=1e-12), h
assert np.allclose(h["space origin"], [{ox}, {oy}, {oz}], rtol=0, atol=1e-9), h
print("ok")
"#,
        dtype = match original.sample_type() {
            volray_core::SampleType::U8 => "uint8",
            volray_core::SampleType::I8 => "int8",
            volray_core::SampleType::U16 => "uint16",
            volray_core::SampleType::I16 => "int16",
            volray_core::SampleType::F32 => "float32",
        },
        sx = s.x,
        sy = s.y,
        sz = s.z,
        ox = o.x,
        oy = o.y,
        oz = o.z,
    );
    let out = Command::new(python)
        .args(["-c", &script])
        .args([&npy, &nrrd, &expect])
        .output()
        .unwrap();
    assert!(
        out.status.success() && String::from_utf8_lossy(&out.stdout).trim() == "ok",
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A raw file over `--max-memory` maps and converts from its mapping (read
/// whole it would be refused: the limit is a tenth of it); a compressed
/// one over the limit is refused, with the reason, and writes nothing.
#[test]
fn a_file_over_the_memory_limit_converts_from_its_mapping_or_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let n = 40usize;
    let values: Vec<u16> = (0..n * n * n).map(|i| (i * 7 % 65521) as u16).collect();
    let raw = dir.path().join("big.raw");
    std::fs::write(
        &raw,
        values
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<u8>>(),
    )
    .unwrap();
    let out = dir.path().join("big.nrrd");
    let run = convert(&[
        raw.to_str().unwrap(),
        "--dims",
        "40,40,40",
        "--dtype",
        "u16",
        "--max-memory",
        "12K",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let back = read_volume(&out);
    assert_eq!(back.sample_type(), volray_core::SampleType::U16);
    let expect: Vec<f32> = values.iter().map(|&v| f32::from(v)).collect();
    assert_eq!(back.values(), expect);

    let gz = fixture("nrrd", "u8_gzip.nrrd");
    let refused = dir.path().join("gz.npy");
    let run = convert(&[&gz, "--max-memory", "10", "-o", refused.to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert!(
        stderr(&run).contains("cannot be mapped"),
        "{}",
        stderr(&run)
    );
    assert_eq!(stderr(&run).lines().count(), 1, "{}", stderr(&run));
    assert!(!refused.exists());
}

#[test]
fn an_unknown_format_or_the_input_itself_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("nifti", "u16.nii");
    let out = dir.path().join("v.png");
    let run = convert(&[&input, "-o", out.to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(1));
    assert!(
        stderr(&run).contains("unknown output format"),
        "{}",
        stderr(&run)
    );
    assert!(!out.exists());
    // The input itself, by another name: refused before reading.
    let copy = dir.path().join("u16.npy");
    std::fs::copy(&input, dir.path().join("keep.nii")).unwrap();
    std::fs::hard_link(dir.path().join("keep.nii"), &copy).unwrap();
    let keep = dir.path().join("keep.nii");
    let before = std::fs::read(&keep).unwrap();
    let run = convert(&[keep.to_str().unwrap(), "-o", copy.to_str().unwrap()]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert_eq!(std::fs::read(&keep).unwrap(), before);
}

/// `convert fractal:33 -o x.ome.zarr --chunk 16`: three levels; level 0
/// renders as the fractal itself (within 1/255), the coarser levels
/// render too; `--zarr-version 2` writes OME-Zarr 0.4 (`.zgroup`,
/// `.zattrs`, `.zarray`) that renders the same.
#[test]
fn an_ome_zarr_image_renders_as_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let png = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let render = |input: &str, extra: &[&str], out: &str| {
        let mut args = vec!["render", input, "--size", "64x48", "-o", out];
        args.extend(extra);
        let run = volray(&args);
        assert!(run.status.success(), "{input}: {}", stderr(&run));
        common::Picture::read(Path::new(out))
    };
    let direct = render("fractal:33", &[], &png("direct.png"));
    for (version, marker) in [("3", "zarr.json"), ("2", ".zgroup")] {
        let store = dir.path().join(format!("v{version}.ome.zarr"));
        let s = store.to_str().unwrap();
        let run = convert(&[
            "fractal:33",
            "-o",
            s,
            "--chunk",
            "16",
            "--zarr-version",
            version,
        ]);
        assert!(run.status.success(), "{}", stderr(&run));
        let said = stderr(&run);
        let ome = if version == "3" { "0.5" } else { "0.4" };
        assert!(
            said.contains(&format!("OME-Zarr {ome} (Zarr v{version})"))
                && said.contains("3 levels (block means): 33x33x33, 17x17x17, 9x9x9"),
            "{said}"
        );
        assert_eq!(said.lines().count(), 1, "{said}");
        assert!(store.join(marker).is_file());
        if version == "2" {
            assert!(store.join(".zattrs").is_file() && store.join("0/.zarray").is_file());
            let attrs = std::fs::read_to_string(store.join(".zattrs")).unwrap();
            assert!(attrs.contains("\"version\": \"0.4\""), "{attrs}");
        }
        let from_store = render(s, &[], &png(&format!("v{version}.png")));
        assert!(direct.max_diff(&from_store) <= 1, "v{version}");
        let coarse = render(s, &["--level", "2"], &png("coarse.png"));
        assert_eq!((coarse.width, coarse.height), (64, 48));
    }
}

/// The OME-Zarr flags apply to OME-Zarr output only; an existing
/// directory that is no Zarr store is not replaced.
#[test]
fn zarr_flags_with_a_file_output_and_a_foreign_directory_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let nrrd = dir.path().join("v.nrrd");
    for flags in [
        &["--zarr-version", "2"][..],
        &["--chunk", "16"],
        &["--labels"],
    ] {
        let mut args = vec!["blobs:8", "-o", nrrd.to_str().unwrap()];
        args.extend(flags);
        let run = convert(&args);
        assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
        assert!(
            stderr(&run).contains(&format!("{} appl", flags[0]))
                && stderr(&run).contains("to OME-Zarr output only"),
            "{}",
            stderr(&run)
        );
        assert!(!nrrd.exists());
    }
    let run = convert(&["blobs:8", "-o", "x.zarr", "--zarr-version", "4"]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert!(
        stderr(&run).contains("not a Zarr version"),
        "{}",
        stderr(&run)
    );

    let photos = dir.path().join("photos.zarr");
    std::fs::create_dir(&photos).unwrap();
    std::fs::write(photos.join("a.jpg"), b"jpeg").unwrap();
    let run = convert(&["blobs:8", "-o", photos.to_str().unwrap()]);
    assert!(!run.status.success());
    assert!(
        stderr(&run).contains("is not a Zarr store"),
        "{}",
        stderr(&run)
    );
    assert_eq!(std::fs::read(photos.join("a.jpg")).unwrap(), b"jpeg");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// zarr-python, ome-zarr-py and ome-zarr-models (target/pyenv, as
/// `.ci/run` makes it) read what `convert` wrote from numpy's `.npy`: the
/// same values (every one, level 0), levels that numpy's own block means
/// give, ome-zarr-py's list of levels and transformations, and the
/// metadata validated against NGFF 0.5 and 0.4.
#[test]
fn zarr_python_and_ome_zarr_read_what_convert_wrote() {
    let Some(python) = pyenv_with(&["numpy", "zarr", "ome_zarr", "ome_zarr_models"]) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/convert/check_ome_zarr.py");
    let py = |args: &[&std::ffi::OsStr]| {
        let out = Command::new(&python)
            .arg(&script)
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success()
                && String::from_utf8_lossy(&out.stdout)
                    .trim_end()
                    .ends_with("ok"),
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let npy = dir.path().join("in.npy");
    py(&["write".as_ref(), npy.as_os_str()]);
    for version in ["3", "2"] {
        let store = dir.path().join(format!("v{version}.ome.zarr"));
        let run = convert(&[
            npy.to_str().unwrap(),
            "-o",
            store.to_str().unwrap(),
            "--chunk",
            "8",
            "--zarr-version",
            version,
        ]);
        assert!(run.status.success(), "{}", stderr(&run));
        py(&[
            "check".as_ref(),
            npy.as_os_str(),
            store.as_os_str(),
            version.as_ref(),
        ]);
    }
}
