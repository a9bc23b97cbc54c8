"""Annotations as keywords (colorbar and its units, scale_bar, title,
label, axes, outline): the same pixels as `volray render`'s flags of the same names
for the same frame, on render, Renderer.render and a scene; without them
the frame is as it was; wrong values are refused in one line."""

import numpy as np
import pytest
import volray
from conftest import read_png, rgb

CASES = [
    # (built-in source, command-line flags, keywords)
    (
        "hydrogen:4,2,0",
        ["--colorbar", "--scale-bar", "--title", "ψ₄₂₀", "--label", "a"],
        {"colorbar": "right", "scale_bar": True, "title": "ψ₄₂₀", "label": "a"},
    ),
    (
        "blobs:32",
        ["--colorbar", "left", "--scale-bar", "0.5", "--axes", "--outline", "--azimuth", "30", "--elevation", "20"],
        {"colorbar": "left", "scale_bar": 0.5, "axes": True, "outline": True, "azimuth": 30, "elevation": 20},
    ),
    (
        "fractal:33",
        ["--outline", "--axes", "--perspective", "35", "--zoom", "1.4", "--azimuth", "-50", "--scale-bar", "--colormap", "magma"],
        {"outline": True, "axes": True, "perspective": 35, "zoom": 1.4, "azimuth": -50, "scale_bar": True, "colormap": "magma"},
    ),
    (
        "marschner-lobb:41",
        ["--blend", "mip", "--colorbar", "--axes", "--background", "1,1,1"],
        {"blend": "mip", "colorbar": "right", "axes": True, "background": (1, 1, 1)},
    ),
    (
        "sphere:32",
        ["--colorbar", "--units", "K"],
        {"colorbar": "right", "units": "K"},
    ),
]


@pytest.mark.parametrize("spec,flags,keywords", CASES, ids=[f"{c[0]} {' '.join(c[1])}" for c in CASES])
def test_figure_keywords_give_the_command_lines_pixels(cli_image, spec, flags, keywords):
    expected = cli_image(spec, "--size", "160", *flags)
    got = rgb(volray.render(volray.read(spec), size=160, **keywords))
    figure = ("colorbar", "units", "scale_bar", "title", "label", "axes", "outline")
    view = {k: v for k, v in keywords.items() if k not in figure}
    bare = rgb(volray.render(volray.read(spec), size=160, **view))
    assert np.abs(got - expected).max() == 0, f"{spec}: annotations differ from volray render's"
    # And they were drawn: the frame is not the bare one.
    assert np.abs(got - bare).max() > 100
    renderer = volray.Renderer(volray.read(spec))
    again = rgb(renderer.render(size=160, **keywords))
    assert np.abs(again - expected).max() == 0, f"{spec}: Renderer.render differs"


def test_the_command_lines_bare_options_are_parsed_as_given(cli_image):
    # The bare frame of the second case, as its keywords without
    # annotations give it: annotations off are the frame as it was.
    volume = volray.read("blobs:32")
    plain = rgb(volray.render(volume, size=64, azimuth=30))
    off = rgb(volray.render(volume, size=64, azimuth=30, colorbar=None, scale_bar=False, title=None,
                            label=None, axes=False, outline=False))
    assert np.array_equal(plain, off)
    assert np.array_equal(plain, cli_image("blobs:32", "--size", "64", "--azimuth", "30"))


def test_a_scene_is_annotated_as_the_command_line_annotates_it(cli_image):
    flags = ["--overlay", "hydrogen:3,1,0", "--outline", "--colorbar", "--axes", "--azimuth", "30", "--elevation", "20"]
    expected = cli_image("blobs:32", "--size", "128", *flags)
    got = rgb(volray.render([volray.read("blobs:32"), volray.read("hydrogen:3,1,0")], size=128, outline=True,
                            colorbar="right", axes=True, azimuth=30, elevation=20))
    assert np.abs(got - expected).max() == 0
    # The annotations are the picture's, not a volume's look.
    with pytest.raises(TypeError, match="unknown key 'axes'"):
        volray.render([volray.read("blobs:32"), volray.read("sphere:16")], looks=[{"axes": True}, {}], size=32)


def test_wrong_annotation_values_are_refused_in_one_line():
    volume = volray.read("sphere:16")
    for keywords, error, message in [
        ({"colorbar": "top"}, ValueError, "not a side"),
        ({"colorbar": 3}, TypeError, "colorbar: expected"),
        ({"scale_bar": -2}, ValueError, "not a positive length"),
        ({"scale_bar": "long"}, TypeError, "scale_bar: expected"),
        ({"title": 5}, TypeError, "title: expected a str"),
        ({"axes": "yes"}, TypeError, "axes: expected True or False"),
        ({"colorbar": "right", "units": ""}, ValueError, "units: .* is not a unit"),
        ({"units": 3}, TypeError, "units: expected a str"),
    ]:
        with pytest.raises(error, match=message) as caught:
            volray.render(volume, size=32, **keywords)
        assert "\n" not in str(caught.value)
