"""Shared helpers: the volray command line (the oracle the module must
match) and a small PNG decoder, so that the tests need nothing beyond
numpy and pytest."""

import importlib
import os
import shutil
import signal
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[3]

# The Ctrl-C tests simulate SIGINT (PyErr_SetInterrupt), which Python
# ignores where SIGINT was ignored when it started: a shell's background
# job (`cargo test ... &`, nohup) starts so. Python's own handler, as in
# a terminal, whoever started the tests.
signal.signal(signal.SIGINT, signal.default_int_handler)


def written_by(tmp_path_factory, script, modules, what):
    """A new directory holding the files `script` (a path under the
    repository) writes with this python; skipped where one of `modules`
    is missing, except under CI=true, where that is a failure."""
    try:
        for module in modules:
            importlib.import_module(module)
    except ImportError:
        if os.environ.get("CI") == "true":
            raise
        pytest.skip(f"{what} missing (.ci/run installs them)")
    out = tmp_path_factory.mktemp(Path(script).parent.name)
    subprocess.run([sys.executable, str(REPO / script), str(out)], check=True)
    return out


def volray_binary():
    """The command line: $VOLRAY_BIN (set by the Rust test that runs
    pytest), else a built one in target/."""
    found = os.environ.get("VOLRAY_BIN")
    if found:
        return found
    for profile in ("release", "debug"):
        candidate = REPO / "target" / profile / "volray"
        if candidate.exists():
            return str(candidate)
    return shutil.which("volray")


@pytest.fixture(scope="session")
def cli():
    binary = volray_binary()
    if binary is None:
        pytest.fail("the volray binary is needed: run cargo build (or set VOLRAY_BIN)")

    def run(*args, check=True):
        done = subprocess.run(
            [binary, *map(str, args)], capture_output=True, text=True, timeout=300
        )
        if check and done.returncode != 0:
            raise AssertionError(f"volray {' '.join(map(str, args))}: {done.stderr}")
        return done

    return run


def read_png(path):
    """An 8- or 16-bit RGB or RGBA PNG (not interlaced) as an (H, W, C) array."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    assert interlace == 0 and colour in (2, 6)
    channels = 3 if colour == 2 else 4
    bpp = channels * depth // 8
    stride = width * bpp
    raw = zlib.decompress(idat)
    out = np.zeros((height, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, dtype=np.int32)
        if kind == 0:
            cur = line
        elif kind == 2:
            cur = (line + prev) & 255
        else:
            for x in range(stride):
                a = cur[x - bpp] if x >= bpp else 0
                b = prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                if kind == 1:
                    pred = a
                elif kind == 3:
                    pred = (a + b) // 2
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + pred) & 255
        out[y] = cur
        prev = cur
    if depth == 16:
        out = (out[:, 0::2] << 8) | out[:, 1::2]
    return out.reshape(height, width, channels)


@pytest.fixture
def cli_image(cli, tmp_path):
    """The RGB pixels `volray render ARGS` writes."""

    def render(*args):
        out = tmp_path / "cli.png"
        cli("render", *args, "-o", out)
        return read_png(out)

    return render


def rgb(frame):
    return np.asarray(frame)[:, :, :3].astype(np.int32)
