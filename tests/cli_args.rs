//! Argument validation of every option of every subcommand: bad values
//! (out of range, non-finite, huge, malformed, unknown names) and options
//! that conflict or do not apply. Each is refused before any work with exit
//! code 1 and exactly one stderr line, `volray: ...`, that names the
//! offending flag; nothing panics and no output file appears. One accepted
//! boundary value per numeric option shows the limits are where the help
//! says. The runs are tiny (`sphere:8`, a few pixels) and spread over a few
//! threads.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Where a case's output goes: `OUT` in its arguments becomes this path in
/// the case's own empty directory.
const OUT: &str = "{out}";
/// `FIX` becomes the directory of the shared fixtures (see [`fixtures`]).
const FIX: &str = "{fix}";

/// One refused command line and what the error must name.
struct Refused {
    args: Vec<String>,
    names: &'static str,
}

fn refused(base: &[&str], extra: &[&str], names: &'static str) -> Refused {
    Refused {
        args: base.iter().chain(extra).map(|s| s.to_string()).collect(),
        names,
    }
}

/// Writes the fixtures: a 4³ raw f32 volume of 0..64 (`v.raw`), the same as
/// NumPy `.npy` (`v.npy`, written by hand: format 1.0, `<f4`, C order), a
/// 3³ raw volume of −1 (`neg.raw`), and transfer functions.
fn fixtures(dir: &Path) {
    let values: Vec<u8> = (0..64).flat_map(|v| (v as f32).to_le_bytes()).collect();
    fs::write(dir.join("v.raw"), &values).unwrap();
    let mut header = "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4, 4), }".to_string();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend((header.len() as u16).to_le_bytes());
    npy.extend(header.as_bytes());
    npy.extend(&values);
    fs::write(dir.join("v.npy"), npy).unwrap();
    let neg: Vec<u8> = (0..27).flat_map(|_| (-1.0f32).to_le_bytes()).collect();
    fs::write(dir.join("neg.raw"), neg).unwrap();
    fs::write(dir.join("bad.json"), "{bad").unwrap();
    fs::write(
        dir.join("full.json"),
        r#"{"domain": [0, 1], "opacity": [[0, 0], [1, 1]], "color": [[0, 1, 0, 0], [1, 0, 0, 1]]}"#,
    )
    .unwrap();
}

/// `render` of `sphere:8` at 8² pixels to OUT.png, plus `extra`.
fn render(extra: &[&str], names: &'static str) -> Refused {
    refused(
        &["render", "sphere:8", "--size", "8", "-o", "{out}/x.png"],
        extra,
        names,
    )
}

/// `render` of the fixture `file` (raw needs `--dims` in `extra`).
fn render_file(file: &str, extra: &[&str], names: &'static str) -> Refused {
    let input = format!("{FIX}/{file}");
    let mut r = refused(&["render"], extra, names);
    r.args.insert(1, input);
    r.args
        .extend(["--size", "8", "-o", "{out}/x.png"].map(String::from));
    r
}

fn render_cases() -> Vec<Refused> {
    let mut cases = Vec::new();
    let mut bad = |flag: &'static str, values: &[&str]| {
        for v in values {
            cases.push(render(&[flag, v], flag));
        }
    };
    // Malformed numbers and lists, common to the numeric options.
    bad(
        "--size",
        &[
            "0",
            "-3",
            "abc",
            "1x",
            "x1",
            "1,2",
            "",
            "1.5",
            "5x5x5",
            "0x5",
            "99999999999999999999",
            "20000",
            "10000x10000",
        ],
    );
    bad(
        "--view",
        &["1,2", "a,b,c", "1,,2", "nan,0,0", "inf,0,0", "", "1,2,3,4"],
    );
    bad("--look-at", &["1,2", "nan,0,0", "x", "1,2,3,"]);
    bad(
        "--up",
        &[
            "0,0,0",
            "1,0,0",
            "1e-300,0,0",
            "1e200,0,1",
            "1,2",
            "nan,0,1",
        ],
    );
    bad(
        "--step",
        &["0", "-1", "nan", "inf", "abc", "1,2", "", "1e-12"],
    );
    bad(
        "--opacity",
        &[
            "0.5,0.5", "0.6,0.2", "-0.1,0.5", "0,2", "1", "nan,1", "1,,2", "abc", "0,0.5,1",
        ],
    );
    bad("--preset", &["foo", ""]);
    bad("--colormap", &["foo", ""]);
    bad(
        "--range",
        &["1,1", "2,1", "nan,1", "1", "1,2,3", "abc", "-inf,1"],
    );
    bad("--ambient", &["-1", "nan", "1,2", "1e40", "abc", ""]);
    bad("--diffuse", &["-0.5", "inf", "1,2,3,4"]);
    bad("--specular", &["-1,0,0", "x", "0,-0.1,0"]);
    bad("--shininess", &["-1", "nan", "1e40", "abc", "1,2"]);
    bad("--light", &["0,0,0", "1,2", "nan,1,1", "1e-300,0,0"]);
    bad("--light-color", &["-1,0,0", "1,2", "inf"]);
    bad("--background", &["2,0,0", "-1", "nan", "1,2", "0,0,1.5"]);
    bad("--threads", &["0", "-1", "70000", "abc", ""]);
    bad("--blend", &["foo", "", "sum"]);
    bad("--nonfinite", &["bogus", "", "refuse,transparent"]);
    bad(
        "--max-memory",
        &["0", "-1G", "1.5", "12Q", "", "G", "99999999999T"],
    );
    // Below what `sphere:8` needs (8³ f32 values and the renderer's work).
    bad("--max-memory", &["1K"]);
    bad("--iso", &["nan", "inf", "1e39", "abc", "", "1,2"]);
    bad(
        "--gradient-opacity",
        &["-0.1,0.5", "0.5", "0.5,0.2", "0,2", "nan,1", "0.5,0.5"],
    );
    bad("--perspective", &["0", "180", "-5", "nan", "abc", "30,40"]);
    bad("--zoom", &["0", "-1", "inf", "nan", "abc"]);
    bad("--azimuth", &["nan", "1e7", "inf", "abc"]);
    bad("--elevation", &["-inf", "-1e7", "x"]);
    bad(
        "--clip",
        &[
            "1,2,3",
            "0,0,0,0,0,0",
            "nan,0,0,1,0,0",
            "0,0,0,1e-300,0,0",
            "1,,2,3,4,5",
        ],
    );
    bad(
        "--crop",
        &[
            "1,-1,-1,1,-1,1",
            "0,0,0,1,0,1",
            "0,1,0,1",
            "nan,1,0,1,0,1",
            "0,1,0,1,0,1,0",
        ],
    );
    bad("--bit-depth", &["12", "0", "-8", "abc", ""]);
    bad("--turntable", &["0", "100001", "-1", "abc"]);
    bad(
        "--spacing",
        &[
            "0,1,1",
            "-1,1,1",
            "1,1",
            "nan,1,1",
            "1e-300,1,1",
            "1e300,1,1",
            "1e-7,1,1",
        ],
    );
    // Built-in sources are not files: the file options do not apply.
    for (flag, value) in [
        ("--dims", "4,4,4"),
        ("--dtype", "u8"),
        ("--endian", "big"),
        ("--format", "raw"),
        ("--frame", "0"),
        ("--array", "a"),
    ] {
        cases.push(render(&[flag, value], flag));
    }
    // Conflicting or inapplicable combinations.
    for (extra, names) in [
        (&["--iso-thickness", "2"][..], "--iso-thickness"),
        (&["--iso", "0.5", "--iso-thickness", "0"], "--iso-thickness"),
        (
            &["--iso", "0.5", "--iso-thickness", "-1"],
            "--iso-thickness",
        ),
        (
            &["--iso", "0.5", "--iso-thickness", "1e7"],
            "--iso-thickness",
        ),
        (
            &["--iso", "0.5", "--iso-thickness", "nan"],
            "--iso-thickness",
        ),
        (&["--blend", "iso"], "--blend iso"),
        (&["--blend", "mip", "--iso", "0.5"], "--iso"),
        (
            &["--blend", "minip", "--gradient-opacity", "0,1"],
            "--gradient-opacity",
        ),
        (
            &["--blend", "average", "--post-classification"],
            "--post-classification",
        ),
        (&["--blend", "mip", "--opacity", "0,1"], "--opacity"),
        (&["--blend", "maximum", "--ambient", "0.5"], "--ambient"),
        (&["--blend", "mip", "--light", "1,0,0"], "--light"),
        (&["--no-shading", "--specular", "0.5"], "--specular"),
        (&["--no-shading", "--shininess", "20"], "--shininess"),
        (&["--no-shading", "--diffuse", "1"], "--diffuse"),
        (&["--no-shading", "--light-color", "1,0,0"], "--light-color"),
        (&["--log", "--iso", "-1"], "--iso"),
        (&["--log", "--range", "-1,1"], "--range"),
        (&["--log", "--range", "0,1"], "--range"),
        (&["--log", "--preset", "ct-bone"], "--preset"),
        (&["--preset", "ct-bone", "--range", "0,1"], "--range"),
        (&["--preset", "mr", "--opacity", "0,1"], "--opacity"),
        (&["--preset", "mr", "--tf", "{fix}/full.json"], "--preset"),
        (
            &["--tf", "{fix}/full.json", "--opacity", "0,1"],
            "--opacity",
        ),
        (
            &["--tf", "{fix}/full.json", "--colormap", "magma"],
            "--colormap",
        ),
        (&["--tf", "{fix}/full.json", "--range", "0,1"], "--range"),
        (&["--tf", "{fix}/bad.json"], "--tf"),
        (&["--view", "0,0,0", "--look-at", "0,0,0"], "--view"),
        (&["--view", "0,0,5"], "--up"),
        (&["--look-at", "1e100,0,0"], "--look-at"),
        (&["--fps", "24"], "--fps"),
        (&["--fps", "-1", "--turntable", "2"], "--fps"),
        (&["--fps", "0", "--turntable", "2"], "--fps"),
        (&["--fps", "1000", "--turntable", "2"], "--fps"),
        (&["--fps", "nan", "--turntable", "2"], "--fps"),
        (&["--turntable", "2", "--bit-depth", "16"], "--bit-depth"),
        (&["sphere:8", "--turntable", "2"], "--turntable"),
        (&["--bogus"], "--bogus"),
        (&["--reference=yes"], "--reference"),
    ] {
        cases.push(render(extra, names));
    }
    // Output names the format cannot take.
    for (out, extra, names) in [
        ("{out}/x.exr", &["--bit-depth", "16"][..], "--bit-depth"),
        ("{out}/x.gif", &["--bit-depth", "16"], "--bit-depth"),
        ("{out}/x.exr", &["--turntable", "2"], "--turntable"),
        // A turntable is written as .mp4 or .webm (tests/cli_movies.rs); .mkv
        // is no animation, and a still is no movie.
        ("{out}/x.mkv", &["--turntable", "2"], "--turntable"),
        ("{out}/x.mp4", &[], "--keyframes"),
        ("{out}/x.gif", &["--resume"], "--resume"),
        ("{out}/x.gif", &["--turntable", "2", "--crf", "20"], "--crf"),
        ("{out}/x.exr", &["sphere:8"], ".exr"),
    ] {
        cases.push(refused(
            &["render", "sphere:8", "--size", "8", "-o", out],
            extra,
            names,
        ));
    }
    cases.push(refused(
        &["render", "sphere:8", "--size", "8"],
        &[],
        "--output",
    ));
    cases.push(refused(&["render", "sphere:8", "-o"], &[], "--output"));
    // Raw files: the layout options.
    for (extra, names) in [
        (&[][..], "--dims"),
        (&["--dims", "4,4"], "--dims"),
        (&["--dims", "4,4,4,4"], "--dims"),
        (&["--dims", "0,4,4"], "--dims"),
        (&["--dims", "1,4,4"], "--dims"),
        (&["--dims", "-4,4,4"], "--dims"),
        (&["--dims", "4,,4"], "--dims"),
        (&["--dims", "a,b,c"], "--dims"),
        (&["--dims", ""], "--dims"),
        (&["--dims", "99999999999,99999999999,99999999999"], "--dims"),
        (&["--dims", "18446744073709551615,2,2"], "--dims"),
        (&["--dims", "8,8,8"], "--dims"),
        (&["--dims", "4,4,4", "--dtype", "u7"], "--dtype"),
        (&["--dims", "4,4,4", "--dtype", ""], "--dtype"),
        (&["--dims", "4,4,4", "--dtype", "f64"], "--dtype"),
        (&["--dims", "4,4,4", "--endian", "middle"], "--endian"),
        (&["--dims", "4,4,4", "--format", "foo"], "--format"),
        (&["--dims", "4,4,4", "--format", ""], "--format"),
        (&["--dims", "4,4,4", "--format", "npy"], "--dims"),
        (&["--dims", "4,4,4", "--frame", "1"], "--frame"),
        (&["--dims", "4,4,4", "--frame", "-1"], "--frame"),
        (&["--dims", "4,4,4", "--frame", "abc"], "--frame"),
        (&["--dims", "4,4,4", "--array", "foo"], "--array"),
        (&["--dims", "4,4,4", "--spacing", "0,1,1"], "--spacing"),
    ] {
        cases.push(render_file("v.raw", extra, names));
    }
    for (extra, names) in [
        (&["--dims", "4,4,4"][..], "--dims"),
        (&["--dtype", "u8"], "--dtype"),
        (&["--endian", "big"], "--endian"),
        (&["--frame", "1"], "--frame"),
        (&["--array", "x"], "--array"),
    ] {
        cases.push(render_file("v.npy", extra, names));
    }
    cases.push(render_file(
        "neg.raw",
        &["--dims", "3,3,3", "--log"],
        "--log",
    ));
    cases
}

fn bench_cases() -> Vec<Refused> {
    let base = ["bench", "sphere:8", "--size", "8", "--json", "{out}/b.json"];
    let peers = ["bench", "--peers", "{fix}", "--json", "{out}/b.json"];
    let mut cases = Vec::new();
    for v in ["0", "1001", "-1", "abc", ""] {
        cases.push(refused(&base, &["--frames", v], "--frames"));
    }
    for (extra, names) in [
        (&["--cases", "a:1"][..], "--peers"),
        (&["--vs-vtk"], "--peers"),
        (&["--peers-python", "/usr/bin/python3"], "--vs-vtk"),
        (&["--peers", "{fix}"], "--peers"),
        (&["--step", "0"], "--step"),
        (&["--step", "1e-12"], "--step"),
        (&["--size", "0"], "--size"),
        (&["--opacity", "1,0"], "--opacity"),
        (&["--blend", "mip", "--iso", "1"], "--iso"),
        (&["--threads", "0"], "--threads"),
        (&["--up", "1,0,0"], "--up"),
        (&["--turntable", "3"], "--turntable"),
        (&["--dims", "4,4,4"], "--dims"),
    ] {
        cases.push(refused(&base, extra, names));
    }
    for (extra, names) in [
        (&["--cases", "a"][..], "--cases"),
        (&["--cases", "a:0"], "--cases"),
        (&["--cases", "a:99999"], "--cases"),
        (&["--cases", "../a:10"], "--cases"),
        (&["--cases", ",a:10"], "--cases"),
        (&["--cases", "a:10,"], "--cases"),
        (&["--cases", ""], "--cases"),
        // The workloads fix their own view: the view options do not apply.
        (&["--size", "8"], "--size"),
        (&["--step", "0.25"], "--step"),
        (&["--colormap", "magma"], "--colormap"),
        (&["--reference"], "--reference"),
        (&["--spacing", "1,1,1"], "--spacing"),
        (&["--nonfinite", "transparent"], "--nonfinite"),
        (&["--max-memory", "1G"], "--max-memory"),
    ] {
        cases.push(refused(&peers, extra, names));
    }
    cases
}

fn info_cases() -> Vec<Refused> {
    let base = ["info", "sphere:8"];
    let mut cases = Vec::new();
    for v in ["0", "1001", "-1", "abc", "", "1.5"] {
        cases.push(refused(&base, &["--bins", v], "--bins"));
    }
    for (extra, names) in [
        (&["--size", "8"][..], "--size"),
        (&["--dims", "4,4,4"], "--dims"),
        (&["--spacing", "0,1,1"], "--spacing"),
        (&["--json=1"], "--json"),
    ] {
        cases.push(refused(&base, extra, names));
    }
    cases.push(refused(
        &["info", "{fix}/v.raw", "--dims", "4,4,4"],
        &["--dtype", "u7"],
        "--dtype",
    ));
    cases
}

fn generate_cases() -> Vec<Refused> {
    let h = ["generate", "hydrogen", "--grid", "4", "-o", "{out}/h.nrrd"];
    let state = ["--n", "2", "--l", "1", "--m", "0"];
    let mut cases = Vec::new();
    for (extra, names) in [
        (&["--l", "0", "--m", "0"][..], "--n"),
        (&["--n", "2", "--l", "1"], "--m"),
        (&["--n", "0", "--l", "0", "--m", "0"], "--n"),
        (&["--n", "13", "--l", "0", "--m", "0"], "--n"),
        (&["--n", "-1", "--l", "0", "--m", "0"], "--n"),
        (&["--n", "abc", "--l", "0", "--m", "0"], "--n"),
        (&["--n", "", "--l", "0", "--m", "0"], "--n"),
        (&["--n", "2", "--l", "2", "--m", "0"], "--l"),
        (&["--n", "2", "--l", "-1", "--m", "0"], "--l"),
        (&["--n", "2", "--l", "1", "--m", "2"], "--m"),
        (&["--n", "2", "--l", "1", "--m", "-2"], "--m"),
        (&["--n", "2", "--l", "1", "--m", "x"], "--m"),
    ] {
        cases.push(refused(&h, extra, names));
    }
    let with_state = |extra: &[&str], names| {
        let mut r = refused(&h, &state, names);
        r.args.extend(extra.iter().map(|s| s.to_string()));
        r
    };
    for v in ["0", "1", "-5", "100000", "99999999999999999999", "abc"] {
        cases.push(with_state(&["--grid", v], "--grid"));
    }
    for v in ["0", "-1", "nan", "inf", "abc", ""] {
        cases.push(with_state(&["--extent", v], "--extent"));
    }
    let mut txt = refused(&h[..4], &state, ".txt");
    txt.args.extend(["-o", "{out}/h.txt"].map(String::from));
    cases.push(txt);
    cases.push(with_state(&["--real=no"], "--real"));

    let f = ["generate", "fractal", "-o", "{out}/f.nrrd"];
    for (flag, values) in [
        ("--size", &["0", "4", "2", "1", "-1", "2049", "abc"][..]),
        ("--dimension", &["2.9", "4", "nan", "inf", "abc"]),
        ("--sigma", &["0", "-1", "nan", "inf", "1e300", "1e-300"]),
        ("--seed", &["-1", "abc", "18446744073709551616", "1.5"]),
        ("--ramp", &["0", "1.5", "-1", "nan"]),
        ("--threshold", &["1", "-0.1", "nan", "x"]),
    ] {
        for v in values {
            // A small size unless the size is the case (twice is refused).
            let extra = match flag {
                "--size" => vec![flag, v],
                _ => vec!["--size", "5", flag, v],
            };
            cases.push(refused(&f, &extra, flag));
        }
    }
    for (extra, names) in [
        (&["--raw-field", "--ramp", "0.5"][..], "--ramp"),
        (&["--raw-field", "--threshold", "0.1"], "--threshold"),
        (&["--random-additions=1"], "--random-additions"),
    ] {
        cases.push(refused(&f, &[&["--size", "5"], extra].concat(), names));
    }
    cases.push(refused(
        &["generate", "fractal", "--size", "5"],
        &[],
        "--output",
    ));
    cases
}

fn paper_cases() -> Vec<Refused> {
    let base = ["paper", "--out", "{out}/paper"];
    let mut cases = Vec::new();
    for v in ["0", "-1", "70000", "abc", ""] {
        cases.push(refused(&base, &["--threads", v], "--threads"));
    }
    cases.push(refused(&base, &["figure9"], "[WHAT]"));
    cases.push(refused(&base, &["all", "all"], "'all'"));
    cases.push(refused(&base, &["--quick=1"], "--quick"));
    cases.push(refused(&["paper", "figure1a"], &[], "--out"));
    cases
}

fn volray(args: &[String]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(args)
        .output()
        .expect("volray runs")
}

/// Whether `err` names `flag` as a whole word: `--l` in `--l: ...` but
/// not in `--light`.
fn names(err: &str, flag: &str) -> bool {
    err.match_indices(flag).any(|(i, _)| {
        let next = err[i + flag.len()..].chars().next();
        !flag.starts_with("--") || !matches!(next, Some(c) if c.is_ascii_alphanumeric() || c == '-')
    })
}

fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(files_under(&path));
        }
        out.push(path);
    }
    out
}

/// Runs one refused case in a fresh directory; `Err` says what went wrong.
fn check(case: &Refused, fix: &Path) -> Result<(), String> {
    let dir = tempfile::tempdir().unwrap();
    let args: Vec<String> = (case.args.iter())
        .map(|a| {
            a.replace(OUT, dir.path().to_str().unwrap())
                .replace(FIX, fix.to_str().unwrap())
        })
        .collect();
    let run = volray(&args);
    let err = String::from_utf8_lossy(&run.stderr);
    let what = format!("{args:?}: {err:?}");
    if run.status.code() != Some(1) {
        return Err(format!("exit {:?}, not 1: {what}", run.status.code()));
    }
    if err.lines().count() != 1 || !err.starts_with("volray: ") || !err.ends_with('\n') {
        return Err(format!("not one line starting 'volray: ': {what}"));
    }
    if err.contains("panicked") {
        return Err(format!("panic: {what}"));
    }
    if !names(&err, case.names) {
        return Err(format!("does not name {}: {what}", case.names));
    }
    let left = files_under(dir.path());
    if !left.is_empty() {
        return Err(format!("left {left:?}: {what}"));
    }
    Ok(())
}

/// `f` of every item, over a few threads; the `Some` results.
fn par_filter_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> Option<R> + Sync) -> Vec<R> {
    let threads = 4;
    let f = &f;
    std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    items
                        .iter()
                        .skip(t)
                        .step_by(threads)
                        .filter_map(f)
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    })
}

fn assert_all_refused(cases: Vec<Refused>) {
    let fix = tempfile::tempdir().unwrap();
    fixtures(fix.path());
    let failures = par_filter_map(&cases, |c| check(c, fix.path()).err());
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

#[test]
fn render_refuses_bad_values_and_combinations_naming_the_flag() {
    let cases = render_cases();
    assert!(cases.len() > 200, "{}", cases.len());
    assert_all_refused(cases);
}

#[test]
fn bench_refuses_bad_values_and_combinations_naming_the_flag() {
    assert_all_refused(bench_cases());
}

#[test]
fn info_refuses_bad_values_naming_the_flag() {
    assert_all_refused(info_cases());
}

#[test]
fn generate_refuses_bad_values_naming_the_flag() {
    assert_all_refused(generate_cases());
}

#[test]
fn paper_refuses_bad_values_naming_the_flag() {
    assert_all_refused(paper_cases());
}

/// Every value at the edge of its option's range is taken: the command
/// succeeds and writes its output.
#[test]
fn boundary_values_are_accepted() {
    let fix = tempfile::tempdir().unwrap();
    fixtures(fix.path());
    let f = fix.path().to_str().unwrap();
    let raw = format!("{f}/v.raw");
    let r = |extra: &[&str]| {
        let mut a = vec!["render", "sphere:8", "-o", "{out}/x.png"];
        if !extra.contains(&"--size") {
            a.extend(["--size", "4"]);
        }
        a.extend_from_slice(extra);
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let mut cases: Vec<(Vec<String>, &str)> = vec![
        (r(&["--size", "1"]), "x.png"),
        (r(&["--size", "16384x1"]), "x.png"),
        (r(&["--step", "1e6"]), "x.png"),
        (r(&["--opacity", "0,1"]), "x.png"),
        (
            r(&["--ambient", "0", "--diffuse", "0", "--specular", "0"]),
            "x.png",
        ),
        (r(&["--shininess", "0", "--light-color", "0"]), "x.png"),
        (r(&["--light", "1e-100,0,0"]), "x.png"),
        (r(&["--up", "0,0,1e100"]), "x.png"),
        (r(&["--background", "1,1,1"]), "x.png"),
        (r(&["--threads", "1"]), "x.png"),
        (r(&["--iso", "0.5", "--iso-thickness", "1e6"]), "x.png"),
        (r(&["--gradient-opacity", "0,1"]), "x.png"),
        (r(&["--perspective", "179.9"]), "x.png"),
        (r(&["--zoom", "1e-3"]), "x.png"),
        (r(&["--azimuth", "1e6", "--elevation", "-1e6"]), "x.png"),
        (r(&["--clip", "0,0,0,1e100,0,0"]), "x.png"),
        (r(&["--crop", "-1,1,-1,1,-1e-9,1e-9"]), "x.png"),
        (r(&["--range", "-1e300,1e300"]), "x.png"),
        (r(&["--spacing", "1,1,1e6", "--step", "1e6"]), "x.png"),
        (r(&["--spacing", "1e-30,1e-30,1e-30"]), "x.png"),
        (r(&["--bit-depth", "16"]), "x.png"),
        (r(&["--blend", "mip", "--no-shading", "--jitter"]), "x.png"),
    ];
    let mut add = |args: &[&str], out: &'static str| {
        cases.push((args.iter().map(|s| s.to_string()).collect(), out));
    };
    add(
        &[
            "render",
            "sphere:8",
            "--size",
            "4",
            "--turntable",
            "1",
            "--fps",
            "100",
            "-o",
            "{out}/t.gif",
        ],
        "t.gif",
    );
    add(
        &[
            "render",
            "sphere:8",
            "--size",
            "4",
            "--turntable",
            "2",
            "--fps",
            "0.01",
            "-o",
            "{out}/t.png",
        ],
        "t.png",
    );
    add(
        &[
            "render",
            &raw,
            "--dims",
            "4,4,4",
            "--dtype",
            "f32",
            "--endian",
            "little",
            "--size",
            "4",
            "-o",
            "{out}/x.png",
        ],
        "x.png",
    );
    add(
        &[
            "render",
            &raw,
            "--dims",
            "2,2,16",
            "--size",
            "4",
            "-o",
            "{out}/x.png",
        ],
        "x.png",
    );
    add(
        &[
            "bench",
            "sphere:8",
            "--size",
            "4",
            "--frames",
            "1",
            "--json",
            "{out}/b.json",
        ],
        "b.json",
    );
    add(
        &[
            "generate",
            "hydrogen",
            "--n",
            "12",
            "--l",
            "11",
            "--m",
            "-11",
            "--grid",
            "2",
            "-o",
            "{out}/h.nrrd",
        ],
        "h.nrrd",
    );
    add(
        &[
            "generate",
            "hydrogen",
            "--n",
            "1",
            "--l",
            "0",
            "--m",
            "0",
            "--grid",
            "2",
            "--extent",
            "1e-3",
            "-o",
            "{out}/h.npy",
        ],
        "h.npy",
    );
    add(
        &[
            "generate",
            "fractal",
            "--size",
            "3",
            "--dimension",
            "3",
            "--sigma",
            "1e30",
            "--ramp",
            "1",
            "--threshold",
            "0",
            "--seed",
            "18446744073709551615",
            "-o",
            "{out}/f.raw",
        ],
        "f.raw",
    );
    add(
        &[
            "generate",
            "fractal",
            "--size",
            "3",
            "--sigma",
            "1e-30",
            "--raw-field",
            "-o",
            "{out}/f.raw",
        ],
        "f.raw",
    );
    let failures = par_filter_map(&cases, |(args, out)| {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path().to_str().unwrap();
        let args: Vec<String> = args.iter().map(|a| a.replace(OUT, d)).collect();
        let run = volray(&args);
        let ok = run.status.success() && dir.path().join(out).is_file();
        (!ok).then(|| format!("{args:?}: {}", String::from_utf8_lossy(&run.stderr)))
    });
    assert!(failures.is_empty(), "refused:\n{}", failures.join("\n"));
    // An info run writes nothing; its bins are the accepted extremes.
    for bins in ["1", "1000"] {
        let run = volray(&["info", "sphere:8", "--bins", bins].map(String::from));
        assert!(run.status.success(), "--bins {bins}");
        let text = String::from_utf8_lossy(&run.stdout);
        assert!(text.contains(&format!("({bins} bins)")), "{text}");
    }
}
