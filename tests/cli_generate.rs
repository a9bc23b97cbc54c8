//! `volray generate`: the paper's data sets written to files that read back.

use std::fs;

mod common;
use common::{stderr, volray};

fn info_json(input: &str) -> serde_json::Value {
    let out = volray(&["info", input, "--json"]);
    assert!(out.status.success(), "{input}: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn read_f32(path: &std::path::Path) -> Vec<f32> {
    fs::read(path)
        .unwrap()
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

#[test]
fn hydrogen_density_is_normalised_and_keeps_its_geometry() {
    let dir = tempfile::tempdir().unwrap();
    // The same density as raw f32 values and as NRRD (which carries the grid).
    let (raw, nrrd) = (dir.path().join("h.raw"), dir.path().join("h.nrrd"));
    for path in [&raw, &nrrd] {
        let out = volray(&[
            "generate",
            "hydrogen",
            "--n",
            "2",
            "--l",
            "1",
            "--m",
            "1",
            "--grid",
            "61",
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let values = read_f32(&raw);
    assert_eq!(values.len(), 61 * 61 * 61);
    // The grid is [−R, R]³ with R holding 99.5%.
    let info = info_json(nrrd.to_str().unwrap());
    let h = info["spacing"][0].as_f64().unwrap();
    let r = -info["origin"][0].as_f64().unwrap();
    assert!((h - 2.0 * r / 60.0).abs() < 1e-9 * r, "{info}");
    // Σ|ψ|²ΔV ≈ 1 (the cube holds at least 99.5%; the Riemann sum of a
    // smooth density on 61 points per side is good to well under 1%).
    let sum: f64 = values.iter().map(|&v| f64::from(v)).sum::<f64>() * h * h * h;
    assert!((sum - 1.0).abs() < 0.01, "Σ|ψ|²ΔV = {sum}");
    // The same density is the render input hydrogen:2,1,1,grid=61.
    let spec = info_json("hydrogen:2,1,1,grid=61");
    assert_eq!(spec["values"]["max"], info["values"]["max"]);
    assert_eq!(spec["spacing"], info["spacing"]);
}

#[test]
fn fractal_files_equal_the_render_input_and_depend_on_the_seed() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.npy");
    let b = dir.path().join("b.npy");
    for (path, seed) in [(&a, "7"), (&b, "8")] {
        let out = volray(&[
            "generate",
            "fractal",
            "--size",
            "17",
            "--dimension",
            "3.5",
            "--seed",
            seed,
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let file = info_json(a.to_str().unwrap());
    let spec = info_json("fractal:17,seed=7,dim=3.5");
    assert_eq!(file["values"], spec["values"]);
    assert_ne!(fs::read(&a).unwrap(), fs::read(&b).unwrap());
    // Post-processed: nothing negative, something non-empty.
    assert_eq!(file["values"]["min"], 0.0);
    assert!(file["values"]["max"].as_f64().unwrap() > 0.0);
    // The raw field has mean-zero displacements and negative values.
    let raw = dir.path().join("raw.raw");
    let out = volray(&[
        "generate",
        "fractal",
        "--size",
        "17",
        "--raw-field",
        "-o",
        raw.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(read_f32(&raw).iter().any(|&v| v < 0.0));
}

#[test]
fn bad_parameters_are_refused_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("x.npy");
    let o = o.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (
            &[
                "generate", "hydrogen", "--n", "13", "--l", "0", "--m", "0", "-o", o,
            ],
            "n",
        ),
        (
            &[
                "generate", "hydrogen", "--n", "3", "--l", "3", "--m", "0", "-o", o,
            ],
            "l",
        ),
        (
            &[
                "generate", "hydrogen", "--n", "3", "--l", "1", "--m", "-2", "-o", o,
            ],
            "m",
        ),
        (&["generate", "fractal", "--size", "100", "-o", o], "100"),
        (
            &["generate", "fractal", "--dimension", "4.5", "-o", o],
            "4.5",
        ),
        (
            &["generate", "fractal", "--size", "9", "-o", "x.vtk"],
            "unknown output format",
        ),
    ];
    for (args, expect) in cases {
        let out = volray(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        let err = stderr(&out);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(expect), "{args:?}: {err}");
    }
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
}
