//! `mpirun -np N volray render` against one process: real `mpirun`, real
//! ranks (1 to 4), the binary built with `--features mpi` (into
//! `target/mpi`, or `VOLRAY_MPI_BIN`). Images within one 8-bit level of
//! the one-process image on every blend mode, orthographic and
//! perspective, with crop and clip planes and post-classification; the
//! same bytes from run to run; `--max-memory` per rank; a file that must
//! be read by rank 0 and scattered; a failure that ends every rank with
//! the same error and writes nothing; `bench`'s per-rank stages.
//!
//! Without `mpirun` the tests fail under `CI=true` (`.ci/run` installs
//! Open MPI) and are skipped, saying so, elsewhere.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `mpirun`, or `None` (and the reason printed) where it is missing
/// outside CI.
fn mpirun() -> Option<&'static str> {
    let found = Command::new("mpirun").arg("--version").output().is_ok();
    if !found {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "mpirun is missing: install Open MPI (apt-get install openmpi-bin libopenmpi-dev libclang-dev), as .ci/run does"
        );
        eprintln!("skipped: mpirun is not installed (apt-get install openmpi-bin libopenmpi-dev)");
        return None;
    }
    Some("mpirun")
}

/// The volray binary built with the `mpi` feature.
fn mpi_volray() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        if let Some(bin) = std::env::var_os("VOLRAY_MPI_BIN") {
            return PathBuf::from(bin);
        }
        let target = root().join("target").join("mpi");
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let status = Command::new(cargo)
            .current_dir(root())
            .args(["build", "--release", "--features", "mpi", "--bin", "volray"])
            .arg("--target-dir")
            .arg(&target)
            .status()
            .expect("cargo runs");
        assert!(
            status.success(),
            "building volray with --features mpi failed"
        );
        target.join("release").join("volray")
    })
}

/// `volray ARGS` in one process (the binary under test, no MPI).
fn single(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `mpirun -np N volray ARGS`, within a minute.
fn ranks(n: usize, args: &[&str]) -> Output {
    let mpirun = mpirun().expect("checked by the caller");
    Command::new("timeout")
        .arg("60")
        .arg(mpirun)
        .args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-np",
            &n.to_string(),
        ])
        .arg(mpi_volray())
        .args(args)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .unwrap()
}

fn pixels(path: &Path) -> Vec<u8> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    buf
}

fn largest_difference(a: &Path, b: &Path) -> u8 {
    let (a, b) = (pixels(a), pixels(b));
    assert_eq!(a.len(), b.len());
    a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap()
}

/// `render ARGS -o OUT`.
fn with_output<'a>(args: &[&'a str], out: &'a str) -> Vec<&'a str> {
    let mut v = vec!["render"];
    v.extend(args);
    v.extend(["-o", out]);
    v
}

#[test]
fn one_to_four_ranks_render_the_one_process_image_within_a_level() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str]); 7] = [
        (
            "orthographic",
            &["fractal:65", "--azimuth", "30", "--elevation", "20"],
        ),
        (
            "perspective, cropped and clipped",
            &[
                "hydrogen:4,2,1,grid=48",
                "--perspective",
                "40",
                "--azimuth",
                "-60",
                "--crop",
                "-40,30,-40,40,-35,40",
                "--clip",
                "0,0,0,1,0.3,0.2",
            ],
        ),
        (
            "post-classified, half steps, unshaded",
            &[
                "marschner-lobb:41",
                "--post-classification",
                "--step",
                "0.5",
                "--no-shading",
                "--elevation",
                "50",
            ],
        ),
        (
            "maximum",
            &["fractal:65", "--blend", "mip", "--azimuth", "100"],
        ),
        (
            "minimum",
            &["blobs:40", "--blend", "minip", "--elevation", "-30"],
        ),
        (
            "average",
            &["blobs:40", "--blend", "average", "--azimuth", "45"],
        ),
        // Zeros go to the whole volume's smallest positive value, not a piece's.
        ("log scale", &["fractal:65", "--log", "--azimuth", "60"]),
    ];
    for (name, args) in cases {
        let mut args = args.to_vec();
        args.extend(["--size", "96x80"]);
        let one = dir.path().join("one.png");
        single(&with_output(&args, one.to_str().unwrap()));
        for n in 1..=4 {
            let out = dir.path().join(format!("{n}.png"));
            let run = ranks(n, &with_output(&args, out.to_str().unwrap()));
            assert!(
                run.status.success(),
                "{name}, {n} ranks: {}",
                String::from_utf8_lossy(&run.stderr)
            );
            let diff = largest_difference(&one, &out);
            assert!(diff <= 1, "{name}, {n} ranks: {diff} levels");
        }
    }
}

#[test]
fn the_same_rank_count_writes_the_same_bytes() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let files: Vec<Vec<u8>> = (0..2)
        .map(|i| {
            let out = dir.path().join(format!("{i}.png"));
            let args = [
                "hydrogen:3,2,0,grid=40",
                "--size",
                "64x64",
                "--bit-depth",
                "16",
            ];
            let run = ranks(3, &with_output(&args, out.to_str().unwrap()));
            assert!(
                run.status.success(),
                "{}",
                String::from_utf8_lossy(&run.stderr)
            );
            std::fs::read(out).unwrap()
        })
        .collect();
    assert_eq!(files[0], files[1]);
}

/// A 257³ `f32` raw file of the fractal cloud (68 MB).
fn big_raw(dir: &Path) -> PathBuf {
    let raw = dir.join("f257.raw");
    single(&[
        "generate",
        "fractal",
        "--size",
        "257",
        "-o",
        raw.to_str().unwrap(),
    ]);
    raw
}

#[test]
fn max_memory_holds_per_rank_so_more_ranks_render_a_bigger_volume() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let raw = big_raw(dir.path());
    let args = [
        raw.to_str().unwrap(),
        "--dims",
        "257,257,257",
        "--dtype",
        "f32",
        "--size",
        "128x128",
        "--max-memory",
        "40M",
    ];
    let one = dir.path().join("one.png");
    let refused = ranks(1, &with_output(&args, one.to_str().unwrap()));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(stderr.contains("over --max-memory 40 MiB"), "{stderr}");
    assert!(!one.exists());
    let four = dir.path().join("four.png");
    let run = ranks(4, &with_output(&args, four.to_str().unwrap()));
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // The same frame as one process with no limit (the file mapped).
    single(&with_output(&args[..7], one.to_str().unwrap()));
    assert!(largest_difference(&one, &four) <= 1);
}

#[test]
fn a_compressed_file_is_read_by_rank_zero_and_scattered() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("f.raw");
    single(&[
        "generate",
        "fractal",
        "--size",
        "33",
        "-o",
        raw.to_str().unwrap(),
    ]);
    let nrrd = dir.path().join("f.nrrd");
    let mut file = std::fs::File::create(&nrrd).unwrap();
    write!(
        file,
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 33 33 33\nspacings: 0.5 0.5 0.5\nendian: little\nencoding: gzip\n\n"
    )
    .unwrap();
    let mut gz = flate2::write::GzEncoder::new(file, flate2::Compression::fast());
    gz.write_all(&std::fs::read(&raw).unwrap()).unwrap();
    gz.finish().unwrap();
    let args = [nrrd.to_str().unwrap(), "--size", "80x80", "--azimuth", "20"];
    let one = dir.path().join("one.png");
    single(&with_output(&args, one.to_str().unwrap()));
    let three = dir.path().join("three.png");
    let run = ranks(3, &with_output(&args, three.to_str().unwrap()));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(stderr.contains("cannot be read by range"), "{stderr}");
    assert!(largest_difference(&one, &three) <= 1);
}

#[test]
fn a_rank_that_cannot_read_ends_every_rank_with_one_error_and_no_file() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("short.raw");
    std::fs::write(&raw, vec![0u8; 1000]).unwrap();
    let out = dir.path().join("out.png");
    let args = [
        raw.to_str().unwrap(),
        "--dims",
        "20,20,20",
        "--dtype",
        "f32",
    ];
    let run = ranks(3, &with_output(&args, out.to_str().unwrap()));
    assert!(!run.status.success());
    assert_ne!(run.status.code(), Some(124), "timed out: a rank hung");
    let stderr = String::from_utf8_lossy(&run.stderr);
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("volray: error:"))
        .collect();
    // Every rank fails with this line; mpirun ends the others once the
    // first exits, so some may be stopped before they print it.
    assert!(!errors.is_empty() && errors.len() <= 3, "{stderr}");
    assert!(errors.iter().all(|e| *e == errors[0]), "{stderr}");
    assert!(errors[0].contains("short.raw"), "{stderr}");
    assert!(!out.exists());

    // Each rank's own piece over its memory: every rank refuses.
    let raw = big_raw(dir.path());
    let args = [
        raw.to_str().unwrap(),
        "--dims",
        "257,257,257",
        "--dtype",
        "f32",
        "--max-memory",
        "12M",
    ];
    let run = ranks(4, &with_output(&args, out.to_str().unwrap()));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("volray: error:"))
        .collect();
    assert!(!errors.is_empty() && errors.len() <= 4, "{stderr}");
    assert!(errors.iter().all(|e| *e == errors[0]), "{stderr}");
    assert!(
        errors[0].contains("rank 0:") && errors[0].contains("run on more ranks"),
        "{stderr}"
    );
    assert!(!out.exists());
}

#[test]
fn bench_reports_each_ranks_stages() {
    if mpirun().is_none() {
        return;
    }
    let run = ranks(
        2,
        &["bench", "fractal:65", "--size", "128x128", "--frames", "2"],
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    for header in [
        "read ms",
        "class ms",
        "cast ms",
        "compose ms",
        "gather ms",
        "sent bytes",
    ] {
        assert!(stdout.contains(header), "{stdout}");
    }
    // A row per rank, printed once (by rank 0).
    let rows = stdout
        .lines()
        .filter(|l| l.trim_start().starts_with(['0', '1']))
        .count();
    assert_eq!(rows, 2, "{stdout}");
    assert!(stdout.contains("2 ranks"), "{stdout}");
}
