"""The 4:2:0 colour conversion kernels against their plain-numpy references, and what they keep."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.videoio import bgr_to_i420, bgr_to_i420_reference, i420_to_bgr, i420_to_bgr_reference


@pytest.mark.parametrize(("h", "w"), [(48, 64), (30, 22), (2, 2)])
def test_kernels_agree_with_the_references(h: int, w: int) -> None:
    image = np.random.default_rng(h * w).integers(0, 256, (h, w, 3), dtype=np.uint8)
    planes = bgr_to_i420(image)
    assert planes.shape == (h * 3 // 2, w) and planes.dtype == np.uint8
    np.testing.assert_array_equal(planes, bgr_to_i420_reference(image))
    np.testing.assert_array_equal(i420_to_bgr(planes, h, w), i420_to_bgr_reference(planes, h, w))


def test_round_trip_keeps_flat_colours_and_a_blob_centre() -> None:
    for colour in [(128, 128, 128), (0, 128, 255), (40, 110, 30), (255, 255, 255), (0, 0, 0)]:
        flat = np.zeros((16, 16, 3), np.uint8)
        flat[:] = colour
        back = i420_to_bgr(bgr_to_i420(flat), 16, 16).astype(int)
        assert np.abs(back - np.array(colour)).max() <= 1, colour
    # a coloured patch on the carpet: its colour's centroid does not move (the chroma sits where it
    # belongs), to within 0.01 px
    img = np.zeros((64, 64, 3), np.uint8)
    img[:] = (40, 110, 30)
    img[20:30, 21:33] = (200, 50, 180)
    diff = np.abs(i420_to_bgr(bgr_to_i420(img), 64, 64).astype(float) - (40, 110, 30)).sum(axis=-1)
    v, u = np.mgrid[:64, :64]
    assert (diff * u).sum() / diff.sum() == pytest.approx(26.5, abs=0.01)
    assert (diff * v).sum() / diff.sum() == pytest.approx(24.5, abs=0.01)
