//! The Python module's tests (crates/python/tests, pytest), run by `cargo
//! test`: a virtual environment in `target/pyenv` with maturin, pytest and
//! numpy from PyPI (made once), and jupyterlab, notebook and anywidget for
//! `volray.view`'s widget (test_jupyter.py drives them in Debian's
//! chromium), the module built into it by `maturin develop --release`,
//! then pytest with this build's `volray` binary as the oracle. Without
//! python3 the test fails under `CI=true` and says so otherwise.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(what: &str, command: &mut Command) {
    let status = command
        .status()
        .unwrap_or_else(|e| panic!("{what}: cannot run: {e}"));
    assert!(status.success(), "{what}: {status}");
}

/// The virtual environment, made (and its tools installed) if missing.
fn venv(python: &str) -> PathBuf {
    let venv = root().join("target/pyenv");
    let bin = venv.join("bin");
    if !bin.join("pytest").exists() || !bin.join("maturin").exists() {
        run(
            "python3 -m venv target/pyenv",
            Command::new(python).args(["-m", "venv"]).arg(&venv),
        );
        run(
            "pip install maturin pytest numpy",
            Command::new(bin.join("pip")).args([
                "install",
                "--quiet",
                "maturin>=1.5,<2",
                "pytest",
                "numpy",
            ]),
        );
    }
    if !bin.join("jupyter-lab").exists() || !bin.join("jupyter-notebook").exists() {
        run(
            "pip install jupyterlab notebook anywidget",
            Command::new(bin.join("pip")).args(JUPYTER),
        );
    }
    venv
}

/// What `volray.view` needs in a notebook, and the front ends its test
/// drives: `pip` arguments.
const JUPYTER: [&str; 5] = ["install", "--quiet", "jupyterlab", "notebook", "anywidget"];

fn python3() -> Option<String> {
    let found = Command::new("python3").arg("--version").output();
    found
        .ok()
        .filter(|o| o.status.success())
        .map(|_| "python3".to_string())
}

#[test]
fn the_python_module_passes_its_tests() {
    let Some(python) = python3() else {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "python3 is needed for the Python module's tests"
        );
        eprintln!("skipped: python3 not found (the Python module's tests need it)");
        return;
    };
    let venv = venv(&python);
    let bin = venv.join("bin");
    let crate_dir = root().join("crates/python");
    run(
        "maturin develop --release",
        Command::new(bin.join("maturin"))
            .args(["develop", "--release", "--quiet"])
            .current_dir(&crate_dir)
            .env("VIRTUAL_ENV", &venv)
            .env("PATH", path_with(&bin)),
    );
    run(
        "pytest crates/python/tests",
        Command::new(bin.join("pytest"))
            .args(["-q", "-p", "no:cacheprovider"])
            .arg(crate_dir.join("tests"))
            .env("VOLRAY_BIN", env!("CARGO_BIN_EXE_volray"))
            .current_dir(root()),
    );
}

fn path_with(dir: &Path) -> std::ffi::OsString {
    let mut paths = vec![dir.to_path_buf()];
    paths.extend(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    ));
    std::env::join_paths(paths).expect("PATH entries without separators")
}
