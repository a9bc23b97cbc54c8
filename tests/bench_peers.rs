//! `volray bench --peers`: the peer benchmark's workloads from a directory
//! of raw volumes with JSON sidecars, its JSON output, and its errors.

use std::fs;
use std::path::Path;

mod common;
use common::{stderr, volray};

/// Writes `name.raw` (a ball, `n³` little-endian f32, x fastest) and its
/// sidecar, as the peers' make_volumes.py does.
fn write_volume(dir: &Path, name: &str, n: usize) {
    let mut bytes = Vec::new();
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    let c = (n - 1) as f32 / 2.0;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let r = ((i as f32 - c).powi(2) + (j as f32 - c).powi(2) + (k as f32 - c).powi(2))
                    .sqrt()
                    / c;
                let v = (1.0 - r).max(0.0);
                (lo, hi) = (lo.min(v), hi.max(v));
                bytes.extend(v.to_le_bytes());
            }
        }
    }
    fs::write(dir.join(format!("{name}.raw")), bytes).unwrap();
    let sidecar = format!(
        r#"{{"name": "{name}", "raw": "{name}.raw", "dims": [{n}, {n}, {n}],
            "dtype": "float32", "byte_order": "little",
            "spacing": [1.0, 1.0, 1.0], "origin": [0.0, 0.0, 0.0],
            "min": {lo}, "max": {hi}}}"#
    );
    fs::write(dir.join(format!("{name}.json")), sidecar).unwrap();
}

#[test]
fn peers_workloads_are_timed_and_written_as_json() {
    let dir = tempfile::tempdir().unwrap();
    write_volume(dir.path(), "ball_a", 17);
    write_volume(dir.path(), "ball_b", 12);
    let json = dir.path().join("times.json");
    let run = volray(&[
        "bench",
        "--peers",
        dir.path().to_str().unwrap(),
        "--cases",
        "ball_a:40,ball_b:24,ball_a:8",
        "--frames",
        "2",
        "--threads",
        "2",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(text.contains("3 workloads, 2 threads"), "{text}");
    assert!(text.contains("| ball_b 12^3, 24^2 (2 threads) |"), "{text}");
    let rows: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&json).unwrap()).unwrap();
    let rows = rows.as_array().unwrap();
    let got: Vec<(String, u64, u64)> = rows
        .iter()
        .map(|r| {
            assert!(r["median_s"].as_f64().unwrap() > 0.0, "{r}");
            (
                r["dataset"].as_str().unwrap().to_string(),
                r["window"].as_u64().unwrap(),
                r["threads"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        got,
        vec![
            ("ball_a".into(), 40, 2),
            ("ball_b".into(), 24, 2),
            ("ball_a".into(), 8, 2)
        ]
    );
}

#[test]
fn bad_peers_directories_get_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let peers = dir.path().to_str().unwrap();
    let missing = volray(&["bench", "--peers", peers, "--cases", "nothing:16"]);
    assert_eq!(missing.status.code(), Some(2), "{}", stderr(&missing));
    assert!(
        stderr(&missing).contains("nothing.json"),
        "{}",
        stderr(&missing)
    );

    // The sidecar promises more values than the raw file holds.
    write_volume(dir.path(), "short", 10);
    let side = fs::read_to_string(dir.path().join("short.json")).unwrap();
    fs::write(
        dir.path().join("short.json"),
        side.replace("[10, 10, 10]", "[10, 10, 11]"),
    )
    .unwrap();
    let short = volray(&["bench", "--peers", peers, "--cases", "short:16"]);
    assert_eq!(short.status.code(), Some(1), "{}", stderr(&short));
    assert!(stderr(&short).contains("short.raw"), "{}", stderr(&short));

    fs::write(
        dir.path().join("odd.json"),
        r#"{"dims": [4, 4, 4], "min": 2, "max": 1}"#,
    )
    .unwrap();
    let odd = volray(&["bench", "--peers", peers, "--cases", "odd:16"]);
    assert_eq!(odd.status.code(), Some(1));
    assert!(stderr(&odd).contains("odd.json") && stderr(&odd).contains("\"min\""));

    for out in [&missing, &short, &odd] {
        assert_eq!(stderr(out).trim().lines().count(), 1, "{}", stderr(out));
    }

    let both = volray(&["bench", "sphere:8", "--peers", peers]);
    assert_eq!(both.status.code(), Some(1));
    assert!(stderr(&both).contains("not both"), "{}", stderr(&both));
}

#[test]
fn vs_vtk_without_the_peers_harness_says_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let volumes = dir.path().join("volumes");
    fs::create_dir(&volumes).unwrap();
    write_volume(&volumes, "ball", 9);
    let run = volray(&[
        "bench",
        "--peers",
        volumes.to_str().unwrap(),
        "--cases",
        "ball:8",
        "--vs-vtk",
    ]);
    assert_eq!(run.status.code(), Some(1));
    assert!(
        stderr(&run).contains("vtk_bench.py not found"),
        "{}",
        stderr(&run)
    );

    // With a harness script but no venv: the Python is named.
    fs::write(dir.path().join("vtk_bench.py"), "").unwrap();
    let run = volray(&[
        "bench",
        "--peers",
        volumes.to_str().unwrap(),
        "--cases",
        "ball:8",
        "--vs-vtk",
        "--peers-python",
        "/nonexistent/python",
    ]);
    assert_eq!(run.status.code(), Some(1));
    let err = stderr(&run);
    assert!(
        err.contains("/nonexistent/python") && err.contains("setup.sh"),
        "{err}"
    );
}
