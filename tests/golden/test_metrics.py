"""Image and provenance metrics."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis.extra.numpy import arrays

from rend3r.golden.metrics import (
    as_rgb888,
    diff_image,
    image_metrics,
    interior_mask,
    provenance_metrics,
    region_interior_mask,
)
from rend3r.emu.image import rgb565_to_rgb888


def test_rgb565_bit_replication() -> None:
    fb = np.array([[0xFFFF, 0x0000, 0xF800, 0x07E0, 0x001F, 0b10000_100000_10000]], dtype=np.uint16)
    rgb = rgb565_to_rgb888(fb)
    assert rgb.tolist() == [[[255, 255, 255], [0, 0, 0], [255, 0, 0], [0, 255, 0], [0, 0, 255], [132, 130, 132]]]


def test_identical_images() -> None:
    fb = np.arange(12, dtype=np.uint16).reshape(3, 4) * 997
    m = image_metrics(fb, fb.copy())
    assert (m.pixels, m.differing, m.max_channel) == (12, 0, 0)
    assert math.isinf(m.psnr)
    assert m.within(0, 0.0, 100.0)


def test_known_difference() -> None:
    a = np.zeros((2, 2, 3), dtype=np.uint8)
    b = a.copy()
    b[0, 0, 1] = 10
    m = image_metrics(a, b)
    assert (m.differing, m.max_channel) == (1, 10)
    assert m.share_differing == 0.25
    mse = 100 / 12
    assert m.psnr == pytest.approx(10 * math.log10(255**2 / mse))
    assert m.within(max_channel=10)
    assert not m.within(max_channel=9)
    assert not m.within(max_share=0.2)
    assert m.within(min_psnr=m.psnr)
    assert not m.within(min_psnr=m.psnr + 0.01)


def test_size_mismatch_rejected() -> None:
    with pytest.raises(ValueError, match="sizes differ"):
        image_metrics(np.zeros((2, 2), np.uint16), np.zeros((2, 3), np.uint16))


def test_bad_image_kind_rejected() -> None:
    with pytest.raises(ValueError, match="expected"):
        as_rgb888(np.zeros((2, 2), np.float32))


@settings(max_examples=50)
@given(arrays(np.uint16, (4, 5)), arrays(np.uint16, (4, 5)))
def test_metrics_symmetric_and_bounded(a: np.ndarray, b: np.ndarray) -> None:
    m1, m2 = image_metrics(a, b), image_metrics(b, a)
    assert m1 == m2
    assert 0 <= m1.max_channel <= 255
    assert 0 <= m1.differing <= m1.pixels
    assert (m1.differing == 0) == (np.array_equal(a, b)) == math.isinf(m1.psnr)


def test_provenance_metrics() -> None:
    a = np.array([[-1, 0, 1, 2]], dtype=np.int32)
    b = np.array([[0, -1, 1, 3]], dtype=np.int32)
    m = provenance_metrics(a, b)
    assert (m.pixels, m.hit_miss, m.nearest_shape) == (4, 2, 1)


def test_interior_mask() -> None:
    prov = np.full((5, 6), -1, dtype=np.int32)
    prov[1:4, 1:4] = 7
    mask = interior_mask(prov)
    # only the centre of the 3x3 hit block is all-hit; column 5 has no hit neighbour
    expected = np.array(
        [
            [0, 0, 0, 0, 0, 1],
            [0, 0, 0, 0, 0, 1],
            [0, 0, 1, 0, 0, 1],
            [0, 0, 0, 0, 0, 1],
            [0, 0, 0, 0, 0, 1],
        ],
        dtype=bool,
    )
    assert mask.tolist() == expected.tolist()


def test_diff_image_highlights_changed_pixels() -> None:
    a = np.full((2, 3), 0xFFFF, dtype=np.uint16)
    b = a.copy()
    b[1, 2] = 0xFFDF  # one blue step lower
    d = diff_image(a, b)
    assert d.shape == (2, 3, 3) and d.dtype == np.uint8
    assert d[1, 2].tolist()[1] == 0 and d[1, 2, 0] == d[1, 2, 2] >= 128
    assert d[0, 0].tolist() == [63, 63, 63]


def test_region_interior_mask_separates_shapes() -> None:
    prov = np.array(
        [
            [0, 0, 0, 1, 1, 1],
            [0, 0, 0, 1, 1, 1],
            [0, 0, 0, 1, 1, 1],
        ],
        dtype=np.int32,
    )
    mask = region_interior_mask(prov)
    # columns 2 and 3 touch the other shape; the rest see one shape in all 3x3 neighbours
    assert mask.tolist() == [[True, True, False, False, True, True]] * 3


def test_masked_metrics_count_only_masked_pixels() -> None:
    a = np.zeros((2, 2), dtype=np.uint16)
    b = a.copy()
    b[0, 0] = 0xFFFF
    mask = np.array([[False, True], [True, True]])
    m = image_metrics(a, b, mask)
    assert (m.pixels, m.differing, m.max_channel) == (3, 0, 0)
    assert image_metrics(a, b, ~mask).max_channel == 255
