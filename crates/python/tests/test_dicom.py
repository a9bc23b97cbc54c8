"""volray.read on DICOM file-sets (crates/io/tests/fixtures/dicom/cd: a
DICOMDIR and two series, written by pydicom's FileSet) and segmentations
(dicom/seg.dcm, written by highdicom): the largest series by default,
`series=` by number or UID, and the label volume of a segmentation."""

from pathlib import Path

import numpy as np
import pytest

import volray

FIXTURES = Path(__file__).resolve().parents[3] / "crates/io/tests/fixtures"
CD = FIXTURES / "dicom/cd"


def test_a_cd_reads_its_largest_series_or_the_one_series_names():
    assert volray.read(CD).dims == (4, 3, 5)
    small = volray.read(CD, series=1)
    assert small.dims == (4, 3, 2)
    assert volray.read(CD / "DICOMDIR", series="1").dims == (4, 3, 2)
    # Series B stores v + 7 at (x, y, z): v = x + 10y + 100z.
    assert small.data[3, 2, 1] == 3 + 20 + 100 + 7
    with pytest.raises(ValueError, match=r'no series "7": name one by its number \(1 to 2\)'):
        volray.read(CD, series=7)


def test_a_segmentation_is_a_label_volume_of_its_segment_numbers():
    seg = volray.read(FIXTURES / "dicom/seg.dcm")
    assert seg.dims == (4, 3, 5)
    want = np.zeros((4, 3, 5))
    want[0, :, :] = 1
    want[3, 2, :] = 2
    assert np.array_equal(seg.data, want)


def test_labels_are_drawn_in_the_colours_the_segmentation_gives_them():
    # "bone" (label 1) red and "vessel" (label 2) blue in the file, which
    # neither palette colour of labels 1 and 2 (orange, green) is.
    seg = volray.read(FIXTURES / "dicom/seg.dcm")
    image = np.asarray(volray.render(seg, labels=True, size=48))
    rgb = image[..., :3].astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    assert ((b > 40) & (b > np.maximum(r, g) + 10)).any(), "no blue pixel"
    assert ((r > 40) & (r > 2 * np.maximum(g, b))).any(), "no red pixel"
