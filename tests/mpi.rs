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

/// Renders `args` in one process, then under `mpirun` at each of
/// `counts` ranks: every run succeeds and its image is within one 8-bit
/// level of the one process's. The ranks' stderr, for more checks.
fn ranks_match_one_process(dir: &Path, what: &str, args: &[&str], counts: &[usize]) -> Vec<String> {
    let one = dir.join("one.png");
    single(&with_output(args, one.to_str().unwrap()));
    let mut stderrs = Vec::new();
    for &n in counts {
        let out = dir.join(format!("{n}.png"));
        let run = ranks(n, &with_output(args, out.to_str().unwrap()));
        let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
        assert!(run.status.success(), "{what}, {n} ranks: {stderr}");
        let diff = largest_difference(&one, &out);
        assert!(diff <= 1, "{what}, {n} ranks: {diff} levels");
        stderrs.push(stderr);
    }
    stderrs
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
        ranks_match_one_process(dir.path(), name, &args, &[1, 2, 3, 4]);
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

/// The fractal cloud of `n`³ points as a gzip-compressed NRRD, which no
/// rank can read by range.
fn gzip_nrrd(dir: &Path, n: usize) -> PathBuf {
    let raw = dir.join("f.raw");
    let size = n.to_string();
    single(&[
        "generate",
        "fractal",
        "--size",
        &size,
        "-o",
        raw.to_str().unwrap(),
    ]);
    let nrrd = dir.join("f.nrrd");
    let mut file = std::fs::File::create(&nrrd).unwrap();
    write!(
        file,
        "NRRD0004\ntype: float\ndimension: 3\nsizes: {n} {n} {n}\nspacings: 0.5 0.5 0.5\nendian: little\nencoding: gzip\n\n"
    )
    .unwrap();
    let mut gz = flate2::write::GzEncoder::new(file, flate2::Compression::fast());
    gz.write_all(&std::fs::read(&raw).unwrap()).unwrap();
    gz.finish().unwrap();
    std::fs::remove_file(raw).unwrap();
    nrrd
}

#[test]
fn a_compressed_file_is_read_by_rank_zero_and_scattered() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let nrrd = gzip_nrrd(dir.path(), 33);
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
fn each_rank_reads_the_chunks_of_its_own_box_of_an_ome_zarr_image() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // The 129³ fractal written by volray convert: 64³ chunks, zstd.
    let store = dir.path().join("f129.ome.zarr");
    single(&["convert", "fractal:129", "-o", store.to_str().unwrap()]);
    // An omero window over the upper half of its values: the default
    // range of every rank as of one process.
    let info = single(&["info", store.to_str().unwrap(), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let (lo, hi) = (
        info["values"]["min"].as_f64().unwrap(),
        info["values"]["max"].as_f64().unwrap(),
    );
    let meta_path = store.join("zarr.json");
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&meta_path).unwrap()).unwrap();
    meta["attributes"]["ome"]["omero"] = serde_json::json!({"channels": [{
        "window": {"start": (lo + hi) / 2.0, "end": hi, "min": lo, "max": hi}
    }]});
    std::fs::write(&meta_path, meta.to_string()).unwrap();
    let args = [
        store.to_str().unwrap(),
        "--size",
        "96x96",
        "--azimuth",
        "30",
    ];
    let stderrs = ranks_match_one_process(dir.path(), "OME-Zarr", &args, &[2, 3, 4]);
    for stderr in &stderrs {
        assert!(!stderr.contains("rank 0 reads it"), "{stderr}");
    }
    // Read by range: under a limit the 8.6 MB of samples exceed, four ranks
    // each read and render their own quarter, the same picture.
    let limited = [&args[..], &["--max-memory", "8M"]].concat();
    let one = dir.path().join("limited1.png");
    let refused = ranks(1, &with_output(&limited, one.to_str().unwrap()));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success(), "one rank rendered under 8M");
    assert!(err.contains("over --max-memory 8 MiB"), "{err}");
    let four = dir.path().join("limited4.png");
    let run = ranks(4, &with_output(&limited, four.to_str().unwrap()));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    assert!(largest_difference(&dir.path().join("one.png"), &four) <= 1);
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

/// A JPEG-LS DICOM whose scan header's length points past the end of the
/// stream (a frame cut short): the committed multi-frame fixture with the
/// first SOS segment's length set to 0xFFFF.
fn corrupt_jpegls(dir: &Path) -> PathBuf {
    let fixture = root().join("crates/io/tests/fixtures/dicom/jpegls_frames.dcm");
    let mut bytes = std::fs::read(fixture).unwrap();
    let sos = bytes
        .windows(2)
        .position(|w| w == [0xFF, 0xDA])
        .expect("a JPEG-LS scan header");
    bytes[sos + 2] = 0xFF;
    bytes[sos + 3] = 0xFF;
    let path = dir.join("corrupt_jpegls.dcm");
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn a_decoder_failing_on_every_rank_is_one_line_each_and_exit_1_not_an_abort() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let dcm = corrupt_jpegls(dir.path());
    let out = dir.path().join("out.png");
    let run = ranks(
        2,
        &with_output(&[dcm.to_str().unwrap()], out.to_str().unwrap()),
    );
    assert_ne!(run.status.code(), Some(124), "timed out: a rank hung");
    // mpirun exits with the ranks' code: 1, bad input; an MPI_Abort
    // would give 101 and mpirun's abort banner.
    assert_eq!(
        run.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        !stderr.contains("MPI_ABORT") && !stderr.contains("MPI_Abort"),
        "{stderr}"
    );
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("volray: error:"))
        .collect();
    assert!(!errors.is_empty() && errors.len() <= 2, "{stderr}");
    assert!(errors.iter().all(|e| *e == errors[0]), "{stderr}");
    assert!(errors[0].contains("corrupt_jpegls.dcm"), "{stderr}");
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

/// `target/pyenv`'s python with mrcfile, nibabel and pynrrd (PyPI),
/// installed if missing (`.ci/run` installs them): the independent
/// writers of the files whose axes must be reordered.
fn python_with_writers() -> PathBuf {
    static PYTHON: OnceLock<PathBuf> = OnceLock::new();
    PYTHON
        .get_or_init(|| {
            let venv = root().join("target/pyenv");
            let python = venv.join("bin/python");
            if !python.exists() {
                let made = Command::new("python3")
                    .args(["-m", "venv"])
                    .arg(&venv)
                    .status()
                    .expect("python3 is needed to write the test files (as .ci/run installs it)");
                assert!(made.success(), "python3 -m venv target/pyenv failed");
            }
            let has = Command::new(&python)
                .args(["-c", "import mrcfile, nibabel, nrrd, numpy"])
                .status()
                .is_ok_and(|s| s.success());
            if !has {
                let pip = Command::new(venv.join("bin/pip"))
                    .args([
                        "install", "--quiet", "numpy", "mrcfile", "nibabel", "pynrrd",
                    ])
                    .status()
                    .expect("pip runs");
                assert!(pip.success(), "pip install mrcfile nibabel pynrrd failed");
            }
            python
        })
        .clone()
}

/// Files whose axes run in another order or sense, written by mrcfile
/// (MAPC/MAPR/MAPS 2,1,3), nibabel (LAS), pynrrd (index axes along
/// −z, +x, +y) and numpy (`np.save`, C order: z fastest): every rank
/// maps the file and reorders its own box, and
/// 1 to 4 ranks give one process's image within a level. They were
/// refused under mpirun before ("the file's axes are not x, y, z").
#[test]
fn files_whose_axes_are_reordered_render_as_one_process() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let wrote = Command::new(python_with_writers())
        .arg(root().join("tests/mpi_support/write_reordered.py"))
        .arg(dir.path())
        .status()
        .unwrap();
    assert!(wrote.success(), "writing the reordered files failed");
    for file in ["perm.mrc", "las.nii", "neg.nhdr", "c.npy"] {
        let input = dir.path().join(file);
        let args = [
            input.to_str().unwrap(),
            "--size",
            "72x64",
            "--azimuth",
            "35",
            "--elevation",
            "25",
        ];
        for stderr in ranks_match_one_process(dir.path(), file, &args, &[1, 2, 3, 4]) {
            // Read by range, not by rank 0 and sent.
            assert!(
                !stderr.contains("cannot be read by range"),
                "{file}: {stderr}"
            );
        }
    }
}

/// A label volume (nibabel's segmentation): the ranks join the labels
/// they find, and render as one process does, with `--label-opacity`
/// and `--show-labels` too; a volume that is not one is refused on
/// every rank with the one-process message.
#[test]
fn label_volumes_render_as_one_process() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let seg = root().join("crates/io/tests/fixtures/labels/seg.nii.gz");
    let seg = seg.to_str().unwrap();
    let cases: [&[&str]; 3] = [
        &["--labels"],
        &["--labels", "--label-opacity", "1:0.1,2:1"],
        &["--labels", "--show-labels", "2,5", "--azimuth", "70"],
    ];
    for case in cases {
        let mut args = vec![seg, "--size", "64x64", "--elevation", "30"];
        args.extend(case);
        ranks_match_one_process(dir.path(), &format!("{case:?}"), &args, &[2, 3]);
    }
    let out = dir.path().join("cloud.png");
    let single_refusal = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(with_output(
            &["fractal:33", "--labels"],
            out.to_str().unwrap(),
        ))
        .output()
        .unwrap();
    let expected = String::from_utf8_lossy(&single_refusal.stderr);
    let run = ranks(
        2,
        &with_output(&["fractal:33", "--labels"], out.to_str().unwrap()),
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    let line = expected
        .lines()
        .find(|l| l.starts_with("volray: error:"))
        .unwrap();
    assert!(stderr.lines().any(|l| l == line), "{stderr} vs {line}");
    assert!(!out.exists());
}

#[test]
fn hot_pixels_are_histogrammed_away_across_ranks_as_in_one_process() {
    if mpirun().is_none() {
        return;
    }
    // Values 10..=100 with three voxels at 1e6: `--tf auto` refines its
    // histogram to 10..100, each pass summed over the ranks.
    let dims = [24, 32, 40];
    let data = (0..dims.iter().product::<usize>())
        .map(|i| match i {
            100 | 9_000 | 25_000 => 1e6,
            _ => 10.0 + 90.0 * (i % 97) as f32 / 96.0,
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("hot.npy");
    volray_io::write_npy(&file, &volray_core::Volume::new(dims, data).unwrap()).unwrap();
    let args = [
        file.to_str().unwrap(),
        "--size",
        "64x64",
        "--elevation",
        "30",
    ];
    ranks_match_one_process(dir.path(), "hot pixels", &args, &[2, 3]);
    // Not blank: over 0..3.9e27 every value would be transparent.
    let one = pixels(&dir.path().join("one.png"));
    let background = &one[..3];
    let shown = one.chunks_exact(3).filter(|p| *p != background).count();
    assert!(shown > 64 * 64 / 4, "{shown}");
}

/// `ARGS` under `mpirun -np N`, each rank run by a Python parent that
/// writes the rank's exact peak resident memory (`ru_maxrss` of its
/// child, KiB) to a file of its own (lines of ranks sharing stderr can
/// interleave); the peaks, one per rank.
fn ranks_with_peak_rss(n: usize, args: &[&str]) -> (Output, Vec<u64>) {
    let peaks = tempfile::tempdir().unwrap();
    let wrapper = "import os, resource, subprocess, sys\n\
        code = subprocess.call(sys.argv[1:])\n\
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss\n\
        path = os.path.join(os.environ['VOLRAY_PEAKS'], str(os.getpid()))\n\
        open(path, 'w').write(str(peak))\n\
        sys.exit(code)";
    let out = Command::new("timeout")
        .arg("60")
        .arg(mpirun().expect("checked by the caller"))
        .args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-np",
            &n.to_string(),
        ])
        .args(["-x", "VOLRAY_PEAKS", "python3", "-c", wrapper])
        .arg(mpi_volray())
        .args(args)
        .env("VOLRAY_PEAKS", peaks.path())
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .unwrap();
    let peaks = std::fs::read_dir(peaks.path())
        .unwrap()
        .map(|f| {
            let text = std::fs::read_to_string(f.unwrap().path()).unwrap();
            text.trim().parse().unwrap()
        })
        .collect();
    (out, peaks)
}

/// A rank over `--max-memory` is refused before it allocates what the
/// limit is about: its peak resident memory stays under the limit plus
/// what the binary takes to start and render a tiny volume under
/// mpirun. Before, each rank copied its whole piece (or generated the
/// whole fractal) and only then compared it with the limit.
#[test]
fn a_rank_over_max_memory_is_refused_before_it_allocates() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let tiny = dir.path().join("tiny.png");
    let (run, base) = ranks_with_peak_rss(
        1,
        &with_output(&["blobs:8", "--size", "8x8"], tiny.to_str().unwrap()),
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let own = base[0];
    let limit_kib = 40 * 1024;
    let raw = big_raw(dir.path());
    let out = dir.path().join("out.png");
    let mapped = [
        raw.to_str().unwrap(),
        "--dims",
        "257,257,257",
        "--dtype",
        "f32",
        "--size",
        "64x64",
        "--max-memory",
        "40M",
    ];
    let cases: [(&str, Vec<&str>, usize); 4] = [
        // A mapped file's piece (68 MB at one rank).
        ("mapped piece", mapped.to_vec(), 1),
        // Its log10 too: 17 MB pieces, whose log would make 2 of them.
        ("piece and its log", [&mapped[..], &["--log"]].concat(), 2),
        // The fractal, generated whole (68 MB) once by rank 0.
        (
            "fractal",
            vec!["fractal:257", "--size", "64x64", "--max-memory", "40M"],
            2,
        ),
        // A file rank 0 reads whole to send each rank its piece.
        ("scattered", vec![], 2),
    ];
    let gz = gzip_nrrd(dir.path(), 129);
    for (name, mut args, n) in cases {
        if name == "scattered" {
            // 129³ f32 (8.6 MB) in a gzip NRRD under a 9 MiB limit: rank 0
            // holds it whole and the pieces it cuts.
            args = vec![
                gz.to_str().unwrap(),
                "--size",
                "64x64",
                "--max-memory",
                "9M",
            ];
        }
        let (run, peaks) = ranks_with_peak_rss(n, &with_output(&args, out.to_str().unwrap()));
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{name}: rendered under the limit");
        assert!(stderr.contains("--max-memory"), "{name}: {stderr}");
        assert!(!out.exists());
        let limit = if name == "scattered" {
            9 * 1024
        } else {
            limit_kib
        };
        for peak in &peaks {
            assert!(
                *peak < own + limit,
                "{name}: a rank peaked at {peak} KiB, over the limit {limit} KiB + the binary's own {own} KiB: {stderr}"
            );
        }
        // mpirun may stop the other ranks once the first exits non-zero;
        // the first to fail has written its peak.
        assert!(!peaks.is_empty(), "{name}: {stderr}");
    }
}

/// A 4-D NIfTI (`.nii`, float32, unit spacing) of `frames` volumes of
/// `n`³, written byte by byte.
fn nifti_4d(dir: &Path, n: usize, frames: &[Vec<f32>]) -> PathBuf {
    let mut bytes = vec![0u8; 352];
    let put_i16 =
        |b: &mut Vec<u8>, at: usize, v: i16| b[at..at + 2].copy_from_slice(&v.to_le_bytes());
    let put_f32 =
        |b: &mut Vec<u8>, at: usize, v: f32| b[at..at + 4].copy_from_slice(&v.to_le_bytes());
    bytes[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dims = [
        4,
        n as i16,
        n as i16,
        n as i16,
        frames.len() as i16,
        1,
        1,
        1,
    ];
    for (i, d) in dims.iter().enumerate() {
        put_i16(&mut bytes, 40 + 2 * i, *d);
    }
    put_i16(&mut bytes, 70, 16); // float32
    put_i16(&mut bytes, 72, 32);
    for (i, p) in [1.0, 1.0, 1.0, 1.0, 1.0].iter().enumerate() {
        put_f32(&mut bytes, 76 + 4 * i, *p);
    }
    put_f32(&mut bytes, 108, 352.0); // vox_offset
    put_f32(&mut bytes, 112, 1.0); // scl_slope
    bytes[344..348].copy_from_slice(b"n+1\0");
    for f in frames {
        bytes.extend(f.iter().flat_map(|v| v.to_le_bytes()));
    }
    let path = dir.join("channels.nii");
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn channels_render_across_ranks_as_in_one_process_in_both_mixes() {
    if mpirun().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // Two channels of one 28³ grid: balls at two places, overlapping.
    let n = 28;
    let ball = |c: [f32; 3], r: f32| -> Vec<f32> {
        (0..n * n * n)
            .map(|i| {
                let p = [(i % n) as f32, ((i / n) % n) as f32, (i / (n * n)) as f32];
                let d = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum::<f32>().sqrt();
                (1.0 - d / r).max(0.0)
            })
            .collect()
    };
    let file = nifti_4d(
        dir.path(),
        n,
        &[ball([13.0, 10.0, 13.0], 9.0), ball([14.0, 17.0, 14.0], 8.0)],
    );
    let file = file.to_str().unwrap();
    for mix in ["composite", "additive"] {
        let args = [
            file,
            "--channels",
            "all",
            "--mix",
            mix,
            "--size",
            "48",
            "--azimuth",
            "30",
            "--elevation",
            "20",
            "--opacity",
            "0,0.3",
        ];
        ranks_match_one_process(dir.path(), &format!("channels, {mix}"), &args, &[2, 3]);
    }
    // Overlays (other grids) are refused under mpirun, in one line.
    let out = dir.path().join("o.png");
    let run = ranks(
        2,
        &with_output(&[file, "--overlay", file], out.to_str().unwrap()),
    );
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("--overlay"));
    assert!(!out.exists());
}
