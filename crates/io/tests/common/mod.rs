//! What the format tests share: fixture paths and read options; checks of
//! a loaded volume's values and geometry against the formula and grid a
//! fixture was written from; the harness that expects a clear refusal;
//! and the generators of broken files for the "never panics" tests.
//!
//! Each test binary compiles this module for itself and uses only part of
//! it, hence the `allow(dead_code)`.
#![allow(dead_code)]

use std::fs;
use std::ops::Range;
use std::path::{Path, PathBuf};

use volray_core::Volume;
use volray_core::glam::{DMat3, DVec3};
use volray_io::{IoError, Loaded, ReadOptions, read};

/// `tests/fixtures/<format>/<name>`.
pub fn fixture(format: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(format)
        .join(name)
}

/// Reading volume `frame` (`--frame`), or the default one.
pub fn with_frame(frame: Option<usize>) -> ReadOptions {
    ReadOptions {
        frame,
        ..ReadOptions::default()
    }
}

/// Reading volume `n` (`--frame n`).
pub fn frame(n: usize) -> ReadOptions {
    with_frame(Some(n))
}

/// Reading time point `t` of channel `c` (`--frame t --channel c`).
pub fn at(t: usize, c: usize) -> ReadOptions {
    ReadOptions {
        frame: Some(t),
        channel: Some(c),
        ..ReadOptions::default()
    }
}

/// Reading the named array (`--array`), or the default one.
pub fn with_array(array: Option<&str>) -> ReadOptions {
    ReadOptions {
        array: array.map(str::to_string),
        ..ReadOptions::default()
    }
}

// ---- what a fixture holds ----

/// `i + 10j + 100k`: the ramp every fixture script stores, in some form,
/// at file index (i, j, k).
pub fn ramp(i: usize, j: usize, k: usize) -> i64 {
    (i + 10 * j + 100 * k) as i64
}

/// The value the NIfTI and VTK fixture scripts store for sample type
/// `name` at ramp value `v` (their `TYPES` tables): each type's formula
/// moves `v` into the range only that type holds.
pub fn typed(name: &str, v: i64) -> f32 {
    match name {
        "u8" => (v % 256) as u8 as f32,
        "i8" => (v % 256 - 128) as i8 as f32,
        "u16" => (v + 60000) as u16 as f32,
        "i16" => (v - 1000) as i16 as f32,
        "u32" => (v + 3_000_000_000) as u32 as f32,
        "i32" => (v - 2_000_000) as i32 as f32,
        "u64" => (v as u64 + (1 << 40)) as f32,
        "i64" => (v - (1 << 40)) as f32,
        "f32" => v as f32 + 0.25,
        "f64" => (v as f64 - 0.125) as f32,
        _ => unreachable!("{name}"),
    }
}

// ---- what a read gave ----

/// Whether some note of `l` contains `text`.
pub fn has_note(l: &Loaded, text: &str) -> bool {
    l.info.notes.iter().any(|n| n.contains(text))
}

/// Asserts that some note of `l` contains `text`, showing the notes if not.
pub fn assert_note(l: &Loaded, text: &str) {
    assert!(
        has_note(l, text),
        "no note with {text:?} in {:?}",
        l.info.notes
    );
}

/// The value of header field `key`; panics, listing the fields, if absent.
pub fn header_value<'l>(l: &'l Loaded, key: &str) -> &'l str {
    l.info
        .header
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no header field {key}: {:?}", l.info.header))
}

/// Asserts that `vol` is `dims` voxels and that voxel (i, j, k) holds
/// exactly `want(i, j, k)`; `what` starts the message of a mismatch.
pub fn check_voxels(
    what: &str,
    vol: &Volume,
    dims: [usize; 3],
    want: impl Fn(usize, usize, usize) -> f32,
) {
    assert_eq!(vol.dims(), dims, "{what}");
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                assert_eq!(vol.get(i, j, k), want(i, j, k), "{what} at ({i}, {j}, {k})");
            }
        }
    }
}

/// A file's grid of samples: `n` per index axis, sample (i, j, k) at
/// `origin + i·steps[0] + j·steps[1] + k·steps[2]`.
#[derive(Debug, Clone, Copy)]
pub struct Grid {
    pub n: [usize; 3],
    pub steps: [DVec3; 3],
    pub origin: DVec3,
}

impl Grid {
    /// The grid of an affine `(i, j, k, 1) -> world` (rows x, y, z) over
    /// `n` samples per axis.
    pub fn from_affine(n: [usize; 3], affine: &[[f64; 4]; 3]) -> Grid {
        let column = |c: usize| DVec3::new(affine[0][c], affine[1][c], affine[2][c]);
        Grid {
            n,
            steps: [column(0), column(1), column(2)],
            origin: column(3),
        }
    }
}

/// Checks a volume against the file grid it was read from, whatever axis
/// order the reader chose: every sample of `grid` must fall on a voxel of
/// `vol` (within `tol`, both in voxels and in world units) that holds
/// `want(i, j, k)`, and the volume holds no other voxels.
pub fn check_world(
    what: &str,
    vol: &Volume,
    grid: &Grid,
    tol: f64,
    want: impl Fn(usize, usize, usize) -> f32,
) {
    let [ni, nj, nk] = grid.n;
    let dims = vol.dims();
    assert_eq!(vol.len(), ni * nj * nk, "{what}: {dims:?}");
    for k in 0..nk {
        for j in 0..nj {
            for i in 0..ni {
                let world = grid.origin
                    + grid.steps[0] * i as f64
                    + grid.steps[1] * j as f64
                    + grid.steps[2] * k as f64;
                let g = (world - vol.origin()) / vol.spacing();
                let idx = [g.x, g.y, g.z].map(|x| {
                    let r = x.round();
                    assert!(
                        (x - r).abs() < tol,
                        "{what}: ({i}, {j}, {k}) at {world} is off the grid"
                    );
                    r
                });
                assert!(
                    idx.iter().zip(dims).all(|(&a, n)| a >= 0.0 && a < n as f64),
                    "{what}: ({i}, {j}, {k}) at {world} lies outside the volume ({idx:?})"
                );
                let [x, y, z] = idx.map(|a| a as usize);
                let at = vol.world_position(x, y, z);
                assert!(
                    (at - world).length() < tol,
                    "{what}: ({i}, {j}, {k}) at {world}, voxel at {at}"
                );
                assert_eq!(
                    vol.get(x, y, z),
                    want(i, j, k),
                    "{what} at file index ({i}, {j}, {k})"
                );
            }
        }
    }
}

/// Checks a skewed cell resampled onto an axis-aligned volume: every voxel
/// whose grid coordinates `to_grid · position` lie inside the file's grid
/// (0 to `last[a]` on axis `a`, no periodic wrap) must hold `want` of those
/// coordinates within `tol`. Returns how many voxels were checked.
pub fn check_resampled(
    vol: &Volume,
    to_grid: DMat3,
    last: [f64; 3],
    tol: f64,
    want: impl Fn(DVec3) -> f64,
) -> usize {
    let [nx, ny, nz] = vol.dims();
    let mut inside = 0;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let g = to_grid * vol.world_position(i, j, k);
                if (0..3).all(|a| g[a] >= 0.0 && g[a] <= last[a]) {
                    let want = want(g);
                    let got = f64::from(vol.get(i, j, k));
                    assert!((got - want).abs() < tol, "({i}, {j}, {k}): {got} vs {want}");
                    inside += 1;
                }
            }
        }
    }
    inside
}

// ---- refusals ----

/// Asserts that `err`'s message is one line that starts with `about`.
fn assert_one_line_about(err: &IoError, about: &Path) {
    let msg = err.to_string();
    assert!(!msg.contains('\n'), "{msg}");
    assert!(msg.starts_with(&about.display().to_string()), "{msg}");
}

/// Reads `path`, which must fail with a one-line message that starts with
/// `about` (the file the error is about), and returns the error.
pub fn error_about(path: &Path, opts: &ReadOptions, about: &Path) -> IoError {
    let err = match read(path, opts) {
        Ok(_) => panic!("{}: read, but should be refused", path.display()),
        Err(e) => e,
    };
    assert_one_line_about(&err, about);
    err
}

/// Asserts that `err` is the refusal of a frame the file does not hold
/// ([`IoError::FrameOutOfRange`] for `frame`, bad input), its message
/// saying `frame {frame} is out of range: {held}`.
pub fn assert_frame_out_of_range(err: &IoError, frame: usize, held: &str) {
    assert!(
        matches!(err, IoError::FrameOutOfRange { frame: f, .. } if *f == frame),
        "{err}"
    );
    assert!(!err.is_io_failure(), "{err}");
    let want = format!("frame {frame} is out of range: {held}");
    assert!(err.to_string().contains(&want), "{err}\n  wanted: {want}");
}

/// Reads `path`, which must be refused as bad input (not an I/O failure)
/// with a one-line message that starts with the path; returns the error.
pub fn refused_error(path: &Path, opts: &ReadOptions) -> IoError {
    let err = error_about(path, opts, path);
    assert!(!err.is_io_failure(), "{err}");
    err
}

/// [`refused_error`]'s message.
pub fn refused(path: &Path, opts: &ReadOptions) -> String {
    refused_error(path, opts).to_string()
}

/// Writes `bytes` as `name` in `dir` and expects [`refused`].
pub fn refused_at(dir: &Path, name: &str, bytes: &[u8], opts: &ReadOptions) -> String {
    let path = dir.join(name);
    fs::write(&path, bytes).unwrap();
    refused(&path, opts)
}

/// Writes `bytes` as `name` in a new temporary directory and expects
/// [`refused`].
pub fn refused_file(name: &str, bytes: &[u8], opts: &ReadOptions) -> String {
    let dir = tempfile::tempdir().unwrap();
    refused_at(dir.path(), name, bytes, opts)
}

/// [`refused_at`] with default options, and the message must contain `want`.
pub fn refuse(dir: &Path, name: &str, bytes: &[u8], want: &str) -> String {
    let msg = refused_at(dir, name, bytes, &ReadOptions::default());
    assert!(msg.contains(want), "{msg}\n  wanted: {want}");
    msg
}

// ---- hostile files: never a panic ----

/// A copy of `bytes` with the first `from` replaced by `to`; panics if
/// `from` is not there.
pub fn replace(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let at = bytes
        .windows(from.len())
        .position(|w| w == from.as_bytes())
        .unwrap_or_else(|| panic!("{from} not found"));
    [&bytes[..at], to.as_bytes(), &bytes[at + from.len()..]].concat()
}

/// A copy of `bytes` with the bytes in `range` XORed with 0x5a: a corrupt
/// stream of the same length.
pub fn scrambled(bytes: &[u8], range: Range<usize>) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for b in &mut out[range] {
        *b ^= 0x5a;
    }
    out
}

/// Reads `path`: true if it gave a volume, false if it was refused as bad
/// input in one line that starts with the path. Anything else (a panic, an
/// I/O failure, a message of several lines) fails the test.
pub fn read_or_refuse(path: &Path, opts: &ReadOptions) -> bool {
    let result = read(path, opts);
    if let Err(e) = &result {
        assert!(!e.is_io_failure(), "{e}");
        assert_one_line_about(e, path);
    }
    result.is_ok()
}

/// The prefixes of `bytes` every `step` bytes, from the empty one.
pub fn truncations(bytes: &[u8], step: usize) -> impl Iterator<Item = &[u8]> {
    (0..bytes.len()).step_by(step).map(move |n| &bytes[..n])
}

/// Knuth's MMIX linear congruential generator: a fixed, seeded sequence,
/// so every run of a test feeds the reader the same files.
pub struct Lcg(pub u64);

impl Lcg {
    /// The next number, of 31 bits (the generator's better high bits).
    pub fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 33
    }

    /// A number below `n`.
    pub fn below(&mut self, n: usize) -> usize {
        self.next() as usize % n
    }
}

/// Marsaglia's xorshift64 step.
fn xorshift(seed: &mut u64) -> u64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    *seed
}

/// The header edits of [`header_edits_never_panic`] touch every
/// `EDIT_STRIDE`-th header byte and cut every `3 * EDIT_STRIDE`-th length,
/// to keep the tests fast where writing a file is slow; 1 visits all.
const EDIT_STRIDE: usize = 5;

/// Truncations of each fixture, and copies whose header bytes from `from`
/// to `header_end(bytes)` are replaced in turn by one of `chars` (bytes
/// that change numbers and structure): each must give a volume or a
/// one-line error about a file in the fixture's directory (an edit can
/// turn the header into a detached one that names a missing data file),
/// never a panic or an allocation the file cannot back. Both outcomes must
/// occur: the edits are not all rejected wholesale.
pub fn header_edits_never_panic(
    fixtures: &[PathBuf],
    from: usize,
    chars: &[u8],
    header_end: impl Fn(&[u8]) -> usize,
) {
    let dir = tempfile::tempdir().unwrap();
    let mut outcomes = [0usize; 2];
    for fixture in fixtures {
        let bytes = fs::read(fixture).unwrap();
        let end = header_end(&bytes);
        let p = dir.path().join(fixture.file_name().unwrap());
        let mut attempt = |b: &[u8]| {
            fs::write(&p, b).unwrap();
            match read(&p, &ReadOptions::default()) {
                Ok(_) => outcomes[0] += 1,
                Err(e) => {
                    assert_one_line_about(&e, dir.path());
                    outcomes[1] += 1;
                }
            }
        };
        for cut in truncations(&bytes, EDIT_STRIDE * 3) {
            attempt(cut);
        }
        for (n, at) in (from..end).step_by(EDIT_STRIDE).enumerate() {
            let mut b = bytes.clone();
            b[at] = chars[n % chars.len()];
            attempt(&b);
        }
    }
    assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
}

/// About 25 truncations of each fixture and 30 copies with three bytes
/// overwritten at places xorshift picks (one sequence from `seed` through
/// all fixtures), each read with every one of `options`: each must read or
/// be refused cleanly ([`read_or_refuse`]).
pub fn byte_flips_never_panic(fixtures: &[PathBuf], seed: u64, options: &[ReadOptions]) {
    let dir = tempfile::tempdir().unwrap();
    let mut seed = seed;
    for fixture in fixtures {
        let good = fs::read(fixture).unwrap();
        let p = dir.path().join(fixture.file_name().unwrap());
        let mut variants: Vec<Vec<u8>> = truncations(&good, good.len() / 25 + 1)
            .map(<[u8]>::to_vec)
            .collect();
        for _ in 0..30 {
            let mut b = good.clone();
            for _ in 0..3 {
                let r = xorshift(&mut seed);
                let at = (r % b.len() as u64) as usize;
                b[at] = (r >> 32) as u8;
            }
            variants.push(b);
        }
        for b in variants {
            fs::write(&p, &b).unwrap();
            for opts in options {
                read_or_refuse(&p, opts);
            }
        }
    }
}

/// Truncations every 61 bytes of every file in `fixture_dir`, and 25
/// copies of each with one byte replaced by a digit, sign, exponent
/// letter, line break or binary byte, read with frame 0, 1 or 2, written
/// as `target` (the name the format is found by): each must read or be
/// refused cleanly ([`read_or_refuse`]).
pub fn text_edits_never_panic(fixture_dir: &Path, target: &str) {
    let dir = tempfile::tempdir().unwrap();
    let replacements = b"0 9-+.eEdD\n\r\t*x\xff\x00";
    let mut rng = Lcg(0x9e37_79b9_7f4a_7c15);
    let path = dir.path().join(target);
    let check = |bytes: &[u8], frame: Option<usize>| {
        fs::write(&path, bytes).unwrap();
        read_or_refuse(&path, &with_frame(frame));
    };
    for entry in fs::read_dir(fixture_dir).unwrap() {
        let good = fs::read(entry.unwrap().path()).unwrap();
        for cut in truncations(&good, 61) {
            check(cut, None);
        }
        for _ in 0..25 {
            let mut b = good.clone();
            let at = rng.below(b.len());
            b[at] = replacements[rng.below(replacements.len())];
            check(&b, Some(rng.below(3)));
        }
    }
}

/// A copy of `bytes` with `count` bytes overwritten (by 0xff, 0 or a
/// random byte) at places `rng` picks, cut short one time in four.
pub fn mutate(bytes: &[u8], rng: &mut Lcg, count: usize) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..count {
        let at = rng.below(out.len());
        out[at] = match rng.next() % 3 {
            0 => 0xff,
            1 => 0,
            _ => rng.next() as u8,
        };
    }
    if rng.next().is_multiple_of(4) {
        out.truncate(rng.below(out.len()) + 1);
    }
    out
}

/// Each of `files` mutated ([`mutate`]) with 1 to 8 bytes changed, written
/// as `target`: each must read or be refused cleanly ([`read_or_refuse`]).
pub fn mutations_never_panic(files: &[PathBuf], target: &str, seed: u64) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(target);
    let mut rng = Lcg(seed);
    for file in files {
        let bytes = fs::read(file).unwrap();
        for n in 1..=8 {
            fs::write(&path, mutate(&bytes, &mut rng, n)).unwrap();
            read_or_refuse(&path, &ReadOptions::default());
        }
    }
}

/// The files an independent writer made: `script` (relative to this
/// crate) run once per test binary by the workspace's `target/pyenv`
/// python into a temporary directory kept in `cell`. `None`, with the
/// reason printed, where that python lacks one of `modules`; under
/// `CI=true` that fails instead (`.ci/run` installs them).
pub fn written_by_python(
    cell: &'static std::sync::OnceLock<Option<tempfile::TempDir>>,
    modules: &[&str],
    script: &str,
) -> Option<&'static Path> {
    let python = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/pyenv/bin/python");
    cell.get_or_init(|| {
        let has = std::process::Command::new(&python)
            .args(["-c", &format!("import {}", modules.join(", "))])
            .status()
            .is_ok_and(|s| s.success());
        if !has {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "target/pyenv lacks one of {modules:?}: target/pyenv/bin/pip install them (as .ci/run does)"
            );
            eprintln!("skipped: target/pyenv lacks one of {modules:?}");
            return None;
        }
        let dir = tempfile::tempdir().unwrap();
        let out = std::process::Command::new(&python)
            .args(["-W", "ignore"])
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join(script))
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{script} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        Some(dir)
    })
    .as_ref()
    .map(|d| d.path())
}
