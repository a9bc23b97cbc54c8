"""volray.read of a chunked file (Zarr, OME-Zarr) is lazy: the volume
comes from the metadata and reads no sample; `.data` reads its level on
first use; render/Renderer read the level a frame needs (`level="auto"`,
as `volray render --level auto`), whole when it fits `max_memory` (the
same pixels as the level read whole) or piece by piece from its chunks
(the same pixels as the command line's piece-by-piece render). The
stores are written by ome-zarr-py and zarr-python (in target/pyenv),
independently of volray's own writer."""

import json
import os

import numpy as np
import pytest

import volray
from volray import _volray

from conftest import read_png, rgb

# A frame of the finest level at this size fits 4 MiB whole; under
# PIECES it is cut into pieces (checked by each test that relies on it).
SIZE = 64
PIECES = 600_000


@pytest.fixture(scope="module")
def zarr_modules():
    try:
        import ome_zarr.writer  # noqa: F401
        import zarr  # noqa: F401
    except ImportError:
        if os.environ.get("CI") == "true":
            raise
        pytest.skip("zarr and ome-zarr are not installed (.ci/run installs them)")
    import zarr
    from ome_zarr.format import FormatV05
    from ome_zarr.writer import write_multiscale

    return zarr, FormatV05, write_multiscale


def ball(n):
    """A soft ball on a ramp along x, `a[z, y, x]` float32, off centre so
    that every axis is told apart."""
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
    c = (n - 1) / 2
    r2 = ((x - c) ** 2 + (y - 0.8 * c) ** 2 + (z - 1.1 * c) ** 2) / (n * n)
    return (np.exp(-8 * r2) * 1000 + 3 * x).astype(np.float32)


def write_pyramid(zarr_modules, path, zyx, levels=3):
    """An OME-Zarr 0.5 pyramid of `zyx` halved `levels - 1` times by
    taking every other point, with scales 1, 2, 4, ...: level k's point i
    lies at 2^k i, as the data's."""
    zarr, FormatV05, write_multiscale = zarr_modules
    pyramid = [np.ascontiguousarray(zyx[:: 1 << k, :: 1 << k, :: 1 << k]) for k in range(levels)]
    axes = [{"name": a, "type": "space", "unit": "micrometer"} for a in "zyx"]
    transforms = [[{"type": "scale", "scale": [float(1 << k)] * 3}] for k in range(levels)]
    group = zarr.open_group(str(path), mode="w", zarr_format=3)
    write_multiscale(
        pyramid,
        group,
        fmt=FormatV05(),
        axes=axes,
        coordinate_transformations=transforms,
        storage_options={"chunks": (16, 16, 16)},
    )
    return pyramid


@pytest.fixture
def store(zarr_modules, tmp_path):
    path = tmp_path / "ball.ome.zarr"
    pyramid = write_pyramid(zarr_modules, path, ball(64))
    return path, pyramid


def chunk_files(level_dir):
    return [
        os.path.join(d, f)
        for d, _, files in os.walk(level_dir)
        for f in files
        if f != "zarr.json"
    ]


def in_memory(volume):
    """The same samples as a volume in memory (not lazy)."""
    return volray.Volume(volume.data, spacing=volume.spacing, origin=volume.origin)


def test_read_of_a_chunked_file_reads_no_sample_until_data_is_asked_for(store, zarr_modules):
    path, pyramid = store
    v = volray.read(path)
    assert v.lazy and v.level == 0
    assert v.dims == (64, 64, 64)
    assert v.spacing == (1.0, 1.0, 1.0) and v.origin == (0.0, 0.0, 0.0)
    assert v.sample_type == "f32" and not v.labels
    assert [lv["dims"] for lv in v.levels] == [(64,) * 3, (32,) * 3, (16,) * 3]
    assert v.info["lazy"] and v.info["values"] == {}
    assert "lazy" in repr(v) and "level 0 of 3" in repr(v)
    coarse = volray.read(path, level=1)
    assert coarse.lazy and coarse.level == 1 and coarse.dims == (32,) * 3
    assert coarse.spacing == (2.0, 2.0, 2.0)
    # The store is rewritten after read: .data holds what is there now,
    # so read() had read none of it.
    zarr = zarr_modules[0]
    zarr.open_array(str(path / "s0"), mode="r+")[...] = pyramid[0][::-1] + 1
    np.testing.assert_array_equal(v.data, (pyramid[0][::-1] + 1).T)
    assert v.info["values"]["max"] == pytest.approx(float(pyramid[0].max() + 1))
    # Kept: the store changing again does not change it.
    zarr.open_array(str(path / "s0"), mode="r+")[...] = 0
    np.testing.assert_array_equal(v.data, (pyramid[0][::-1] + 1).T)
    # A volume in memory is not lazy.
    assert not volray.Volume(np.zeros((4, 4, 4), np.float32)).lazy


def test_data_of_a_lazy_volume_whose_chunks_went_bad_raises_naming_the_file(store):
    path, _ = store
    v = volray.read(path)
    for f in chunk_files(path / "s0"):
        with open(f, "wb") as out:
            out.write(b"not a zstd frame at all")
    with pytest.raises(ValueError, match=str(path)):
        v.data


def test_a_frame_in_pieces_over_a_corrupt_chunk_is_a_value_error_and_over_an_unreadable_one_an_os_error(store):
    path, _ = store
    args = dict(size=SIZE, azimuth=30, elevation=20, tf="auto")
    chunk = sorted(chunk_files(path / "s0"))[0]
    with open(chunk, "wb") as out:
        out.write(b"not a zstd frame at all")
    with pytest.raises(ValueError, match=str(path)) as bad:
        volray.Renderer(volray.read(path), max_memory=PIECES).render(**args)
    assert "\n" not in str(bad.value)
    # A directory where the chunk's file should be: the system cannot read it.
    os.remove(chunk)
    os.mkdir(chunk)
    with pytest.raises(OSError, match="not a regular file") as unreadable:
        volray.Renderer(volray.read(path), max_memory=PIECES).render(**args)
    assert str(path) in str(unreadable.value)


def test_data_over_max_memory_is_refused_before_reading_with_the_coarser_level_that_fits(store):
    path, _ = store
    # Level 0 takes 1 MiB as float32, level 1 128 KiB, level 2 16 KiB.
    v = volray.read(path, max_memory=100_000)
    assert v.dims == (64, 64, 64)
    with pytest.raises(ValueError, match=r"ball.ome.zarr: level 0 .*more than max_memory.*level=2"):
        v.data
    assert volray.read(path, level=2, max_memory=100_000).data.shape == (16, 16, 16)


def test_level_auto_at_read_is_refused_pointing_to_render(store):
    path, _ = store
    with pytest.raises(ValueError, match="render"):
        volray.read(path, level="auto")
    with pytest.raises(TypeError, match="level"):
        volray.read(path, level=1.5)


@pytest.mark.parametrize("level", [0, 1, 2])
def test_a_lazy_volume_renders_a_level_as_that_level_read_whole(store, cli_image, level):
    path, _ = store
    args = dict(size=SIZE, azimuth=30, elevation=20)
    lazy = volray.render(volray.read(path), level=level, **args)
    whole = volray.render(in_memory(volray.read(path, level=level)), **args)
    assert np.array_equal(np.asarray(lazy), np.asarray(whole))
    # Read at that level, the level is the volume's own.
    assert np.array_equal(np.asarray(volray.render(volray.read(path, level=level), **args)), np.asarray(lazy))
    expected = cli_image(path, "--level", level, "--size", SIZE, "--azimuth", 30, "--elevation", 20)
    assert np.array_equal(rgb(lazy), expected[:, :, :3])


def test_a_frame_over_max_memory_is_rendered_in_pieces_within_1_255_of_the_whole(store, cli_image):
    path, _ = store
    args = dict(size=SIZE, azimuth=30, elevation=20, tf="auto")
    whole = volray.Renderer(volray.read(path))
    pieces = volray.Renderer(volray.read(path), max_memory=PIECES)
    a = np.asarray(whole.render(**args)).astype(int)
    b = np.asarray(pieces.render(**args)).astype(int)
    assert whole.pieces == 1 and pieces.pieces > 1
    assert np.abs(a - b).max() <= 1
    # The automatic transfer function was chosen from the same histogram,
    # found piece by piece: the value range is the whole level's.
    assert pieces.value_range == whole.value_range
    # The command line, in pieces under the same limit, renders the same.
    expected = cli_image(path, "--size", SIZE, "--azimuth", 30, "--elevation", 20, "--tf", "auto", "--max-memory", PIECES)
    assert np.array_equal(b[:, :, :3], expected[:, :, :3])


def test_value_range_before_any_frame_is_the_level_asked_for_whole_or_in_pieces(store):
    path, pyramid = store
    full = (float(pyramid[0].min()), float(pyramid[0].max()))
    coarse = (float(pyramid[2].min()), float(pyramid[2].max()))
    assert coarse != full
    for max_memory in (None, 100_000):
        assert volray.Renderer(volray.read(path), max_memory=max_memory).value_range == pytest.approx(full)
        assert volray.Renderer(volray.read(path), level=2, max_memory=max_memory).value_range == pytest.approx(coarse)
        # level="auto" needs a view: the volume's own level until a frame.
        auto = volray.Renderer(volray.read(path, level=2), level="auto", max_memory=max_memory)
        assert auto.value_range == pytest.approx(coarse)
    tight = volray.Renderer(volray.read(path), max_memory=100_000)
    assert tight.value_range == pytest.approx(full) and tight.pieces > 1


def test_labels_in_pieces_are_found_as_in_the_whole(zarr_modules, tmp_path):
    path = tmp_path / "labels.ome.zarr"
    n = 48
    z, y, x = np.mgrid[0:n, 0:n, 0:n]
    labels = (1 + (x // 16) + 3 * (y // 24) + 5 * (z > 30)).astype(np.uint8)
    labels[:4] = 0
    write_pyramid(zarr_modules, path, labels, levels=2)
    args = dict(size=48, azimuth=40, elevation=25)
    whole = volray.render(volray.read(path), labels=True, **args)
    pieces = volray.Renderer(volray.read(path), labels=True, max_memory=120_000)
    frame = pieces.render(**args)
    assert pieces.pieces > 1
    assert np.abs(np.asarray(whole).astype(int) - np.asarray(frame).astype(int)).max() <= 1
    # Not a label volume: refused in pieces as whole, with the same words.
    fractional = tmp_path / "fractional.ome.zarr"
    write_pyramid(zarr_modules, fractional, ball(48), levels=1)
    with pytest.raises(ValueError) as whole_error:
        volray.render(volray.read(fractional), labels=True, **args)
    with pytest.raises(ValueError) as pieces_error:
        volray.render(volray.read(fractional), labels=True, max_memory=120_000, **args)
    assert "labels must be integers" in str(pieces_error.value)
    assert str(pieces_error.value) == str(whole_error.value)


def cli_level(cli, path, *args):
    done = cli("render", path, "--level", "auto", *args, "-o", os.path.join(os.path.dirname(path), "auto.png"))
    line = [l for l in done.stderr.splitlines() if "--level auto" in l]
    assert len(line) == 1, done.stderr
    return int(line[0].split(": level ")[1].split()[0])


def test_level_auto_picks_the_level_the_command_line_picks(store, cli):
    path, _ = store
    renderer = volray.Renderer(volray.read(path), level="auto")
    assert renderer.level is None
    chosen = {}
    for size in (8, 16, 31, 32, 64, 128):
        renderer.render(size=size)
        chosen[size] = renderer.level
        assert renderer.level == cli_level(cli, path, "--size", size), size
    # The 63 µm face over SIZE pixels: level k (2^k µm voxels) once
    # 2^k <= 63/size within 1/32.
    assert chosen == {8: 2, 16: 2, 31: 1, 32: 1, 64: 0, 128: 0}
    # Zoomed in, a 16-pixel frame needs finer voxels.
    renderer.render(size=16, zoom=4)
    assert renderer.level == 0 == cli_level(cli, path, "--size", 16, "--zoom", 4)


def test_a_renderer_chooses_its_level_again_when_the_size_changes(store):
    path, _ = store
    renderer = volray.Renderer(volray.read(path), level="auto")
    small = renderer.render(size=16)
    assert renderer.level == 2
    assert np.array_equal(np.asarray(small), np.asarray(volray.render(volray.read(path, level=2), size=16)))
    large = renderer.render(size=SIZE)
    assert renderer.level == 0
    assert np.array_equal(np.asarray(large), np.asarray(volray.render(volray.read(path), size=SIZE)))
    # Over max_memory at the finer level, it goes piece by piece there,
    # and back to whole at the coarser one.
    tight = volray.Renderer(volray.read(path), level="auto", max_memory=PIECES)
    tight.render(size=SIZE)
    assert (tight.level, tight.pieces > 1) == (0, True)
    tight.render(size=16)
    assert (tight.level, tight.pieces) == (2, 1)
    assert "level auto" in repr(tight)


def test_level_is_refused_for_a_volume_in_memory_and_out_of_range(store):
    path, _ = store
    with pytest.raises(ValueError, match="level"):
        volray.render(np.zeros((8, 8, 8), np.float32), level=0)
    with pytest.raises(ValueError, match="in memory"):
        volray.render(volray.hydrogen(2, 1, 0, grid=16), level="auto")
    with pytest.raises(ValueError, match="level 3 is not among the file's 3 levels"):
        volray.Renderer(volray.read(path), level=3)
    with pytest.raises(ValueError, match="level"):
        volray.Renderer(volray.read(path), level="coarse")


def test_a_level_read_whole_budgets_its_brick_caches_for_each_frame(store):
    # As a volume in memory: what max_memory leaves after the frame being
    # rendered; a frame that leaves less has the level prepared again.
    path, _ = store
    limit = 64 << 20
    renderer = volray.Renderer(volray.read(path), level=0, max_memory=limit)
    small = renderer.render(size=SIZE)
    budget = renderer._cache_budget
    assert renderer.pieces == 1 and 0 < budget < limit
    large = renderer.render(size=(300, 200))
    # 16 bytes a pixel more.
    assert budget - renderer._cache_budget >= 16 * (300 * 200 - SIZE * SIZE)
    assert renderer.pieces == 1 and renderer.level == 0
    whole = in_memory(volray.read(path))
    assert np.array_equal(np.asarray(small), np.asarray(volray.render(whole, size=SIZE)))
    assert np.array_equal(np.asarray(large), np.asarray(volray.render(whole, size=(300, 200))))


def test_log_is_taken_whole_and_in_pieces_on_the_whole_levels_scale(store, cli_image):
    path, _ = store
    frame = volray.render(volray.read(path), log=True, size=SIZE)
    expected = volray.render(in_memory(volray.read(path)), log=True, size=SIZE)
    assert np.array_equal(np.asarray(frame), np.asarray(expected))
    # 1.5 MB cannot hold the level's f32 log beside its samples: in pieces,
    # after a pass for the level's smallest positive value.
    renderer = volray.Renderer(volray.read(path), log=True, max_memory=1_500_000)
    pieces = rgb(renderer.render(size=SIZE))
    assert renderer.pieces > 1
    assert np.abs(pieces - rgb(frame)).max() <= 1
    cli = cli_image(path, "--log", "--size", SIZE, "--max-memory", "1500000")
    assert np.array_equal(pieces, cli[:, :, :3])


def test_ctrl_c_stops_a_frame_in_pieces_at_its_next_piece(store):
    path, _ = store
    renderer = volray.Renderer(volray.read(path), max_memory=PIECES)
    arguments = dict(size=SIZE, range=(0, 1200), threads=1)
    reference = np.asarray(renderer.render(**arguments))
    pieces = renderer.pieces
    assert pieces >= 4
    _volray._interrupt_next_frame()
    with pytest.raises(KeyboardInterrupt):
        renderer.render(**arguments)
    # Stopped within the first piece's frame: the pieces after it not read.
    reported = _volray._hooked_frame_pixels()
    assert 0 < reported <= SIZE * SIZE, reported
    # The renderer renders on afterwards, the same picture.
    assert np.array_equal(np.asarray(renderer.render(**arguments)), reference)


def test_an_omero_window_is_the_default_range_whole_and_in_pieces(zarr_modules, store, cli_image):
    path, _ = store
    zarr = zarr_modules[0]
    group = zarr.open_group(str(path), mode="r+")
    ome = dict(group.attrs["ome"])
    ome["omero"] = {
        "channels": [
            {
                "window": {"start": 300.0, "end": 900.0, "min": 0.0, "max": 1200.0},
                "color": "00FF00",
                "label": "ball",
                "active": True,
            }
        ]
    }
    group.attrs["ome"] = ome
    args = dict(size=SIZE, azimuth=30, elevation=20, colormap="viridis")
    hinted = rgb(volray.render(volray.read(path), **args))
    # The window is the range a script would give, as the command line takes it.
    assert np.array_equal(hinted, rgb(volray.render(volray.read(path), range=(300, 900), **args)))
    expected = cli_image(path, "--size", SIZE, "--azimuth", 30, "--elevation", 20, "--colormap", "viridis")
    assert np.array_equal(hinted, expected[:, :, :3])
    # A range given wins; another range is another picture.
    wide = rgb(volray.render(volray.read(path), range=(0, 1200), **args))
    assert np.abs(hinted - wide).max() > 16
    # In pieces too.
    renderer = volray.Renderer(volray.read(path), max_memory=PIECES)
    pieces = rgb(renderer.render(**args))
    assert renderer.pieces > 1
    assert np.abs(pieces - hinted).max() <= 1


def _view_frame(tab, state, seq, tmp_path, quality="full"):
    """The header and pixels of the frame `state` asks for."""
    refused = tab.receive(json.dumps({"type": "view", "seq": seq, "quality": quality, "state": state}))
    assert refused is None, refused
    while True:
        is_frame, data = tab.next()
        if is_frame:
            tab.ack()  # as the widget's page does
            break
        assert json.loads(data)["type"] != "error", data
    n = int.from_bytes(data[:4], "little")
    header = json.loads(data[4 : 4 + n])
    if header["mime"] != "image/png":  # a draft may come as JPEG
        return header, None
    png = tmp_path / "frame.png"
    png.write_bytes(data[4 + n :])
    return header, read_png(png)[:, :, :3]


def test_the_notebook_viewer_reads_a_chunked_files_levels_as_its_frames_need_them(store, tmp_path):
    from volray._volray import _ViewHost

    path, _ = store
    host = _ViewHost(volray.read(path), size=SIZE, azimuth=30)
    tab = host.open()
    hello = json.loads(tab.next()[1])
    assert hello["dims"] == [64, 64, 64]
    assert hello["levels"] == [[64, 64, 64], [32, 32, 32], [16, 16, 16]]
    state = hello["start"]
    # The still: the level render's level="auto" picks, whole; the
    # keywords read back name that choice and render the same frame.
    header, still = _view_frame(tab, state, 1, tmp_path)
    assert header["level"]["index"] == 0 and header["level"]["pieces"] == 1, header["level"]
    keywords = host.keywords()
    assert keywords["level"] == "auto", keywords
    assert 'level="auto"' in header["command"]
    expected = rgb(volray.render(volray.read(path), **keywords))
    assert np.array_equal(still, expected)
    # A draft, while the view moves: a coarser level held whole.
    state["azimuth"] = 60
    header, _ = _view_frame(tab, state, 2, tmp_path, "draft")
    assert header["level"]["index"] > 0, header["level"]
    tab.close()

    # A level asked for: the stills show it, and the keywords say it.
    host = _ViewHost(volray.read(path), size=SIZE, level=1)
    tab = host.open()
    state = json.loads(tab.next()[1])["start"]
    header, still = _view_frame(tab, state, 1, tmp_path)
    assert header["level"]["index"] == 1 and host.keywords()["level"] == 1
    expected = rgb(volray.render(volray.read(path), **host.keywords()))
    assert np.array_equal(still, expected)
    assert np.array_equal(still, rgb(volray.render(volray.read(path, level=1), size=SIZE)))
    tab.close()

    # What the levels do not take yet is refused, naming the way round.
    for keywords, message in [
        ({"colorbar": "right"}, "not drawn on a chunked file's levels"),
        ({"log": True}, "not yet with log=True"),
        ({"level": 3}, "not among the file's 3 levels"),
    ]:
        with pytest.raises(ValueError, match=message):
            _ViewHost(volray.read(path), size=SIZE, **keywords)
