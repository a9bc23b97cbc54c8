"""volray.view in JupyterLab and in Notebook 7: a notebook executed in a
headless Chromium (Debian's chromium and chromedriver, over WebDriver) by
a ``jupyter lab`` (``jupyter notebook``) this test starts on a free
loopback port with a token, under a base URL as JupyterHub's proxy gives
one (``/user/volray/``). The widget shows the
viewer's page with the notebook's colours, a drag changes its frame, and
``volray.render(ball, camera=w.camera, tf=w.transfer_function)`` in the
next cell equals the still frame the page shows, pixel for pixel; then
the page follows the notebook into its dark theme.

Without chromium, chromedriver, jupyterlab, notebook or anywidget the test is
skipped with the reason, except under ``CI=true``, where it fails.
"""

import base64
import json
import os
import secrets
import shutil
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

from conftest import read_png

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
BASE = "/user/volray/"
# Each front end: its command and its package.
APPS = {"lab": ("jupyter-lab", "jupyterlab"), "notebook": ("jupyter-notebook", "notebook")}
# Far more than anything needs (seconds), so that a slow machine never
# fails the test while a broken widget does not hang it.
PATIENCE = 120.0


def missing_tools():
    missing = [p for p in (CHROMIUM, CHROMEDRIVER) if not Path(p).exists()]
    for command, package in APPS.values():
        if not (Path(sys.executable).parent / command).exists():
            missing.append(f"{package} (pip install {package})")
    try:
        import anywidget  # noqa: F401
    except ImportError:
        missing.append("anywidget (pip install anywidget)")
    return missing


@pytest.fixture
def tools():
    missing = missing_tools()
    if missing:
        note = f"the Jupyter test needs {', '.join(missing)}"
        if os.environ.get("CI") == "true":
            pytest.fail(f"CI=true: {note}")
        pytest.skip(note)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait(what, check, patience=PATIENCE):
    start = time.monotonic()
    while True:
        value = check()
        if value:
            return value
        if time.monotonic() - start > patience:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.05)


class WebDriver:
    """Just what the test needs of WebDriver, over HTTP."""

    def __init__(self, port, profile):
        self.url = f"http://127.0.0.1:{port}"
        capabilities = {
            "alwaysMatch": {
                "goog:chromeOptions": {
                    "binary": CHROMIUM,
                    "args": [
                        "--headless",
                        "--no-sandbox",
                        "--disable-gpu",
                        "--disable-background-networking",
                        "--disable-component-update",
                        "--disable-sync",
                        "--no-first-run",
                        "--disable-dev-shm-usage",
                        "--window-size=1200,900",
                        f"--user-data-dir={profile}",
                    ],
                }
            }
        }
        session = wait(
            "a WebDriver session",
            lambda: self._try("POST", "/session", {"capabilities": capabilities}),
        )
        self.session = f"/session/{session['sessionId']}"

    def _try(self, method, path, body=None):
        try:
            return self.call(method, path, body, session=False)
        except (urllib.error.URLError, ConnectionError):
            return None

    def call(self, method, path, body=None, session=True):
        url = self.url + (self.session if session else "") + path
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(url, data=data, method=method)
        request.add_header("Content-Type", "application/json")
        try:
            with urllib.request.urlopen(request, timeout=PATIENCE) as answer:
                return json.loads(answer.read())["value"]
        except urllib.error.HTTPError as e:
            raise AssertionError(f"WebDriver {path}: {e.read()[:500]!r}") from None

    def go(self, url):
        self.call("POST", "/url", {"url": url})

    def run(self, script, *args):
        return self.call("POST", "/execute/sync", {"script": script, "args": list(args)})

    def run_async(self, script, *args):
        return self.call("POST", "/execute/async", {"script": script, "args": list(args)})

    def until(self, what, expression):
        return wait(what, lambda: self.run(f"return {expression};"))

    def element(self, selector):
        found = self.call("POST", "/element", {"using": "css selector", "value": selector})
        return found

    def into_frame(self, element):
        self.call("POST", "/frame", {"id": element})

    def out_of_frames(self):
        self.call("POST", "/frame", {"id": None})

    def drag(self, element, by, steps=8):
        moves = [
            {"type": "pointerMove", "duration": 0, "origin": element, "x": 0, "y": 0},
            {"type": "pointerDown", "button": 0},
        ]
        for _ in range(steps):
            moves.append(
                {
                    "type": "pointerMove",
                    "duration": 16,
                    "origin": "pointer",
                    "x": round(by[0] / steps),
                    "y": round(by[1] / steps),
                }
            )
        moves.append({"type": "pointerUp", "button": 0})
        actions = [{"type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"}, "actions": moves}]
        self.call("POST", "/actions", {"actions": actions})
        self.call("DELETE", "/actions")

    def quit(self):
        try:
            self.call("DELETE", "")
        except Exception:
            pass


NOTEBOOK_CELLS = [
    # The widget.
    """import json, numpy as np, volray
x, y, z = np.mgrid[-1:1:48j, -1:1:48j, -1:1:48j]
ball = (np.exp(-4 * (x * x + y * y + z * z)) * (1.2 + np.sin(4 * x + 2 * y))).astype(np.float32)
w = volray.view(ball, size=(160, 120), azimuth=30, elevation=10, height=420)
w""",
    # The read-back, rendered: its pixels and its camera, for the test.
    """frame = volray.render(ball, camera=w.camera, tf=w.transfer_function)
np.save("expected.npy", np.asarray(frame))
json.dump({"azimuth": w.camera.azimuth, "elevation": w.camera.elevation,
           "size": list(w.camera.size), "state": w.state}, open("camera.json", "w"))""",
    # The page's Figure box read back: render's keywords, the colour bar too.
    """figure = volray.render(ball, **w.keywords)
np.save("figure.npy", np.asarray(figure))
json.dump(sorted(w.keywords), open("keywords.json", "w"))""",
]


def notebook():
    cells = [
        {
            "cell_type": "code",
            "execution_count": None,
            "metadata": {},
            "outputs": [],
            "source": source,
        }
        for source in NOTEBOOK_CELLS
    ]
    return {
        "cells": cells,
        "metadata": {
            "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"}
        },
        "nbformat": 4,
        "nbformat_minor": 5,
    }


@pytest.fixture(params=["lab", "notebook"])
def lab(request, tools, tmp_path):
    """A JupyterLab (a Notebook 7) on a free loopback port, under BASE,
    with a token; its root is `tmp_path/root`, which holds the notebook.
    Gives the notebook's URL, the token, the root and `tmp_path`."""
    app = request.param
    root = tmp_path / "root"
    root.mkdir()
    (root / "view.ipynb").write_text(json.dumps(notebook()))
    token = secrets.token_hex(16)
    port = free_port()
    env = dict(os.environ)
    env.update(
        JUPYTER_CONFIG_DIR=str(tmp_path / "config"),
        JUPYTER_RUNTIME_DIR=str(tmp_path / "runtime"),
        IPYTHONDIR=str(tmp_path / "ipython"),
        JUPYTER_PLATFORM_DIRS="1",
    )
    log = open(tmp_path / "lab.log", "wb")
    server = subprocess.Popen(
        [
            str(Path(sys.executable).parent / APPS[app][0]),
            "--no-browser",
            "--ip=127.0.0.1",
            f"--port={port}",
            "--ServerApp.port_retries=0",
            f"--IdentityProvider.token={token}",
            f"--ServerApp.base_url={BASE}",
            f"--ServerApp.root_dir={root}",
            "--allow-root",
            "--expose-app-in-browser",
            *(
                [
                    f"--LabApp.workspaces_dir={tmp_path / 'workspaces'}",
                    "--LabApp.news_url=",
                    "--LabApp.extension_manager=readonly",
                    "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
                ]
                if app == "lab"
                else []
            ),
        ],
        stdout=log,
        stderr=subprocess.STDOUT,
        env=env,
        cwd=root,
    )
    url = f"http://127.0.0.1:{port}{BASE}"

    def up():
        if server.poll() is not None:
            raise AssertionError(f"jupyter lab exited: {(tmp_path / 'lab.log').read_text()[-3000:]}")
        try:
            with urllib.request.urlopen(f"{url}api/status?token={token}", timeout=5) as r:
                return r.status == 200
        except (urllib.error.URLError, ConnectionError):
            return False

    try:
        wait("jupyter lab to answer", up)
        page = "lab/tree" if app == "lab" else "notebooks"
        yield f"{url}{page}/view.ipynb?token={token}", root, tmp_path
    finally:
        server.terminate()
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
        log.close()


@pytest.fixture
def browser(tmp_path):
    port = free_port()
    driver = subprocess.Popen(
        [CHROMEDRIVER, f"--port={port}"],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    web = None
    try:
        web = WebDriver(port, tmp_path / "profile")
        yield web
    finally:
        if web is not None:
            web.quit()
        driver.terminate()
        driver.wait()


RUN_CELL = """
const [index] = arguments;
const app = window.jupyterapp;
const panel = app.shell.currentWidget;
panel.content.activeCellIndex = index;
app.commands.execute("notebook:run-cell");
return true;
"""

KERNEL_IDLE = """(() => {
  const app = window.jupyterapp;
  const panel = app && app.shell.currentWidget;
  const kernel = panel && panel.sessionContext && panel.sessionContext.session
    && panel.sessionContext.session.kernel;
  return !!(kernel && kernel.status === "idle" && panel.content.widgets.length === CELLS);
})()""".replace("CELLS", str(len(NOTEBOOK_CELLS)))

FRAME_BYTES = """
const done = arguments[arguments.length - 1];
fetch(document.getElementById("frame").src)
  .then((r) => r.arrayBuffer())
  .then((b) => {
    let s = "";
    for (const x of new Uint8Array(b)) s += String.fromCharCode(x);
    done(btoa(s));
  })
  .catch((e) => done("error: " + e));
"""


def test_the_widget_shows_the_view_and_reads_it_back(lab, browser):
    notebook_url, root, tmp = lab
    web = browser
    web.go(notebook_url)
    web.until("the notebook with its kernel idle", KERNEL_IDLE)

    # The widget: the page in its iframe, with the notebook's colours.
    web.run(RUN_CELL, 0)
    web.until("the widget's iframe", "document.querySelector('iframe.volray-view') !== null")
    theirs = web.run(
        "return getComputedStyle(document.querySelector('iframe.volray-view'))"
        ".getPropertyValue('--jp-layout-color2').trim();"
    )
    iframe = web.element("iframe.volray-view")
    web.into_frame(iframe)
    web.until("the first still frame", "document.body.dataset.state === 'still'")
    assert web.run("return document.getElementById('frame').naturalWidth;") == 160
    assert theirs, "the notebook's theme has --jp-layout-color2"
    assert web.run("return document.documentElement.style.getPropertyValue('--bg');") == theirs
    assert web.run("return getComputedStyle(document.body).getPropertyValue('--bg').trim();") == theirs
    before = frame_bytes(web)
    frames = int(web.run("return document.body.dataset.frames;"))

    # A drag orbits: new frames, then the still of the new view.
    web.drag(web.element("#frame"), (60, 25))
    web.until(
        "the still after the drag",
        f"document.body.dataset.state === 'still' && Number(document.body.dataset.frames) > {frames + 1}",
    )
    shown = frame_bytes(web)
    assert shown != before, "the drag changed the frame"
    assert "volray.render(volume, camera=volray.Camera(size=(160, 120)" in web.run(
        "return document.getElementById('command').textContent;"
    )
    (tmp / "shown.png").write_bytes(shown)
    shown = read_png(tmp / "shown.png")

    # The next cell renders the view read back from the widget.
    web.out_of_frames()
    web.run(RUN_CELL, 1)
    wait("the read-back cell's files", lambda: (root / "camera.json").exists() and (root / "expected.npy").exists())
    wait("camera.json written whole", lambda: _json(root / "camera.json"))
    camera = _json(root / "camera.json")
    assert camera["size"] == [160, 120]
    assert camera["azimuth"] != 30, f"the drag orbited: {camera}"
    expected = np.load(root / "expected.npy")
    assert expected.shape[:2] == (120, 160)
    assert shown.shape[:2] == (120, 160)
    diff = np.abs(expected[:, :, :3].astype(np.int32) - shown[:, :, :3].astype(np.int32))
    assert diff.max() == 0, f"{np.count_nonzero(diff.max(axis=2))} pixels differ, by up to {diff.max()}"
    assert expected[:, :, :3].std() > 5, "the frame shows something"

    # The Figure box: a colour bar and the box's outline drawn into the
    # frame, and `render(ball, **w.keywords)` draws them alike.
    web.into_frame(web.element("iframe.volray-view"))
    web.run("document.getElementById('f-colorbar').click(); document.getElementById('f-outline').click();")
    # The command comes with its frame: the still that shows both.
    web.until(
        "the still with the figure",
        "document.body.dataset.state === 'still'"
        " && document.getElementById('command').textContent.includes('outline=True')"
        " && document.getElementById('command').textContent.includes('colorbar=')",
    )
    (tmp / "figure.png").write_bytes(frame_bytes(web))
    annotated = read_png(tmp / "figure.png")
    assert not np.array_equal(annotated[:, :, :3], shown[:, :, :3]), "the figure was drawn"
    web.out_of_frames()
    web.run(RUN_CELL, 2)
    wait("the figure cell's files", lambda: (root / "figure.npy").exists() and _json(root / "keywords.json"))
    assert {"colorbar", "outline", "camera", "tf"} <= set(_json(root / "keywords.json"))
    rendered = np.load(root / "figure.npy")
    diff = np.abs(rendered[:, :, :3].astype(np.int32) - annotated[:, :, :3].astype(np.int32))
    assert diff.max() == 0, f"{np.count_nonzero(diff.max(axis=2))} pixels differ, by up to {diff.max()}"

    # The page follows a change of the notebook's theme.
    web.run("window.jupyterapp.commands.execute('apputils:change-theme', {theme: 'JupyterLab Dark'});")
    web.until("the dark theme", "document.body.dataset.jpThemeLight === 'false'")
    dark = wait(
        "the dark theme's colours",
        lambda: (
            web.run(
                "return getComputedStyle(document.querySelector('iframe.volray-view'))"
                ".getPropertyValue('--jp-layout-color2').trim();"
            )
            or ""
        ).lower()
        not in ("", theirs.lower())
        and web.run(
            "return getComputedStyle(document.querySelector('iframe.volray-view'))"
            ".getPropertyValue('--jp-layout-color2').trim();"
        ),
    )
    web.into_frame(web.element("iframe.volray-view"))
    web.until("the page's dark colours", f"document.documentElement.style.getPropertyValue('--bg') === {json.dumps(dark)}")
    assert web.run("return document.body.dataset.theme;") == "dark"


def frame_bytes(web):
    """The PNG the page shows in #frame, as the kernel sent it."""
    text = web.run_async(FRAME_BYTES)
    assert not text.startswith("error"), text
    return base64.b64decode(text)


def _json(path):
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None
