//! Analyze 7.5 images with SPM's orientation in a `.mat` beside the
//! header, written at test time by nibabel and scipy
//! (`tests/analyze_spm/write_files.py`): level-4 and level-5 (plain and
//! compressed) MATLAB files, `mat` and `M`, each image placed in the world
//! where nibabel places it (its affine is the oracle), every sample
//! checked; an empty `.mat` ignored as nibabel ignores it; one without
//! either matrix, a singular one and broken ones refused naming the
//! `.mat`.
//!
//! The writer runs in `target/pyenv` (which `.ci/run` installs); without
//! nibabel and scipy these tests fail under `CI=true` and are skipped
//! elsewhere.

mod common;

use std::collections::HashMap;
use std::path::Path;
use std::sync::OnceLock;

use common::{Grid, assert_note, check_world, error_about};
use volray_io::{ReadOptions, read};

fn files() -> Option<&'static Path> {
    static DIR: OnceLock<Option<tempfile::TempDir>> = OnceLock::new();
    common::written_by_python(
        &DIR,
        &["nibabel", "scipy", "numpy"],
        "tests/analyze_spm/write_files.py",
    )
}

/// nibabel's affine of each readable image (`affines.txt`).
fn affines(dir: &Path) -> HashMap<String, [[f64; 4]; 3]> {
    let text = std::fs::read_to_string(dir.join("affines.txt")).unwrap();
    text.lines()
        .map(|line| {
            let mut words = line.split_whitespace();
            let name = words.next().unwrap().to_string();
            let n: Vec<f64> = words.map(|w| w.parse().unwrap()).collect();
            let row = |r: usize| [n[4 * r], n[4 * r + 1], n[4 * r + 2], n[4 * r + 3]];
            (name, [row(0), row(1), row(2)])
        })
        .collect()
}

fn ramp(i: usize, j: usize, k: usize) -> f32 {
    (i + 10 * j + 100 * k) as f32
}

#[test]
fn every_image_lies_where_nibabel_puts_it() {
    let Some(dir) = files() else { return };
    let affines = affines(dir);
    assert_eq!(affines.len(), 4);
    for (name, affine) in &affines {
        let l = read(&dir.join(format!("{name}.hdr")), &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{e}"));
        check_world(
            name,
            &l.volume,
            &Grid::from_affine([4, 3, 5], affine),
            1e-9,
            ramp,
        );
        if name == "empty" {
            assert_note(&l, "empty.mat is empty: ignored");
        } else {
            assert_note(&l, &format!("orientation from SPM's {name}.mat"));
        }
    }
    // Without the .mat nibabel's header affine would put j along y: the
    // coronal one puts it along z.
    assert_eq!(affines["coronal"][2][1], 2.0);
}

#[test]
fn a_mat_without_an_affine_is_refused_naming_it() {
    let Some(dir) = files() else { return };
    for (name, want) in [
        (
            "neither",
            "holds neither \"mat\" nor \"M\" (its matrices: other)",
        ),
        ("singular", "its \"mat\" is not an invertible affine"),
    ] {
        let mat = dir.join(format!("{name}.mat"));
        let e = error_about(
            &dir.join(format!("{name}.hdr")),
            &ReadOptions::default(),
            &mat,
        );
        assert!(!e.is_io_failure(), "{e}");
        let text = e.to_string();
        assert!(text.contains(want), "{text}");
        assert!(text.contains(&format!("beside {name}.hdr")), "{text}");
    }
}

#[test]
fn broken_mat_files_are_refused_never_a_panic() {
    let Some(dir) = files() else { return };
    let work = tempfile::tempdir().unwrap();
    for source in ["coronal", "m_only", "pages"] {
        let bytes = std::fs::read(dir.join(format!("{source}.mat"))).unwrap();
        for ext in ["hdr", "img"] {
            std::fs::copy(
                dir.join(format!("{source}.{ext}")),
                work.path().join(format!("x.{ext}")),
            )
            .unwrap();
        }
        let hdr = work.path().join("x.hdr");
        let mut cuts: Vec<usize> = (1..bytes.len()).step_by(7).collect();
        cuts.push(bytes.len() - 1);
        for cut in cuts {
            std::fs::write(work.path().join("x.mat"), &bytes[..cut]).unwrap();
            // A cut may leave a shorter valid file (level 4 holds "M"
            // first); what it must never do is panic or misname.
            if let Err(e) = read(&hdr, &ReadOptions::default()) {
                assert_eq!(
                    e.path(),
                    work.path().join("x.mat"),
                    "{source} cut {cut}: {e}"
                );
            }
        }
        let mut flipped = bytes.clone();
        for at in 0..bytes.len() {
            flipped[at] ^= 0xa5;
            std::fs::write(work.path().join("x.mat"), &flipped).unwrap();
            let _ = read(&hdr, &ReadOptions::default());
            flipped[at] ^= 0xa5;
        }
    }
}
