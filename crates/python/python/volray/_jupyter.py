"""``volray.view``: the viewer in a notebook, an anywidget.

The page of ``volray view`` runs in a sandboxed iframe of the widget, and
its messages travel over the kernel's own connection (the widget's comm)
instead of a WebSocket: no port, no token, nothing to forward, so it works
behind JupyterHub's proxy prefix and over SSH as the notebook does. Each
output showing the widget is a page with its own renderer thread in the
kernel; frames are rendered on the kernel's CPU cores, JPEG while the view
moves and PNG once it stops, as ``volray view`` renders them.

A page acknowledges each frame it is given: at most a few go
unacknowledged (``volray_view::MAX_IN_FLIGHT``), the next waiting in the
kernel, so that a slow connection slows the renderer instead of filling
the comm. A page also says it is alive every ``_HEARTBEAT_S`` seconds: a
page not heard from for ``_TIMEOUT_S`` (reloaded, or its browser tab
closed, which sends no message) has its renderer closed, so that reloads
do not use up the pages a widget may open. While a cell runs the kernel
reads no message of any page, so no page is closed then, and each is
given ``_TIMEOUT_S`` again once the cell ends.
"""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path
from typing import Any, Dict, Optional

from ._volray import _ViewHost

try:
    import anywidget
    import traitlets
except ImportError as e:  # pragma: no cover - the message is the point
    raise ImportError(
        "volray.view needs anywidget in the kernel's environment: pip install anywidget"
    ) from e

_MAX_HEIGHT = 4096


class Viewer(anywidget.AnyWidget):
    """The viewer of one volume in a notebook (:func:`volray.view`).

    ``camera`` and ``transfer_function`` read back the view shown last,
    so that ``volray.render(volume, camera=w.camera,
    tf=w.transfer_function)`` renders its still frame, pixel for pixel,
    where the other keywords are left at their defaults;
    ``volray.render(volume, **w.keywords)`` does whatever they are.
    """

    _esm = Path(__file__).parent / "_widget.js"
    _page = traitlets.Unicode("").tag(sync=True)
    height = traitlets.Int(560).tag(sync=True)
    # How often a page says it is alive, and how long the kernel waits
    # before closing the renderer of a page it has not heard from.
    _HEARTBEAT_S = 2.0
    _TIMEOUT_S = 10.0
    _heartbeat_ms = traitlets.Int(int(_HEARTBEAT_S * 1000)).tag(sync=True)

    def __init__(self, host: _ViewHost, height: int = 560, **kwargs: Any) -> None:
        if isinstance(height, bool) or not isinstance(height, int):
            raise TypeError("height: expected an int (pixels)")
        if not 100 <= height <= _MAX_HEIGHT:
            raise ValueError(f"height: {height} pixels is not in 100 to {_MAX_HEIGHT}")
        super().__init__(
            _page=host.page,
            height=height,
            _heartbeat_ms=int(self._HEARTBEAT_S * 1000),
            **kwargs,
        )
        self._host = host
        self._tabs: Dict[str, Any] = {}
        # When each page was last heard from (time.monotonic()).
        self._seen: Dict[str, float] = {}
        self._lock = threading.Lock()
        self._reaping = False
        self._busy = False  # a cell runs: the pages' messages wait
        self.on_msg(self._on_message)
        self._shell = None
        try:
            from IPython import get_ipython

            shell = get_ipython()
        except ImportError:  # pragma: no cover - anywidget needs IPython
            shell = None
        if shell is not None and hasattr(shell, "events"):
            shell.events.register("pre_run_cell", self._cell_starts)
            shell.events.register("post_run_cell", self._cell_ends)
            self._shell = shell

    # ---------------------------------------------------------- read back

    @property
    def camera(self):
        """The camera of the view shown last, as a :class:`volray.Camera`."""
        return self._host.camera

    @property
    def transfer_function(self):
        """The transfer function of the view shown last, whole (window,
        opacity points, colours), as a :class:`volray.TransferFunction`."""
        return self._host.transfer_function

    @property
    def keywords(self) -> Dict[str, Any]:
        """The keywords of :func:`volray.render` that render the view
        shown last (beside those of the volume given to ``view``)."""
        return dict(self._host.keywords())

    @property
    def state(self) -> Dict[str, Any]:
        """The view shown last as the page's state (its JSON form)."""
        return json.loads(self._host.state())

    def __repr__(self) -> str:
        try:
            c = self.camera
        except ValueError:  # the last view asked for was refused
            return "volray.Viewer()"
        return (
            f"volray.Viewer(size={c.size}, azimuth={c.azimuth:g}, "
            f"elevation={c.elevation:g}, zoom={c.zoom:g})"
        )

    # ---------------------------------------------------------- the pages

    @property
    def pages(self) -> int:
        """How many pages have a renderer open in the kernel."""
        with self._lock:
            return len(self._tabs)

    def _on_message(self, _widget: Any, content: Any, _buffers: Any) -> None:
        if not isinstance(content, dict) or not isinstance(content.get("view"), str):
            return
        view = content["view"][:64]
        with self._lock:
            if view in self._tabs:
                self._seen[view] = time.monotonic()
        if content.get("open"):
            self._open(view, resume=content.get("resume") is True)
        elif content.get("ack"):
            with self._lock:
                tab = self._tabs.get(view)
            if tab is not None:
                tab.ack()
        elif content.get("alive"):
            with self._lock:
                known = view in self._tabs
            if not known:
                # Closed while the page was silent (a browser throttles a
                # hidden page's timers): it opens again, keeping its view.
                self.send({"view": view, "gone": True})
        elif isinstance(content.get("text"), str):
            with self._lock:
                tab = self._tabs.get(view)
            if tab is None:
                return
            refused = tab.receive(content["text"])
            if refused is not None:
                self.send({"view": view, "text": refused})
        elif content.get("close"):
            self._close(view)

    def _open(self, view: str, resume: bool = False) -> None:
        self._close(view)
        self._reap()
        try:
            tab = self._host.open()
        except RuntimeError as e:
            message = json.dumps({"type": "error", "seq": None, "message": str(e)})
            self.send({"view": view, "text": message})
            self.send({"view": view, "closed": True})
            return
        with self._lock:
            self._tabs[view] = tab
            self._seen[view] = time.monotonic()
            start_reaper = not self._reaping
            self._reaping = True
        threading.Thread(
            target=self._pump,
            args=(view, tab, resume),
            name=f"volray-view-{view}",
            daemon=True,
        ).start()
        if start_reaper:
            threading.Thread(target=self._reaper, name="volray-view-reaper", daemon=True).start()

    def _cell_starts(self, _info: Any = None) -> None:
        with self._lock:
            self._busy = True

    def _cell_ends(self, _result: Any = None) -> None:
        """The kernel reads the pages' messages again: each page is given
        ``_TIMEOUT_S`` from now."""
        now = time.monotonic()
        with self._lock:
            self._busy = False
            for view in self._seen:
                self._seen[view] = now

    def _reap(self) -> None:
        """Closes the renderers of the pages not heard from for
        ``_TIMEOUT_S`` seconds (none while a cell runs)."""
        now = time.monotonic()
        with self._lock:
            if self._busy:
                return
            silent = [v for v in self._tabs if now - self._seen.get(v, now) > self._TIMEOUT_S]
        for view in silent:
            self._close(view)

    def _reaper(self) -> None:
        """Reaps silent pages while any page is open."""
        while True:
            time.sleep(min(self._HEARTBEAT_S, self._TIMEOUT_S / 2))
            self._reap()
            with self._lock:
                if not self._tabs:
                    self._reaping = False
                    return

    def _pump(self, view: str, tab: Any, resume: bool = False) -> None:
        """Sends the tab's messages to its page until the tab closes (a
        resumed page keeps its view: its new hello is not sent)."""
        try:
            while True:
                message = tab.next()
                if message is None:
                    break
                is_frame, data = message
                if resume and not is_frame:
                    resume = False
                    continue
                if is_frame:
                    self.send({"view": view, "frame": True}, buffers=[data])
                else:
                    self.send({"view": view, "text": data})
        finally:
            tab.close()
            with self._lock:
                if self._tabs.get(view) is tab:
                    del self._tabs[view]
                    self._seen.pop(view, None)

    def _close(self, view: str) -> None:
        with self._lock:
            tab = self._tabs.pop(view, None)
            self._seen.pop(view, None)
        if tab is not None:
            tab.close()

    def close(self) -> None:
        """Closes every page's renderer, then the widget."""
        lock = getattr(self, "_lock", None)  # None: __init__ refused its arguments
        tabs = []
        if lock is not None:
            with lock:
                tabs = list(self._tabs.values())
                self._tabs.clear()
                self._seen.clear()
        for tab in tabs:
            tab.close()
        shell = getattr(self, "_shell", None)
        if shell is not None:
            for event, callback in [("pre_run_cell", self._cell_starts), ("post_run_cell", self._cell_ends)]:
                try:
                    shell.events.unregister(event, callback)
                except ValueError:  # pragma: no cover - unregistered already
                    pass
            self._shell = None
        super().close()


def view(volume: Any, *, height: int = 560, **options: Any) -> Viewer:
    """The viewer of ``volume`` (an array, a :class:`volray.Volume`, or
    the path of a file to :func:`volray.read`) in a notebook: drag to
    orbit, shift-drag to pan, the wheel to zoom, the transfer function
    edited over the histogram, as ``volray view`` shows it. ``options``
    are the keywords of :func:`volray.render`: the view it starts with,
    the figure's (``colorbar``, ``title``, ...) its Figure box; a chunked
    file's levels are read as the frames need them (``level``: the
    stills', ``"auto"`` by default). ``height`` is the widget's height in pixels. Without
    ``size`` the frame fits the widget."""
    if isinstance(volume, (str, Path)):
        from ._volray import read

        volume = read(volume)
    host = _ViewHost(volume, **options)
    return Viewer(host, height=height)
