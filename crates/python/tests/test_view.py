"""volray.view's kernel side, without a browser: the viewer's messages as
the widget carries them (``_ViewHost``, ``_ViewTab``), the frames it sends
equal to ``volray.render`` of the view read back, and bad input refused
with Python exceptions. tests/test_jupyter.py drives the widget in a
browser."""

import json
import threading
import time

import numpy as np
import pytest

import volray
from volray._volray import _ViewHost
from conftest import read_png, rgb


@pytest.fixture(scope="module")
def ball():
    x, y, z = np.mgrid[-1:1:32j, -1:1:32j, -1:1:32j]
    return (np.exp(-4 * (x * x + y * y + z * z)) * (1.2 + np.sin(4 * x + 2 * y))).astype(
        np.float32
    )


def frame_of(message, tmp_path):
    """A frame message's header and pixels."""
    is_frame, data = message
    assert is_frame, data
    n = int.from_bytes(data[:4], "little")
    header = json.loads(data[4 : 4 + n])
    path = tmp_path / "frame.png"
    path.write_bytes(data[4 + n :])
    return header, read_png(path)


def ask(tab, state, seq, quality="full"):
    """The next message after asking for `state`, a frame acknowledged as
    the widget's page acknowledges it."""
    refused = tab.receive(json.dumps({"type": "view", "seq": seq, "quality": quality, "state": state}))
    assert refused is None, refused
    message = tab.next()
    if message is not None and message[0]:
        tab.ack()
    return message


def test_the_frames_are_render_of_the_view_read_back(ball, tmp_path):
    host = _ViewHost(ball, size=(64, 48), azimuth=20, elevation=10)
    tab = host.open()
    is_frame, hello = tab.next()
    hello = json.loads(hello)
    assert not is_frame and hello["type"] == "hello"
    state = hello["start"]
    assert (state["width"], state["height"], state["azimuth"]) == (64, 48, 20)
    assert host.camera.azimuth == 20

    # An orbit: the camera and the transfer function read back render it.
    state["azimuth"] = 75
    header, shown = frame_of(ask(tab, state, 1), tmp_path)
    assert header["quality"] == "full" and header["command"].startswith("volray.render(volume,")
    assert host.camera.azimuth == 75
    expected = rgb(volray.render(ball, camera=host.camera, tf=host.transfer_function))
    assert np.array_equal(shown[:, :, :3], expected)
    assert expected.std() > 5

    # The page's look: its keywords render it.
    state.update(
        window=[0.1, 1.5],
        opacity=[[0, 0], [0.4, 0.1], [1, 0.8]],
        colormap="magma",
        step=0.5,
        shading=False,
        background=[0.2, 0.1, 0.0],
    )
    header, shown = frame_of(ask(tab, state, 2), tmp_path)
    # The Command box's call, run, renders the frame too.
    assert '.with_colormap("magma")' in header["command"]
    ran = eval(header["command"], {"volray": volray, "volume": ball})
    assert np.array_equal(shown[:, :, :3], rgb(ran))
    keywords = host.keywords()
    assert keywords["step"] == 0.5 and keywords["shading"] is False
    assert host.transfer_function.domain == (0.1, 1.5)
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ball, **keywords)))
    assert not np.array_equal(shown[:, :, :3], expected)

    # A projection, and its command.
    state.update(blend="mip", colormap="grey")
    header, shown = frame_of(ask(tab, state, 3), tmp_path)
    assert 'blend="mip"' in header["command"]
    ran = eval(header["command"], {"volray": volray, "volume": ball})
    assert np.array_equal(shown[:, :, :3], rgb(ran))
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ball, **host.keywords())))
    tab.close()
    assert tab.next() is None


def test_shadows_are_kept_while_lit_and_dropped_under_a_projection(ball, tmp_path):
    host = _ViewHost(ball, size=(48, 40), shadows=True, azimuth=40)
    tab = host.open()
    state = json.loads(tab.next()[1])["start"]
    header, shown = frame_of(ask(tab, state, 1), tmp_path)
    assert host.keywords()["shadows"] is True and "shadows=True" in header["command"]
    ran = eval(header["command"], {"volray": volray, "volume": ball})
    assert np.array_equal(shown[:, :, :3], rgb(ran))
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ball, **host.keywords())))
    unshadowed = rgb(volray.render(ball, camera=host.camera, tf=host.transfer_function))
    assert not np.array_equal(shown[:, :, :3], unshadowed)
    state["blend"] = "mip"
    header, shown = frame_of(ask(tab, state, 2), tmp_path)
    assert "shadows" not in host.keywords()
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ball, **host.keywords())))
    tab.close()


def test_the_pages_depth_cues_are_the_keywords(ball, tmp_path):
    # The page turns ambient occlusion on and shading off: the shadows
    # go, the occlusion stays, and the keywords render the frame shown.
    host = _ViewHost(ball, size=(48, 40), shadows=True, azimuth=40)
    tab = host.open()
    state = json.loads(tab.next()[1])["start"]
    assert state["shadows"] is True and "ambient_occlusion" not in state
    state["ambient_occlusion"] = 3
    state["shading"] = False
    header, shown = frame_of(ask(tab, state, 1), tmp_path)
    keywords = host.keywords()
    assert keywords["ambient_occlusion"] == 3 and "shadows" not in keywords, keywords
    assert "ambient_occlusion=3" in header["command"], header["command"]
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ball, **keywords)))
    plain = {k: v for k, v in keywords.items() if k != "ambient_occlusion"}
    assert not np.array_equal(shown[:, :, :3], rgb(volray.render(ball, **plain)))
    tab.close()


def test_the_pages_figure_is_drawn_as_renders_figure_keywords_draw_it(ball, tmp_path):
    # A CT-like ball in Hounsfield units under a CT preset, started with
    # a colour bar and a title: the bar says HU in the frame, and the
    # keywords read back (a whole transfer function, no preset) say it too.
    ct = (ball * 1500 - 400).astype(np.float32)
    host = _ViewHost(ct, size=(120, 96), preset="ct-bone", colorbar="right", title="A ball")
    tab = host.open()
    start = json.loads(tab.next()[1])["start"]
    figure = start["figure"]
    assert (figure["colorbar"], figure["title"], figure["axes"]) == ("right", "A ball", False), figure
    header, shown = frame_of(ask(tab, start, 1), tmp_path)
    keywords = host.keywords()
    assert keywords["colorbar"] == "right" and keywords["units"] == "HU", keywords
    assert keywords["title"] == "A ball" and "preset" not in keywords, keywords
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ct, **keywords)))
    ran = eval(header["command"], {"volray": volray, "volume": ct})
    assert np.array_equal(shown[:, :, :3], rgb(ran))
    # The unit is on the bar: without it the picture differs.
    unitless = {k: v for k, v in keywords.items() if k != "units"}
    assert not np.array_equal(shown[:, :, :3], rgb(volray.render(ct, **unitless)))

    # The Figure box's every annotation, the page's state to keywords.
    state = dict(start)
    state["figure"] = {
        "colorbar": "left",
        "scale_bar": True,
        "scale_length": 0.5,
        "axes": True,
        "outline": True,
        "title": 'a "quoted" title',
        "label": "b",
    }
    header, shown = frame_of(ask(tab, state, 2), tmp_path)
    keywords = host.keywords()
    for key, value in [("colorbar", "left"), ("scale_bar", 0.5), ("axes", True), ("outline", True), ("label", "b")]:
        assert keywords[key] == value, (key, keywords)
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ct, **keywords)))
    ran = eval(header["command"], {"volray": volray, "volume": ct})
    assert np.array_equal(shown[:, :, :3], rgb(ran))
    # The camera and transfer function read back as before: the bare frame.
    bare = rgb(volray.render(ct, camera=host.camera, tf=host.transfer_function))
    assert not np.array_equal(shown[:, :, :3], bare)
    state["figure"] = {}
    _, shown = frame_of(ask(tab, state, 3), tmp_path)
    assert np.array_equal(shown[:, :, :3], bare)
    assert not any(k in host.keywords() for k in ("colorbar", "units", "title"))
    tab.close()

    # A unit given wins over the preset's.
    host = _ViewHost(ct, size=(64, 48), preset="ct-bone", colorbar=True, units="mg/mL")
    tab = host.open()
    start = json.loads(tab.next()[1])["start"]
    _, shown = frame_of(ask(tab, start, 1), tmp_path)
    assert host.keywords()["units"] == "mg/mL"
    assert np.array_equal(shown[:, :, :3], rgb(volray.render(ct, **host.keywords())))
    tab.close()


def test_bad_messages_are_answered_and_closed_tabs_end(ball):
    host = _ViewHost(ball, size=32)
    tab = host.open()
    tab.next()  # the hello
    answer = json.loads(tab.receive("{not json"))
    assert answer["type"] == "error" and "malformed" in answer["message"]
    state = json.loads(host.state())
    state["zoom"] = -1
    answer = json.loads(tab.receive(json.dumps({"type": "view", "seq": 5, "quality": "full", "state": state})))
    assert answer["seq"] == 5 and "zoom" in answer["message"]
    state["zoom"] = 1
    state["colormap"] = "nope"
    answer = json.loads(tab.receive(json.dumps({"type": "view", "seq": 6, "quality": "full", "state": state})))
    assert answer["seq"] == 6 and "nope" in answer["message"]
    # A state the page may send but this viewer does not render.
    state["colormap"] = "viridis"
    state["time"] = 1
    assert tab.receive(json.dumps({"type": "view", "seq": 7, "quality": "full", "state": state})) is None
    is_frame, text = tab.next()
    assert not is_frame and "time" in json.loads(text)["message"]
    # The last view asked for cannot be read back: said so.
    with pytest.raises(ValueError, match="time"):
        host.camera
    # Closing ends the tab's messages, whoever waits for them.
    got = []
    waiter = threading.Thread(target=lambda: got.append(tab.next()))
    waiter.start()
    tab.close()
    waiter.join(timeout=30)
    assert not waiter.is_alive() and got == [None]


def test_bad_input_is_refused_with_python_exceptions(ball, tmp_path):
    pytest.importorskip("anywidget")
    with pytest.raises(ValueError, match="colorbar"):
        volray.view(ball, colorbar="up")
    with pytest.raises(ValueError, match="not a unit"):
        volray.view(ball, colorbar="right", units=" ")
    with pytest.raises(ValueError, match="level"):
        volray.view(ball, level=1)
    with pytest.raises(ValueError, match="zoom"):
        volray.view(ball, zoom=-1)
    with pytest.raises(ValueError, match="height"):
        volray.view(ball, height=10)
    with pytest.raises(TypeError, match="height"):
        volray.view(ball, height="tall")
    with pytest.raises(OSError):
        volray.view(tmp_path / "missing.npy")
    w = volray.view(ball, size=(40, 30), azimuth=10)
    assert w.camera.size == (40, 30) and w.camera.azimuth == 10
    assert w.keywords["camera"].azimuth == 10
    assert w.state["azimuth"] == 10
    assert "<!doctype html>" in w._page and "Content-Security-Policy" in w._page
    w.close()


def test_a_label_volume_is_shown_in_its_label_colours_and_read_back(tmp_path):
    # Three labelled balls and an empty background (label 0).
    x, y, z = np.mgrid[0:24, 0:24, 0:24]
    seg = np.zeros((24, 24, 24), np.uint8)
    for label, (cx, cy, cz) in [(1, (7, 8, 12)), (2, (16, 9, 12)), (5, (12, 16, 10))]:
        seg[(x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2 < 25] = label
    host = _ViewHost(seg, labels=True, show_labels=[1, 5], size=(48, 40), azimuth=30)
    tab = host.open()
    is_frame, hello = tab.next()
    hello = json.loads(hello)
    state = hello["start"]
    state["azimuth"] = 60
    header, shown = frame_of(ask(tab, state, 1), tmp_path)
    # The read-back names the label table whole, as the transfer function.
    keywords = host.keywords()
    assert keywords["labels"] is True and "tf" in keywords
    assert "labels=True" in header["command"]
    expected = rgb(volray.render(seg, **keywords))
    assert np.array_equal(shown[:, :, :3], expected)
    ran = eval(header["command"], {"volray": volray, "volume": seg})
    assert np.array_equal(shown[:, :, :3], rgb(ran))
    # ... which is the table of `labels=True, show_labels=[1, 5]`: label 2
    # hidden, which showing changes the picture.
    camera = keywords["camera"]
    assert np.array_equal(
        expected, rgb(volray.render(seg, labels=True, show_labels=[1, 5], camera=camera))
    )
    every = rgb(volray.render(seg, labels=True, camera=camera))
    assert not np.array_equal(every, expected)
    tab.close()


def test_an_array_written_in_a_later_cell_is_shown_as_it_is_now(ball, tmp_path):
    a = ball.copy()
    host = _ViewHost(a, size=(48, 40), azimuth=30)
    tab = host.open()
    state = json.loads(tab.next()[1])["start"]
    _, before = frame_of(ask(tab, state, 1), tmp_path)
    assert np.array_equal(before[:, :, :3], rgb(volray.render(a, **host.keywords())))
    # A later cell writes the array between frames: the next frame shows
    # it, every time (the digest is taken before each frame).
    for seq, write in enumerate([lambda: a.__setitem__((slice(None), slice(None), slice(0, 16)), 0),
                                 lambda: a.__setitem__(Ellipsis, ball[::-1])], start=2):
        write()
        header, shown = frame_of(ask(tab, state, seq), tmp_path)
        assert header["seq"] == seq
        expected = rgb(volray.render(a, **host.keywords()))
        assert np.array_equal(shown[:, :, :3], expected)
        assert not np.array_equal(shown[:, :, :3], before[:, :, :3])
        before = shown
    tab.close()


class _Page:
    """A widget's messages to its pages, as the kernel would send them."""

    def __init__(self, widget):
        self.lock = threading.Lock()
        self.texts = []
        self.frames = []
        self.gone = []
        self.acked = 0
        self.most_unacknowledged = 0
        widget.send = self.send

    def send(self, content, buffers=None):
        with self.lock:
            if content.get("frame"):
                data = bytes(buffers[0])
                n = int.from_bytes(data[:4], "little")
                self.frames.append(json.loads(data[4 : 4 + n])["seq"])
                self.most_unacknowledged = max(self.most_unacknowledged, len(self.frames) - self.acked)
            elif "text" in content:
                self.texts.append((content["view"], json.loads(content["text"])))
            elif content.get("gone"):
                self.gone.append(content["view"])

    def errors(self):
        with self.lock:
            return [t for _, t in self.texts if t.get("type") == "error"]


def _until(what, condition, seconds=60):
    end = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < end, f"not within {seconds} s: {what}"
        time.sleep(0.01)


def test_a_page_not_heard_from_is_closed_so_reloads_do_not_use_up_the_pages(ball):
    pytest.importorskip("anywidget")
    w = volray.view(ball, size=32)
    page = _Page(w)
    w._HEARTBEAT_S = 0.05
    w._TIMEOUT_S = 0.3
    # Twelve reloads, more than the eight pages a widget renders at once:
    # each page opens, then is never heard from again (a reload sends no
    # close); each silent page's renderer is closed.
    for i in range(12):
        w._on_message(w, {"view": f"reload-{i}", "open": True}, [])
        _until("the hello", lambda: len(page.texts) == i + 1)
        _until("the silent page closed", lambda: w.pages == 0, seconds=30)
    assert page.errors() == []
    # A live page says so and stays open past the timeout.
    w._on_message(w, {"view": "live", "open": True}, [])
    end = time.monotonic() + 4 * w._TIMEOUT_S
    while time.monotonic() < end:
        w._on_message(w, {"view": "live", "alive": True}, [])
        time.sleep(w._HEARTBEAT_S)
    assert w.pages == 1
    # While a cell runs the kernel reads no page's messages: a page is not
    # closed then, and is given the timeout again once the cell ends.
    w._cell_starts()
    time.sleep(4 * w._TIMEOUT_S)
    assert w.pages == 1
    w._cell_ends()
    assert w.pages == 1
    w._on_message(w, {"view": "live", "alive": True}, [])
    # Closed by its page (the output cleared): gone at once.
    w._on_message(w, {"view": "live", "close": True}, [])
    assert w.pages == 0
    # A page closed while silent (its browser tab hidden) is told so, and
    # opens again keeping its view: no second hello.
    w._on_message(w, {"view": "live", "alive": True}, [])
    assert page.gone == ["live"]
    hellos = len(page.texts)
    w._on_message(w, {"view": "live", "open": True, "resume": True}, [])
    assert w.pages == 1
    time.sleep(0.2)
    assert len(page.texts) == hellos
    w.close()
    assert w.pages == 0


def test_a_page_is_given_at_most_two_frames_unacknowledged_their_bytes_held(ball):
    pytest.importorskip("anywidget")
    w = volray.view(ball, size=64)
    page = _Page(w)
    w._on_message(w, {"view": "p", "open": True}, [])
    _until("the hello", lambda: len(page.texts) == 1)
    state = page.texts[0][1]["start"]
    idle = w._host.held()

    def ask_for(seq):
        state["azimuth"] = seq
        text = json.dumps({"type": "view", "seq": seq, "quality": "full", "state": state})
        w._on_message(w, {"view": "p", "text": text}, [])

    ask_for(1)
    _until("a frame", lambda: len(page.frames) == 1)
    ask_for(2)
    _until("a second frame", lambda: len(page.frames) == 2)
    # The page acknowledges none: the newer views wait in the kernel.
    for seq in range(3, 8):
        ask_for(seq)
    time.sleep(1.0)
    assert len(page.frames) == 2 and w._tabs["p"].in_flight == 2
    assert w._host.held() > idle
    tab = w._tabs["p"]

    def ack():
        with page.lock:
            page.acked += 1
        w._on_message(w, {"view": "p", "ack": True}, [])

    # Each acknowledgement lets one more go, until the latest view's.
    while 7 not in page.frames:
        ack()
        _until("a frame after an acknowledgement", lambda: len(page.frames) == page.acked + 2)
    assert page.frames[:2] == [1, 2] and page.frames[-1] == 7, page.frames
    ack()
    ack()
    assert tab.in_flight == 0
    assert page.most_unacknowledged == 2
    assert page.errors() == []
    assert w._host.held() == idle
    w.close()
