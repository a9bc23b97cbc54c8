"""volray.render gives the command line's pixels for the same data and
options: the paper's volumes, the peers' workloads (step 0.5, looking
along +x, the peers' ramp), and the options that change the path taken."""

import json

import numpy as np
import pytest
import volray
from conftest import read_png, rgb

PEERS_TF = {
    "opacity": [[0, 0], [0.05, 0], [0.95, 0.9], [1, 0.5]],
    "color": [[0, 0, 0, 1], [0.5, 0, 1, 0], [1, 1, 0, 0]],
}

CASES = [
    # (built-in source, command-line flags, keywords)
    ("hydrogen:4,2,1", [], {}),
    ("hydrogen:6,2,1", ["--view", "150,150,500"], {"view": (150, 150, 500)}),
    ("fractal:65", ["--colormap", "magma", "--azimuth", "30"], {"colormap": "magma", "azimuth": 30}),
    ("marschner-lobb:41", ["--blend", "mip"], {"blend": "mip"}),
    ("marschner-lobb:41", ["--blend", "average", "--colormap", "viridis"], {"blend": "average", "colormap": "viridis"}),
    (
        "blobs:48",
        ["--perspective", "40", "--elevation", "20", "--post-classification", "--opacity", "0,0.8"],
        {"perspective": 40, "elevation": 20, "post_classification": True, "opacity": (0, 0.8)},
    ),
    (
        "blobs:48",
        ["--crop", "-1,0.5,-1,1,-1,1", "--clip", "0,0,0,1,1,0", "--no-shading"],
        {"crop": (-1, 0.5, -1, 1, -1, 1), "clip": (0, 0, 0, 1, 1, 0), "shading": False},
    ),
    ("blobs:48", ["--iso", "0.5", "--background", "0.2,0.2,0.3"], {"iso": 0.5, "background": (0.2, 0.2, 0.3)}),
    ("fractal:65", ["--preset", "electron-density", "--step", "0.5", "--size", "96x64"], {"preset": "electron-density", "step": 0.5, "size": (96, 64)}),
    ("hydrogen:3,2,0", ["--reference", "--size", "48"], {"reference": True, "size": 48}),
    ("fractal:65", ["--shadows", "--light", "1,0.5,1"], {"shadows": True, "light": (1, 0.5, 1)}),
    ("blobs:48", ["--shadows", "--post-classification"], {"shadows": True, "post_classification": True}),
    # True is the default radius (8), not the number 1.
    ("fractal:65", ["--ambient-occlusion", "--ambient", "0.5"], {"ambient_occlusion": True, "ambient": 0.5}),
    ("blobs:48", ["--ambient-occlusion", "3", "--no-shading", "--post-classification"], {"ambient_occlusion": 3, "shading": False, "post_classification": True}),
]


@pytest.mark.parametrize("spec,flags,keywords", CASES, ids=[f"{c[0]} {' '.join(c[1])}" for c in CASES])
def test_render_gives_the_command_lines_pixels(cli_image, spec, flags, keywords):
    size = [] if "--size" in flags else ["--size", "96"]
    expected = cli_image(spec, *size, *flags)
    keywords = {"size": 96, **keywords}
    got = rgb(volray.render(volray.read(spec), **keywords))
    assert got.shape == expected.shape
    assert np.abs(got - expected).max() == 0, f"{spec}: pixels differ from volray render"


def test_the_peers_workloads_give_the_command_lines_pixels(cli_image, tmp_path):
    tf_file = tmp_path / "peers.json"
    tf_file.write_text(json.dumps(PEERS_TF))
    for spec, size in [("hydrogen:4,2,1", 120), ("hydrogen:6,3,2", 120), ("fractal:65", 240)]:
        volume = volray.read(spec)
        nx, ny, nz = volume.dims
        (sx, sy, sz), (ox, oy, oz) = volume.spacing, volume.origin
        centre = (ox + sx * (nx - 1) / 2, oy + sy * (ny - 1) / 2, oz + sz * (nz - 1) / 2)
        eye = (centre[0] - 10 * sx * nx, centre[1], centre[2])
        flags = ["--size", size, "--step", "0.5", "--tf", tf_file]
        flags += ["--view", ",".join(map(str, eye)), "--look-at", ",".join(map(str, centre))]
        expected = cli_image(spec, *flags)
        transfer = volray.TransferFunction.from_json(str(tf_file))
        got = rgb(volray.render(volume, size=size, step=0.5, tf=transfer, view=eye, look_at=centre))
        assert np.abs(got - expected).max() == 0, spec


def test_generated_arrays_equal_volray_generate(cli, tmp_path):
    # volray writes .npy as a[x, y, z], the module's order.
    cli("generate", "hydrogen", "--n", 4, "--l", 2, "--m", 1, "--grid", 40, "-o", tmp_path / "h.npy")
    assert np.array_equal(volray.hydrogen(4, 2, 1, grid=40), np.load(tmp_path / "h.npy"))
    cli("generate", "fractal", "--size", 33, "--seed", 3, "-o", tmp_path / "f.npy")
    assert np.array_equal(volray.fractal(33, seed=3), np.load(tmp_path / "f.npy"))


def test_a_generated_array_renders_as_the_built_in_source(cli_image):
    # The array alone, with the source's spacing and origin given.
    source = volray.read("hydrogen:4,2,1")
    array = volray.hydrogen(4, 2, 1)
    assert np.array_equal(array, source.data)
    got = rgb(volray.render(array, spacing=source.spacing, origin=source.origin, size=96))
    assert np.abs(got - cli_image("hydrogen:4,2,1", "--size", "96")).max() == 0


def test_a_renderer_reused_across_views_gives_each_views_frame(cli_image):
    volume = volray.read("fractal:65")
    renderer = volray.Renderer(volume)
    for azimuth in (0, 45, 90):
        expected = cli_image("fractal:65", "--size", "64", "--azimuth", str(azimuth))
        assert np.abs(rgb(renderer.render(size=64, azimuth=azimuth)) - expected).max() == 0


def test_a_camera_object_is_the_camera_keywords():
    volume = volray.read("blobs:32")
    camera = volray.Camera(size=(80, 60), azimuth=25, zoom=1.5)
    a = np.asarray(volray.render(volume, camera=camera))
    b = np.asarray(volray.render(volume, size=(80, 60), azimuth=25, zoom=1.5))
    assert np.array_equal(a, b)
    with pytest.raises(ValueError, match="conflicts with camera="):
        volray.render(volume, camera=camera, zoom=2)


def test_label_volumes_render_as_the_command_line_renders_them(cli_image, tmp_path):
    x, y, z = np.mgrid[0:40, 0:40, 0:40]
    labels = np.zeros((40, 40, 40), np.uint8)
    labels[(x - 12) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 < 64] = 1
    labels[(x - 28) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 < 64] = 2
    np.save(tmp_path / "labels.npy", labels)
    expected = cli_image(tmp_path / "labels.npy", "--size", "64", "--labels", "--label-opacity", "2:0.3")
    got = rgb(volray.render(labels, size=64, labels=True, label_opacity={2: 0.3}))
    assert np.abs(got - expected).max() == 0


def test_a_few_hot_pixels_leave_the_command_lines_window(cli_image, tmp_path):
    """Values 10..100 with three voxels at 1e6: `--tf auto` refines its
    histogram to the values' window (core's robust_histogram), in Python
    as on the command line, and the picture shows them."""
    z, y, x = np.meshgrid(np.arange(20), np.arange(24), np.arange(28), indexing="ij")
    data = (10 + 90 * ((x * 31 + y * 7 + z * 13) % 97) / 96).astype(np.float32)
    data[3, 5, 7] = data[10, 20, 4] = data[15, 2, 20] = 1e6
    path = tmp_path / "hot.npy"
    np.save(path, data)
    expected = cli_image(path, "--size", "64")
    for source in (volray.read(str(path)), data):
        got = rgb(volray.render(source, size=64))
        assert np.abs(got - expected).max() == 0, "pixels differ from volray render"
    # Over the range 10..1e6 every value would be transparent.
    shown = np.any(np.abs(got - got[0, 0]) > 8, axis=-1).mean()
    assert shown > 0.25, shown
