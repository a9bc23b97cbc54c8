"""The example script runs on the fixtures and writes what it says."""

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]


def test_the_scan_and_orbital_example_writes_its_pictures(tmp_path):
    done = subprocess.run(
        [
            sys.executable,
            str(REPO / "examples/python_scan_and_orbital.py"),
            str(REPO / "crates/io/tests/fixtures/nifti/f32.nii"),
            str(REPO / "crates/io/tests/fixtures/cube/orbitals_angstrom.cube"),
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    for name in ("scan.png", "orbital.png", "lobes.png", "scan_mip_turntable.npy"):
        assert (tmp_path / name).stat().st_size > 0, name
    assert "NIfTI" in done.stdout
