//! `--max-memory` through the binary: files whose header needs more are
//! refused before reading (exit 1, naming the flag), built-in sources by
//! their spec, and volumes whose rendering may need more before rendering.

mod common;

use common::{stderr, volray};

const NRRD: &str = "crates/io/tests/fixtures/nrrd/f32_lps.nrrd"; // 4x3x5 f32: 240 bytes

fn refused(args: &[&str], want: &[&str]) {
    let out = volray(args);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    for w in want {
        assert!(err.contains(w), "{args:?}: {err}\n  wanted: {w}");
    }
}

#[test]
fn info_obeys_the_limit_exactly() {
    refused(
        &["info", "--max-memory", "239", NRRD],
        &[
            "f32_lps.nrrd",
            "\"sizes\" 4 3 5",
            "exceed --max-memory 239 bytes",
        ],
    );
    let out = volray(&["info", "--max-memory", "240", NRRD]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = volray(&[
        "info",
        "--max-memory",
        "1K",
        "crates/io/tests/fixtures/vtk/vti_binary.vti",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("--max-memory 1 KiB"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn sizes_are_parsed_or_refused() {
    for bad in ["0", "-1", "1.5", "4X", "G", ""] {
        refused(&["info", "--max-memory", bad, NRRD], &["--max-memory"]);
    }
    for good in ["1G", "1.5GiB", "512m", "4096"] {
        let out = volray(&["info", "--max-memory", good, NRRD]);
        assert!(out.status.success(), "{good}: {}", stderr(&out));
    }
}

#[test]
fn built_in_sources_and_rendering_obey_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let png = png.to_str().unwrap();
    // 512^3 f32 is 512 MiB: refused from the spec, before generating.
    refused(
        &["render", "blobs:512", "--max-memory", "100M", "-o", png],
        &[
            "blobs:512",
            "points per side 512 512 512",
            "512 MiB",
            "--max-memory 100 MiB",
        ],
    );
    refused(
        &["info", "hydrogen:2,1,0,grid=300", "--max-memory", "100M"],
        &["points per side 300 300 300"],
    );
    // blobs:33 is 144 KiB; rendering it needs the volume, a few hundred
    // bytes a brick of bookkeeping (64 bricks) and the frame: 150K is too
    // little whatever the caches.
    refused(
        &[
            "render",
            "blobs:33",
            "--size",
            "16",
            "--max-memory",
            "150K",
            "-o",
            png,
        ],
        &[
            "blobs:33: rendering 33x33x33 voxels",
            "more than --max-memory 150 KiB",
        ],
    );
    assert!(!dir.path().join("x.png").exists());
    // 200K leaves the caches of classified and lit bricks about 40 KiB
    // (of the 1.1 MiB all 64 bricks take): the same picture, pixel for
    // pixel, as with room for every brick.
    let roomy = dir.path().join("roomy.png");
    for (limit, out) in [("200K", png), ("2M", roomy.to_str().unwrap())] {
        let run = volray(&[
            "render",
            "blobs:33",
            "--size",
            "16",
            "--max-memory",
            limit,
            "-o",
            out,
        ]);
        assert!(run.status.success(), "{limit}: {}", stderr(&run));
    }
    assert_eq!(std::fs::read(png).unwrap(), std::fs::read(&roomy).unwrap());
    // A projection needs the volume and the frame only.
    let out = volray(&[
        "render",
        "blobs:33",
        "--size",
        "16",
        "--blend",
        "mip",
        "--max-memory",
        "200K",
        "-o",
        png,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    refused(
        &[
            "bench",
            "blobs:33",
            "--size",
            "16",
            "--frames",
            "1",
            "--max-memory",
            "150K",
        ],
        &["rendering 33x33x33 voxels"],
    );
}

/// A raw volume larger than `--max-memory` is mapped from its file rather
/// than refused, and renders exactly as it does read into memory; `info`
/// says it is mapped. A compressed one cannot be mapped, and its refusal
/// says so and what to do.
#[test]
fn a_volume_over_the_limit_is_mapped_and_renders_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("ct.raw");
    let n = 64usize;
    let bytes: Vec<u8> = (0..n * n * n)
        .flat_map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            let r = ((x * x + y * y + z * z) as f64).sqrt();
            let hu: i16 = if r < 40.0 {
                40 + (x % 7) as i16 * 100
            } else {
                -1000
            };
            hu.to_le_bytes()
        })
        .collect();
    std::fs::write(&raw, bytes).unwrap();
    let raw = raw.to_str().unwrap();
    let layout = ["--dims", "64,64,64", "--dtype", "i16"];
    let (mapped, read_in) = (dir.path().join("mapped.png"), dir.path().join("read.png"));
    for (limit, out) in [("400K", &mapped), ("1G", &read_in)] {
        let args = [
            &["render", raw][..],
            &layout,
            &["--preset", "ct-bone", "--size", "48", "--max-memory", limit],
            &["-o", out.to_str().unwrap()],
        ]
        .concat();
        let run = volray(&args);
        assert!(run.status.success(), "{limit}: {}", stderr(&run));
    }
    assert_eq!(
        std::fs::read(&mapped).unwrap(),
        std::fs::read(&read_in).unwrap()
    );
    let info = volray(&[&["info", raw, "--max-memory", "400K"][..], &layout].concat());
    let text = String::from_utf8_lossy(&info.stdout).to_string();
    assert!(
        text.contains("in memory: mapped from the file, i16 (2 bytes a voxel, 512 KiB)"),
        "{text}"
    );

    refused(
        &[
            "info",
            "--max-memory",
            "10",
            "crates/io/tests/fixtures/nrrd/u8_gzip.nrrd",
        ],
        &[
            "cannot be mapped from the file instead (gzip-compressed data: store it uncompressed (raw encoding))",
            "(60 values, 60 bytes at 1 byte a value), which",
            "exceed --max-memory 10 bytes",
        ],
    );
}
