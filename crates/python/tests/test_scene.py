"""Several volumes in one picture: volray.render([a, b, ...]) and
volray.Scene (volray-core's scene: one ray march through every volume).
One volume in a list renders exactly as alone; an opaque ball of one
volume in front of another's hides it, seen from either side; the
additive mix sums the volumes' colours; label volumes keep their table's
colours; bad input raises one clear exception."""

import numpy as np
import pytest
import volray

N = 32


def ball(centre, radius=6.0, n=N):
    """a[x, y, z]: 1 at `centre`, falling linearly to 0 at `radius`."""
    x, y, z = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
    d = np.sqrt((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2)
    return np.clip(1 - d / radius, 0, 1).astype(np.float32)


# Opaque where the value is over 0.2: a hard ball of radius 4.8.
OPAQUE = volray.TransferFunction(opacity=[(0, 0), (0.2, 0), (0.21, 1), (1, 1)])
# Faint everywhere: every sample shows through.
FAINT = volray.TransferFunction(opacity=[(0, 0), (1, 0.15)])


def pixels(frame):
    return frame.to_numpy(np.float32)


def centre(frame):
    p = pixels(frame)
    return p[p.shape[0] // 2, p.shape[1] // 2]


def test_two_volumes_render_together():
    a, b = ball((16, 8, 16)), ball((16, 24, 16))
    frame = volray.render([a, b], looks=[{"color": "magenta"}, {"color": "green"}], size=48)
    assert (frame.width, frame.height) == (48, 48)
    p = pixels(frame)
    # Seen from +x, +y is to the right: a (magenta) left, b (green) right.
    left, right = p[24, 12], p[24, 36]
    assert left[0] > 0.2 and left[2] > 0.2 and left[1] < 0.02, left
    assert right[1] > 0.2 and right[0] < 0.02, right
    # A tuple of volumes, and volray.Volume objects, are lists too.
    again = volray.render(
        (volray.Volume(a), volray.Volume(b)),
        looks=({"color": (1, 0, 1)}, {"color": "#00ff00"}),
        size=48,
    )
    assert np.array_equal(np.asarray(again), np.asarray(frame))


@pytest.mark.parametrize(
    "options",
    [
        {},
        {"azimuth": 30, "elevation": 20, "step": 0.5},
        {"post_classification": True, "colormap": "viridis"},
        {"blend": "mip", "colormap": "magma"},
        {"tf": FAINT, "colormap": "inferno", "range": (0.1, 0.9)},
        {"iso": 0.5, "perspective": 30},
        {"spacing": (1, 1.5, 0.8), "origin": (3, -2, 1), "crop": (0, 20, 0, 40, 0, 30)},
    ],
)
def test_one_volume_in_a_list_renders_as_alone(options):
    v = ball((12, 18, 16), radius=10) + 0.5 * ball((22, 10, 12), radius=5)
    alone = np.asarray(volray.render(v, size=40, **options))
    listed = np.asarray(volray.render([v], size=40, **options))
    assert np.array_equal(listed, alone)
    scene = volray.Scene([v], spacing=options.get("spacing"), origin=options.get("origin"))
    frame_options = {k: o for k, o in options.items() if k not in ("spacing", "origin")}
    assert np.array_equal(np.asarray(scene.render(size=40, **frame_options)), alone)


def test_one_label_volume_in_a_list_renders_as_alone():
    labels = (ball((16, 16, 16), radius=12) > 0.3).astype(np.uint8)
    labels[16:] *= 2
    alone = np.asarray(volray.render(labels, labels=True, size=40, azimuth=40))
    listed = np.asarray(volray.render([labels], looks=[{"labels": True}], size=40, azimuth=40))
    assert np.array_equal(listed, alone)


@pytest.mark.parametrize("reference", [False, True])
def test_the_front_volume_hides_the_one_behind_from_either_side(reference):
    # Both balls on the view axis: a nearer +x, b nearer -x.
    a, b = ball((23, 16, 16)), ball((9, 16, 16))
    looks = [{"color": "magenta"}, {"color": "green"}]
    common = dict(tf=OPAQUE, shading=False, size=48, reference=reference)
    # From +x (azimuth 0, looking along -x) a is in front, from -x b is.
    front_a = centre(volray.render([a, b], looks=looks, azimuth=0, **common))
    front_b = centre(volray.render([a, b], looks=looks, azimuth=180, **common))
    assert front_a[0] > 0.99 and front_a[2] > 0.99 and front_a[1] < 0.01, front_a
    assert front_b[1] > 0.99 and front_b[0] < 0.01 and front_b[2] < 0.01, front_b
    # Listed the other way round, the same volume wins: order is not depth.
    swapped = centre(volray.render([b, a], looks=looks[::-1], azimuth=0, **common))
    assert np.allclose(swapped, front_a, atol=1 / 255)


def test_the_additive_mix_sums_the_colours():
    a, b = ball((22, 16, 16), radius=8), ball((10, 16, 16), radius=8)
    looks = [{"color": "red"}, {"color": "green"}]
    common = dict(tf=FAINT, shading=False, size=40, mix="additive")
    both = pixels(volray.render([a, b], looks=looks, **common))
    only = [
        pixels(volray.render([a, b], looks=[looks[0], {**looks[1], "visible": False}], **common)),
        pixels(volray.render([a, b], looks=[{**looks[0], "visible": False}, looks[1]], **common)),
    ]
    # Each alone has its own colour only; together, their sum.
    assert only[0][:, :, 0].max() > 0.3 and only[0][:, :, 1].max() == 0
    assert only[1][:, :, 1].max() > 0.3 and only[1][:, :, 0].max() == 0
    expected = np.minimum(only[0][:, :, :3] + only[1][:, :, :3], 1)
    assert np.abs(both[:, :, :3] - expected).max() < 1e-5
    # Composited instead, the front ball dims the one behind: less green.
    composite = pixels(volray.render([a, b], looks=looks, **{**common, "mix": "composite"}))
    assert composite[20, 20, 1] < both[20, 20, 1] - 0.01


def test_opacity_scale_and_visible():
    a, b = ball((23, 16, 16)), ball((9, 16, 16))
    common = dict(tf=OPAQUE, shading=False, size=48)
    looks = [{"color": "magenta"}, {"color": "green"}]
    hidden = centre(
        volray.render([a, b], looks=[{**looks[0], "visible": False}, looks[1]], **common)
    )
    assert hidden[1] > 0.99 and hidden[0] < 0.01
    faded = centre(
        volray.render([a, b], looks=[{**looks[0], "opacity_scale": 0.05}, looks[1]], **common)
    )
    # The front ball lets 95 % of the light behind it through, per sample:
    # about 60 % through its 9.6 samples.
    assert 0.2 < faded[0] < 0.6 and 0.4 < faded[1] < 0.8, faded


def test_a_label_volume_over_a_scan():
    scan = ball((16, 16, 16), radius=14)
    labels = np.zeros((N, N, N), np.uint8)
    labels[4:12, 10:22, 10:22] = 1  # in front, from +x
    labels[20:28, 10:22, 10:22] = 2
    alone = pixels(volray.render(labels, labels=True, size=48))
    looks = [{"colormap": "gray", "opacity": (0, 0.02)}, {"labels": True}]
    scene = pixels(volray.render([scan, labels], looks=looks, size=48))
    hidden = pixels(
        volray.render([scan, labels], looks=[{**looks[0], "visible": False}, looks[1]], size=48)
    )
    # The labels keep their table's colours; the scan only greys them.
    assert np.abs(hidden - alone).max() <= 1 / 255 + 1e-6
    assert not np.array_equal(scene, hidden)
    # A label look may style the labels as a label volume alone would.
    only_two = pixels(
        volray.render(
            [scan, labels],
            looks=[{**looks[0], "visible": False}, {"labels": True, "show_labels": [2]}],
            size=48,
        )
    )
    assert not np.array_equal(only_two, hidden)
    with pytest.raises(ValueError, match="volume 1: color conflicts with labels=True"):
        volray.render([scan, labels], looks=[{}, {"labels": True, "color": "red"}], size=48)


def test_channel_axis_splits_channels_in_the_palette_colours():
    stack = np.stack([ball((16, 8, 16)), ball((16, 24, 16)), ball((16, 16, 8))])
    split = volray.render(stack, channel_axis=0, size=40)
    # Channels add up unless told otherwise.
    listed = volray.render(
        list(stack),
        looks=[{"color": "magenta"}, {"color": "green"}, {"color": "cyan"}],
        mix="additive",
        size=40,
    )
    assert np.array_equal(np.asarray(split), np.asarray(listed))
    # Where channels overlap, the additive mix sums what the composite mixes.
    same = np.stack([ball((16, 16, 16)), ball((16, 16, 16))])
    added = np.asarray(volray.render(same, channel_axis=0, size=40), dtype=float)
    mixed = np.asarray(volray.render(same, channel_axis=0, mix="composite", size=40), dtype=float)
    assert added[20, 20, :3].sum() > 1.3 * mixed[20, 20, :3].sum()
    # The axis may be any, negative too; a look's colour wins.
    moved = np.moveaxis(stack, 0, -1)
    again = volray.render(
        moved, channel_axis=-1, looks=[{}, {"color": "green"}, {"colormap": None}], size=40
    )
    assert np.array_equal(np.asarray(again), np.asarray(split))
    with pytest.raises(ValueError, match="channel_axis: expected a 4-D array"):
        volray.render(stack[0], channel_axis=0)


def test_a_scene_keeps_its_volumes_across_frames():
    a, b = ball((23, 16, 16)), ball((9, 16, 16))
    scene = volray.Scene([a, b], looks=[{"color": "magenta"}, {"color": "green"}])
    assert len(scene) == 2 and scene.mix == "composite"
    assert "32x32x32" in repr(scene)
    common = dict(tf=OPAQUE, shading=False, size=48)
    first = np.asarray(scene.render(**common))
    assert np.array_equal(
        first,
        np.asarray(volray.render([a, b], looks=scene.looks, **common)),
    )
    # Looks and mix are attributes.
    scene.looks = [{"color": "yellow"}, {"color": "green"}]
    assert scene.looks[0] == {"color": "yellow"}
    assert centre(scene.render(**common))[1] > 0.99
    scene.mix = "additive"
    assert scene.mix == "additive"
    with pytest.raises(ValueError, match="mix: unknown mix 'over'"):
        scene.mix = "over"
    # An array changed in place is rendered as it is now.
    scene.looks = [{"color": "magenta"}, {"color": "green"}]
    scene.mix = "composite"
    assert np.array_equal(np.asarray(scene.render(**common)), first)
    a[...] = 0
    assert centre(scene.render(**common))[1] > 0.99
    # A volume keyword is fixed once the volumes are prepared.
    with pytest.raises(ValueError, match=r"looks\[1\]: spacing is fixed"):
        scene.looks = [{}, {"spacing": (2, 2, 2)}]


def test_bad_input_raises_one_clear_exception():
    a, b = ball((16, 16, 16)), ball((16, 16, 16))
    with pytest.raises(ValueError, match="looks: 1 looks for 2 volumes: give one per volume"):
        volray.render([a, b], looks=[{}])
    with pytest.raises(TypeError, match=r"looks\[1\]: unknown key 'colour' for volume 1"):
        volray.render([a, b], looks=[{}, {"colour": "red"}])
    with pytest.raises(TypeError, match=r"looks\[0\]: expected a dict"):
        volray.render([a, b], looks=["red", {}])
    with pytest.raises(TypeError, match="unexpected keyword argument 'colour'"):
        volray.render([a, b], colour="red")
    far = volray.Volume(b, origin=(100, 0, 0))
    with pytest.raises(ValueError, match="volume 1 .* does not meet the first volume's box"):
        volray.render([a, far])
    with pytest.raises(ValueError, match="volume 1: preset: unknown preset 'bone2'"):
        volray.render([a, b], looks=[{}, {"preset": "bone2"}])
    with pytest.raises(TypeError, match="volume 0: opacity: expected two numbers"):
        volray.render([a, b], looks=[{"opacity": "x"}, {}])
    with pytest.raises(ValueError, match="volume 1: color: unknown colour 'mauve'"):
        volray.render([a, b], looks=[{}, {"color": "mauve"}])
    with pytest.raises(ValueError, match="volume 0: color conflicts with colormap"):
        volray.render([a, b], looks=[{"color": "red", "colormap": "inferno"}, {}])
    with pytest.raises(ValueError, match=r"volume 1: opacity_scale: 2 must be a number in \[0, 1"):
        volray.render([a, b], looks=[{}, {"opacity_scale": 2}])
    with pytest.raises(ValueError, match="mix: unknown mix 'sum'"):
        volray.render([a, b], mix="sum")
    with pytest.raises(ValueError, match="level: several volumes"):
        volray.render([a, b], level=1)
    nan = b.copy()
    nan[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="volume 1: .*nonfinite='transparent'"):
        volray.render([a, nan])
    # A look may say what the volume's own keywords are.
    volray.render([a, nan], looks=[{}, {"nonfinite": "transparent"}], size=16)


@pytest.mark.parametrize("mix", ["composite", "additive"])
def test_ctrl_c_stops_a_scene_frame(mix):
    from volray import _volray

    rng = np.random.default_rng(7)
    a, b = rng.random((40, 40, 40), np.float32), rng.random((40, 40, 40), np.float32)
    scene = volray.Scene([a, b], looks=[{"color": "magenta"}, {"color": "green"}], mix=mix)
    # One worker, held after its first report until the interrupt is seen.
    arguments = dict(size=64, step=0.25, opacity=(0, 0.02), threads=1)
    _volray._interrupt_next_frame()
    with pytest.raises(KeyboardInterrupt):
        scene.render(**arguments)
    reported = _volray._hooked_frame_pixels()
    assert 0 < reported < 64 * 64, reported
    # The scene renders on afterwards, as a fresh one does.
    fresh = volray.Scene([a.copy(), b.copy()], looks=scene.looks, mix=mix)
    assert np.array_equal(
        np.asarray(scene.render(**arguments)), np.asarray(fresh.render(**arguments))
    )


def test_the_volumes_brick_caches_share_what_max_memory_leaves_after_the_frame():
    # Each volume alone would get the limit less its own frame; together
    # their caches live at once, so they share what every frame leaves
    # (volray-app's shared_cache_budget), and a larger frame shrinks them.
    a, b = ball((16, 8, 16)), ball((16, 24, 16))
    limit = 64 << 20
    alone = volray.Renderer(a, max_memory=limit)
    alone.render()
    need = limit - alone._cache_budget  # one volume's default frame
    scene = volray.Scene([a, b], max_memory=limit)
    small = scene.render()
    shares = scene._cache_budgets
    assert len(shares) == 2 and shares[0] == shares[1]
    # Two volumes' frames, the rest halved: not the limit less one frame each.
    assert limit - 2 * need - 1 <= 2 * shares[0] <= limit - 2 * need
    assert 0 < shares[0] < alone._cache_budget / 2
    big = scene.render(size=(520, 500))
    # 16 bytes a pixel for each of the two frames, shared by two volumes.
    assert shares[0] - scene._cache_budgets[0] >= 16 * (520 * 500 - 480 * 480)
    budget = scene._cache_budgets
    again = scene.render()
    assert scene._cache_budgets == budget  # never grows back
    # The budget changes speed, never pixels.
    assert np.array_equal(pixels(small), pixels(again))
    assert np.array_equal(pixels(big), pixels(volray.Scene([a, b]).render(size=(520, 500))))
