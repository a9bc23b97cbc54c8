"""Bad input raises ValueError, TypeError or OSError with the command
line's one-line messages (options named as Python spells them); two
threads render at once; Ctrl-C stops a long render."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
import volray
from volray import _volray


def ball(n=24):
    x, y, z = np.mgrid[-1 : 1 : n * 1j, -1 : 1 : n * 1j, -1 : 1 : n * 1j]
    return np.exp(-4 * (x * x + y * y + z * z)).astype(np.float32)


def test_non_finite_values_are_refused_unless_transparent():
    a = ball()
    a[3, 4, 5] = np.nan
    with pytest.raises(ValueError, match=r"1 of 13824 values are not finite.*nonfinite='transparent'"):
        volray.render(a, size=32)
    assert volray.render(a, size=32, nonfinite="transparent").width == 32


@pytest.mark.parametrize(
    "volume,error,message",
    [
        (np.zeros((4, 4)), ValueError, r"a 3-D array, but this one has shape \[4, 4\]"),
        (np.zeros((0, 4, 4), np.float32), ValueError, "at least two points"),
        (np.zeros((4, 1, 4), np.uint8), ValueError, "at least two points"),
        (np.zeros((4, 4, 4), np.complex64), TypeError, "dtype .* is not a volume's"),
        (np.zeros((4, 4, 4), object), TypeError, "dtype .* is not a volume's"),
        ("not a volume", ValueError, "3-D array"),
    ],
)
def test_arrays_that_are_not_volumes_are_refused(volume, error, message):
    with pytest.raises(error, match=message):
        volray.render(volume)


@pytest.mark.parametrize(
    "keywords,error,message",
    [
        (dict(preset="ct-bone", tf="auto"), ValueError, "^preset conflicts with tf: give one of them$"),
        (dict(blend="mip", opacity=(0, 1)), ValueError, "opacity shapes the opacity of blend='composite'; blend='mip' projects"),
        (dict(shading=False, shininess=20), ValueError, "shininess sets the lighting, but shading=False turns the lighting off"),
        (dict(blend="iso"), ValueError, "blend='iso' needs the isovalue: give iso=VALUE"),
        (dict(preset="bone"), ValueError, "preset: unknown preset 'bone': expected one of ct-bone"),
        (dict(blend="sum"), ValueError, "blend: unknown blend mode 'sum'"),
        (dict(zoom=-1), ValueError, "^zoom: zoom -1 must be"),
        (dict(size=0), ValueError, "^size: image width 0 must be"),
        (dict(show_labels=[1]), ValueError, "show_labels applies to label volumes: give labels=True"),
        (dict(size="big"), TypeError, "size: expected an int or"),
        (dict(view=(1, 2)), TypeError, r"view: expected three numbers"),
        (dict(colour="red"), TypeError, "unexpected keyword argument 'colour'"),
        (dict(log=True, range=(0, 1)), ValueError, "range: with log=True the value window"),
        (dict(max_memory=1000), ValueError, "more than max_memory"),
        (dict(tf="/no/such/file.json"), OSError, "tf /no/such/file.json: cannot read"),
        (dict(order="yxz"), ValueError, "order: 'yxz' is not an axis order"),
        (dict(ambient_occlusion=40), ValueError, "^ambient_occlusion: ambient occlusion radius 40 must be 1 to 32 voxels$"),
        (dict(ambient_occlusion="yes"), TypeError, "ambient_occlusion: expected True, False or a radius in voxels"),
        (dict(ambient_occlusion=True, blend="mip"), ValueError, "ambient_occlusion sets the lighting, but blend='mip' is unshaded"),
    ],
)
def test_bad_options_raise_the_command_lines_messages(keywords, error, message):
    keywords = {"size": 32, **keywords}
    with pytest.raises(error, match=message):
        volray.render(ball() + 1, **keywords)


def test_files_that_cannot_be_read_raise_os_or_value_errors(tmp_path):
    with pytest.raises(OSError, match="no-such.nrrd"):
        volray.read(tmp_path / "no-such.nrrd")
    bad = tmp_path / "bad.npy"
    bad.write_bytes(b"\x93NUMPY\x01\x00garbage")
    with pytest.raises(ValueError, match="bad.npy"):
        volray.read(bad)
    with pytest.raises(ValueError, match="exceed"):
        volray.read(_big(tmp_path), max_memory=1000)


def test_read_refuses_what_the_command_line_refuses_in_its_words(tmp_path):
    # volray-app's rules for an input, Python's read and `volray render` alike.
    np.save(tmp_path / "a.npy", ball())
    with pytest.raises(ValueError, match="a.npy: dims, dtype and endian describe raw files; this is a NumPy .npy file"):
        volray.read(tmp_path / "a.npy", dims=(24, 24, 24))
    raw = tmp_path / "a.raw"
    raw.write_bytes(bytes(8))
    with pytest.raises(ValueError, match="a.raw: raw data needs dims"):
        volray.read(raw, dtype="u8")
    with pytest.raises(ValueError, match="sphere:8: .* apply to files only"):
        volray.read("sphere:8", frame=0)
    with pytest.raises(ValueError, match="spacing"):
        volray.read("sphere:8", spacing=(0, 1, 1))
    # A built-in source is checked against max_memory before it is made.
    with pytest.raises(ValueError, match="blobs:200: points per side 200 200 200 .* exceed the memory limit"):
        volray.read("blobs:200", max_memory=1000)
    sphere = volray.read("sphere:8", spacing=(2, 1, 0.5))
    assert sphere.spacing == (2.0, 1.0, 0.5) and sphere.dims == (8, 8, 8)
    assert np.array_equal(sphere.data, volray.read("sphere:8").data)


def test_a_frame_that_needs_more_memory_shrinks_the_brick_caches_to_fit():
    # The caches get what max_memory leaves after the frame being
    # rendered, as the command line budgets them; the pixels are the same.
    a = ball()
    limit = 64 << 20
    r = volray.Renderer(a, max_memory=limit)
    small = r.render(size=32)
    first = r._cache_budget
    assert 0 < first < limit
    big = r.render(size=(520, 500))
    after_big = r._cache_budget
    # 16 bytes a pixel more than the default 480x480 frame's.
    assert first - after_big >= 16 * (520 * 500 - 480 * 480)
    shadowed = r.render(size=(520, 500), shadows=True)
    # Shadows keep a light volume of 2 bytes a voxel.
    assert after_big - r._cache_budget >= 2 * 24**3
    # What a renderer made for that frame first gets; never more again.
    fresh = volray.Renderer(a, max_memory=limit)
    fresh.render(size=(520, 500), shadows=True)
    assert fresh._cache_budget == r._cache_budget
    budget = r._cache_budget
    again = r.render(size=32)
    assert r._cache_budget == budget
    roomy = volray.Renderer(a)
    frames = [(small, {"size": 32}), (big, {"size": (520, 500)}), (again, {"size": 32}),
              (shadowed, {"size": (520, 500), "shadows": True})]
    for frame, keywords in frames:
        assert np.array_equal(np.asarray(frame), np.asarray(roomy.render(**keywords)))


def _big(tmp_path):
    path = tmp_path / "big.npy"
    np.save(path, np.zeros((32, 32, 32), np.float32))
    return path


def test_read_describes_the_file(tmp_path):
    a = ball().astype(np.uint16)
    np.save(tmp_path / "a.npy", a)
    volume = volray.read(tmp_path / "a.npy")
    assert np.array_equal(volume.data, a) and volume.sample_type == "u16"
    info = volume.info
    assert info["format"] == "NumPy .npy" or "npy" in info["format"].lower()
    assert info["dims"] == (24, 24, 24) and info["values"]["max"] == a.max()


def test_frames_save_as_png_and_exr_and_show_in_jupyter(tmp_path):
    frame = volray.render(ball(), size=(40, 30))
    assert (frame.width, frame.height) == (40, 30)
    assert frame._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"
    frame.save(tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes() == frame._repr_png_()
    frame.save(tmp_path / "f16.png", bit_depth=16)
    frame.save(tmp_path / "f.exr")
    assert (tmp_path / "f.exr").read_bytes()[:4] == b"\x76\x2f\x31\x01"
    floats = np.asarray(frame, dtype=np.float32)
    assert floats.shape == (30, 40, 4) and floats.dtype == np.float32
    assert np.array_equal(np.round(np.clip(floats, 0, 1) * 255).astype(np.uint8), np.asarray(frame))
    with pytest.raises(OSError):
        frame.save(tmp_path / "no-such-dir" / "f.png")
    assert not (tmp_path / "no-such-dir").exists()


def test_two_threads_render_at_once_and_each_gets_its_frame():
    volume = volray.Volume(ball(40))
    renderer = volray.Renderer(volume)
    expected = {az: np.asarray(renderer.render(size=96, azimuth=az)) for az in (0, 60)}

    def work(az):
        frames = []
        for _ in range(5):
            frames.append(np.asarray(volray.render(volume, size=96, azimuth=az)))
            frames.append(np.asarray(renderer.render(size=96, azimuth=az)))
        return frames

    # A thread's exception is raised here by result(), failing the test.
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = {az: pool.submit(work, az) for az in (0, 60)}
        results = {az: future.result() for az, future in results.items()}
    for az, frames in results.items():
        assert len(frames) == 10, az
        assert all(np.array_equal(f, expected[az]) for f in frames), az


def test_ctrl_c_stops_a_long_render():
    rng = np.random.default_rng(1)
    noise = rng.random((64, 64, 64), dtype=np.float32)
    renderer = volray.Renderer(noise)
    # One worker: the hook holds it after its first tile until the calling
    # thread has seen the interrupt, so every later tile is skipped,
    # whatever the machine's load (no timer races the frame).
    arguments = dict(size=256, step=0.25, opacity=(0, 0.02), threads=1)
    _volray._interrupt_next_frame()
    with pytest.raises(KeyboardInterrupt):
        renderer.render(**arguments)
    # Stopped after the first tile (16 x 16 pixels): the rest skipped.
    reported = _volray._hooked_frame_pixels()
    assert 0 < reported < 256 * 256 // 4, reported
    # The renderer renders on afterwards, its caches whole.
    fresh = volray.Renderer(noise.copy()).render(**arguments)
    assert np.array_equal(np.asarray(renderer.render(**arguments)), np.asarray(fresh))
