//! `volray bench --peers DIR --vs-vtk`: VTK's `vtkFixedPointVolumeRayCastMapper`
//! timed on the same workload in the same run, through the peers' own
//! harness (`vtk_bench.py` in DIR's parent, run by the Python of the
//! peers' venv), and its image compared with volray's.
//!
//! VTK's time is the mapper's own `GetTimeToDraw()` median over the same
//! number of frames after its warm-up, as the peers report it; its image is
//! the one `vtk_bench.py` writes for that case.

use super::{input, io};
use crate::AppError;
use std::path::{Path, PathBuf};
use std::process::Command;
use volray_core::Image;
use volray_io::BitDepth;

/// The environment variable naming the peers' Python.
const PYTHON_VAR: &str = "VOLRAY_PEERS_PYTHON";

/// Reads two PNGs and prints the mean absolute difference of their RGB
/// values and their two means, in levels of 255.
const COMPARE: &str = "import sys, numpy as np
from PIL import Image
a, b = (np.asarray(Image.open(p).convert('RGB'), dtype=float) for p in sys.argv[1:3])
if a.shape != b.shape: sys.exit(f'image sizes differ: {a.shape} vs {b.shape}')
print(np.abs(a - b).mean(), a.mean(), b.mean())";

/// The peers' harness, ready to run.
pub struct Harness {
    python: PathBuf,
    dir: PathBuf,
    /// Scratch files of this run, removed at the end.
    scratch: PathBuf,
}

/// One VTK run of a workload, and how its image compares with volray's.
#[derive(Debug, Clone)]
pub struct VtkRun {
    pub median_s: f64,
    png: PathBuf,
    /// Mean absolute difference of the RGB values, levels of 255.
    pub mean_abs_diff: f64,
    pub mean_volray: f64,
    pub mean_vtk: f64,
}

impl Harness {
    /// The harness around the volumes in `volumes` (its parent directory),
    /// with `python` or the peers' venv.
    pub fn find(volumes: &Path, python: Option<&Path>) -> Result<Self, AppError> {
        let fail = |what: String| input(format!("--vs-vtk: {what}"));
        // The parent of DIR as given (DIR itself may be a link).
        let given = std::path::absolute(volumes)
            .map_err(|e| fail(format!("{}: {e}", volumes.display())))?;
        let dir = given
            .parent()
            .ok_or_else(|| fail(format!("{} has no parent", given.display())))?
            .to_path_buf();
        let volumes = volumes
            .canonicalize()
            .map_err(|e| fail(format!("{}: {e}", volumes.display())))?;
        let script = dir.join("vtk_bench.py");
        if !script.is_file() {
            return Err(fail(format!(
                "{} not found: DIR must be the volumes/ directory of the peers' harness",
                script.display()
            )));
        }
        // vtk_bench.py reads the volumes beside it: they must be these.
        if dir.join("volumes").canonicalize().ok().as_ref() != Some(&volumes) {
            return Err(fail(format!(
                "{} is not {}/volumes, which VTK would render",
                volumes.display(),
                dir.display()
            )));
        }
        let python = match python {
            Some(p) => p.to_path_buf(),
            None => match std::env::var_os(PYTHON_VAR) {
                Some(p) => PathBuf::from(p),
                None => dir.join(".venv/bin/python"),
            },
        };
        let works = Command::new(&python)
            .args(["-c", "import vtk, numpy, PIL"])
            .output()
            .is_ok_and(|o| o.status.success());
        if !works {
            return Err(fail(format!(
                "{} cannot import vtk, numpy and PIL: run the peers' setup.sh in {}, or give the venv's Python with --peers-python or ${PYTHON_VAR}",
                python.display(),
                dir.display()
            )));
        }
        let scratch = std::env::temp_dir().join(format!("volray-bench-{}", std::process::id()));
        std::fs::create_dir_all(&scratch).map_err(|e| io(format!("{}: {e}", scratch.display())))?;
        Ok(Harness {
            python,
            dir,
            scratch,
        })
    }

    /// Times VTK on one workload: `frames` timed renders after a warm-up.
    pub fn run(
        &self,
        dataset: &str,
        window: usize,
        threads: usize,
        frames: u32,
    ) -> Result<VtkRun, AppError> {
        let json = self.scratch.join(format!("vtk_{dataset}_{window}.json"));
        let output = Command::new(&self.python)
            .arg(self.dir.join("vtk_bench.py"))
            .args(["--mappers", "fixedpoint", "--cases"])
            .arg(format!("{dataset}:{window}"))
            .args([
                "--threads",
                &threads.to_string(),
                "--n",
                &frames.to_string(),
            ])
            .args(["--wait-quiet", "0", "--json"])
            .arg(&json)
            .output()
            .map_err(|e| io(format!("{}: {e}", self.python.display())))?;
        if !output.status.success() {
            let err = String::from_utf8_lossy(&output.stderr);
            let last = err
                .lines()
                .rev()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("");
            return Err(io(format!(
                "vtk_bench.py failed on {dataset}:{window}: {last}"
            )));
        }
        let text =
            std::fs::read_to_string(&json).map_err(|e| io(format!("{}: {e}", json.display())))?;
        let bad = || io(format!("{}: not vtk_bench.py's results", json.display()));
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|_| bad())?;
        let result = &value["results"][0];
        let median_s = result["median_s"].as_f64().ok_or_else(bad)?;
        let png = self.dir.join(result["png"].as_str().ok_or_else(bad)?);
        Ok(VtkRun {
            median_s,
            png,
            mean_abs_diff: f64::NAN,
            mean_volray: f64::NAN,
            mean_vtk: f64::NAN,
        })
    }

    /// Compares volray's `image` of a workload with VTK's.
    pub fn compare(
        &self,
        run: VtkRun,
        image: &Image,
        dataset: &str,
        window: usize,
    ) -> Result<VtkRun, AppError> {
        let ours = self.scratch.join(format!("volray_{dataset}_{window}.png"));
        volray_io::write_png(&ours, image, BitDepth::Eight)?;
        let output = Command::new(&self.python)
            .args(["-c", COMPARE])
            .arg(&ours)
            .arg(&run.png)
            .output()
            .map_err(|e| io(format!("{}: {e}", self.python.display())))?;
        let text = String::from_utf8_lossy(&output.stdout);
        let numbers: Vec<f64> = text
            .split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect();
        match numbers[..] {
            [diff, a, b] if output.status.success() => Ok(VtkRun {
                mean_abs_diff: diff,
                mean_volray: a,
                mean_vtk: b,
                ..run
            }),
            _ => Err(io(format!(
                "comparing with {}: {}",
                run.png.display(),
                String::from_utf8_lossy(&output.stderr).trim()
            ))),
        }
    }
}

impl Drop for Harness {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.scratch);
    }
}
