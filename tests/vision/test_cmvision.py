"""CMVision kernels against plain-numpy references and OpenCV.

Exact agreement: classification bit sets, runs, and region areas; centroids within 1e-9 px.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from vision import _kernels as kern
from vision.cmvision import (
    ColourClass,
    RegionParams,
    Segmenter,
    _screen_boxes,
    build_lut,
    classify_reference,
    merge_reference,
    regions_reference,
    runs_reference,
)
from vision.pipeline import default_colours

from .conftest import render, snapshot

CLASSES = default_colours()


@pytest.fixture(scope="module")
def scene(cameras: list) -> NDArray[np.uint8]:  # type: ignore[type-arg]
    robots = [[t, i, -3.6 + 0.3 * i, -1.0 + 1.4 * t, 0.4 * i] for t in (0, 1) for i in range(12)]
    image, _ = render(cameras[0], snapshot(robots, ball=(-2.2, 0.4, 0.0215)))
    return image


def random_image(seed: int, shape: tuple[int, int] = (60, 90)) -> NDArray[np.uint8]:
    """Blocky random colours (so that runs and regions form), plus noise."""
    rng = np.random.default_rng(seed)
    blocks = rng.integers(0, 256, size=(shape[0] // 6 + 1, shape[1] // 6 + 1, 3))
    img = np.repeat(np.repeat(blocks, 6, axis=0), 6, axis=1)[: shape[0], : shape[1]]
    img = img + rng.integers(-30, 31, size=img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def wide_classes() -> dict[str, ColourClass]:
    """Overlapping boxes that catch much of a random image."""
    return {
        "a": ColourClass(lo=(0, 0, 0), hi=(140, 255, 130)),
        "b": ColourClass(lo=(100, 90, 0), hi=(255, 255, 255)),
        "c": ColourClass(lo=(50, 100, 120), hi=(200, 160, 255)),
    }


@pytest.mark.parametrize("space", ["yuv", "bgr"])
@pytest.mark.parametrize("seed", [0, 1])
def test_lut_classification_equals_direct_thresholds(space: str, seed: int, scene: NDArray[np.uint8]) -> None:
    for image, classes in ((random_image(seed), wide_classes()), (scene, CLASSES)):
        seg = Segmenter(classes, space, RegionParams())  # type: ignore[arg-type]
        np.testing.assert_array_equal(seg.classify(image), classify_reference(image, list(classes.values()), space))  # type: ignore[arg-type]


def every_colour(step: int = 3) -> NDArray[np.uint8]:
    """One pixel per (b, g, r) on a grid of ``step`` levels per channel, 0 and 255 included."""
    v = np.unique(np.r_[np.arange(0, 256, step), 255]).astype(np.uint8)
    b, g, r = np.meshgrid(v, v, v, indexing="ij")
    return np.stack([b, g, r], axis=-1).reshape(len(v) * len(v), len(v), 3)


@pytest.mark.parametrize("space", ["yuv", "bgr"])
@pytest.mark.parametrize("classes", [CLASSES, wide_classes()], ids=["default", "wide"])
def test_screened_classification_equals_direct_thresholds_over_colour_space(
    space: str, classes: dict[str, ColourClass]
) -> None:
    # the default boxes screen most colours out; the wide ones let many pixels through the screen
    image = every_colour()
    seg = Segmenter(classes, space, RegionParams())  # type: ignore[arg-type]
    bits = classify_reference(image, list(classes.values()), space)  # type: ignore[arg-type]
    np.testing.assert_array_equal(seg.classify(image), bits)
    runs, counts = seg.runs(image)
    got = [[tuple(int(x) for x in runs[i, k]) for k in range(counts[i])] for i in range(image.shape[0])]
    assert got == runs_reference(bits)


@pytest.mark.parametrize("classes", [CLASSES, wide_classes(), {}], ids=["default", "wide", "none"])
def test_screen_rows_are_the_class_boxes_in_unsigned_compare_form(classes: dict[str, ColourClass]) -> None:
    boxes = _screen_boxes(list(classes.values()))
    assert boxes.dtype == np.uint8 and boxes.shape == (len(classes), 6)
    v = np.arange(256)
    for row, c in zip(boxes.astype(np.int64), classes.values(), strict=True):
        for ch in range(3):
            lo, width = row[2 * ch], row[2 * ch + 1]
            # the kernel's test: uint8(value - lo) <= width, exactly lo <= value <= hi
            np.testing.assert_array_equal((v - lo) % 256 <= width, (v >= c.lo[ch]) & (v <= c.hi[ch]))


def test_yuv_matches_opencv_within_one_level() -> None:
    from vision.cmvision import convert_colour

    image = random_image(3)
    ours = convert_colour(image, "yuv")
    # OpenCV's full-range YCrCb holds the same channels in the order Y, Cr (our V), Cb (our U)
    cv = cv2.cvtColor(image, cv2.COLOR_BGR2YCrCb).astype(np.int32)[..., [0, 2, 1]]
    assert np.abs(ours - cv).max() <= 1


def test_lut_has_one_bit_per_class() -> None:
    lut = build_lut(list(wide_classes().values()))
    assert lut.shape == (3, 256)
    assert lut[0, 120] == 0b111  # channel 0: a is 0..140, b 100..255, c 50..200
    assert lut[0, 210] == 0b010
    assert lut[1, 95] == 0b011  # channel 1: a is 0..255, b 90..255, c 100..160
    with pytest.raises(ValueError, match="at most 32"):
        build_lut([ColourClass()] * 33)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fused_runs_equal_reference(seed: int) -> None:
    image = random_image(seed)
    seg = Segmenter(wide_classes(), "yuv", RegionParams())
    runs, counts = seg.runs(image)
    ref = runs_reference(classify_reference(image, list(wide_classes().values()), "yuv"))
    got = [[tuple(int(x) for x in runs[i, k]) for k in range(counts[i])] for i in range(image.shape[0])]
    assert got == ref


@pytest.mark.parametrize("threads", [2, 3, 7])
def test_runs_in_bands_on_threads_equal_reference(threads: int) -> None:
    # every image counts as large: the rows are split into ``threads`` bands classified at once
    image = random_image(threads, (61, 90))
    seg = Segmenter(wide_classes(), "yuv", RegionParams(threads=threads, threads_min_pixels=0))
    runs, counts = seg.runs(image)
    ref = runs_reference(classify_reference(image, list(wide_classes().values()), "yuv"))
    got = [[tuple(int(x) for x in runs[i, k]) for k in range(counts[i])] for i in range(image.shape[0])]
    assert got == ref


def test_runs_beyond_capacity_are_dropped() -> None:
    image = np.zeros((4, 64, 3), np.uint8)
    image[:, ::2] = 255  # 32 one-pixel runs per row
    seg = Segmenter({"white": ColourClass(lo=(200, 0, 0), hi=(255, 255, 255))}, "yuv", RegionParams(max_runs_per_row=8))
    _, counts = seg.runs(image)
    assert counts.tolist() == [8, 8, 8, 8]


@pytest.mark.parametrize("connectivity", [4, 8])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_regions_equal_opencv_connected_components(connectivity: int, seed: int) -> None:
    image = random_image(seed, (80, 120))
    classes = wide_classes()
    params = RegionParams(connectivity=connectivity, merge_gap_px=0.0)
    seg = Segmenter({n: ColourClass(lo=c.lo, hi=c.hi, min_area_px=1) for n, c in classes.items()}, "yuv", params)
    regions = seg.regions(image, merge=False)
    bits = classify_reference(image, list(classes.values()), "yuv")
    low = np.full(bits.shape, -1)
    for k in range(len(classes) - 1, -1, -1):
        low[(bits >> k) & 1 == 1] = k
    for k in range(len(classes)):
        n, labels, stats, cents = cv2.connectedComponentsWithStats(
            (low == k).astype(np.uint8), connectivity=connectivity
        )
        ours = regions.of_class(k)
        assert len(ours) == n - 1
        ref = sorted(((stats[j, cv2.CC_STAT_AREA], cents[j, 0] + 0.5, cents[j, 1] + 0.5) for j in range(1, n)),
                     key=lambda r: (-r[0], r[1], r[2]))
        got = sorted(((regions.area[j], *regions.centroid[j]) for j in ours), key=lambda r: (-r[0], r[1], r[2]))
        np.testing.assert_allclose(np.array(got), np.array(ref), atol=1e-9)
        # the kernels' statistics also equal plain numpy on OpenCV's labels (moments, boxes)
        table = regions_reference(labels.astype(np.int64) - 1, np.full(labels.shape, k))
        np.testing.assert_allclose(
            sorted(map(tuple, table[:, kern.R_AREA :])), sorted(map(tuple, _stats_of(seg, image, k))), atol=1e-6
        )
        assert np.all(np.diff(regions.area[ours]) <= 0), "regions sorted by area"


def _stats_of(seg: Segmenter, image: NDArray[np.uint8], k: int) -> NDArray[np.float64]:
    runs, counts = seg.runs(image)
    flat, label, n = kern.connect_runs(runs, counts, seg.params.connectivity == 8)
    st = kern.region_stats(flat, label, int(n[0]))
    return st[st[:, kern.R_CLASS] == k][:, kern.R_AREA :]


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_merge_kernel_equals_reference(seed: int) -> None:
    image = random_image(seed, (80, 120))
    seg = Segmenter(wide_classes(), "yuv", RegionParams())
    runs, counts = seg.runs(image)
    flat, label, n = kern.connect_runs(runs, counts, True)
    stats = kern.region_stats(flat, label, int(n[0]))
    ref = merge_reference(stats, 2.0, 0.3)
    got = stats.copy()
    alive = kern.merge_regions(got, 2.0, 0.3)
    assert alive.sum() < len(stats), "the case merges something"
    np.testing.assert_allclose(got[alive], ref)


def test_density_merge_joins_fragments_and_min_area_drops_specks() -> None:
    image = np.zeros((40, 40, 3), np.uint8)
    image[10:20, 10:20] = (255, 255, 255)
    image[14, 10:20] = 0  # a dot cut in two by a dark row
    image[30, 30] = (255, 255, 255)  # a speck
    white = ColourClass(lo=(200, 0, 0), hi=(255, 255, 255), min_area_px=3)
    seg = Segmenter({"white": white}, "yuv", RegionParams(connectivity=4, merge_gap_px=1.0, merge_min_density=0.8))
    merged = seg.regions(image)
    assert merged.area.tolist() == [90.0]
    np.testing.assert_allclose(merged.centroid[0], [15.0, 15.0 + 0.5 / 9.0 * 1.0], atol=0.06)
    unmerged = seg.regions(image, merge=False)
    assert sorted(unmerged.area.tolist()) == [40.0, 50.0]


@pytest.mark.slow
@pytest.mark.parametrize("space", ["yuv", "bgr"])
def test_kernel_colour_conversion_equals_reference_for_every_colour(space: str) -> None:
    from vision.cmvision import convert_colour

    g, r = np.meshgrid(np.arange(256), np.arange(256), indexing="ij")
    for b in range(0, 256, 32):  # all 2^24 colours, 32 blue levels at a time
        image = np.stack([np.broadcast_to(np.arange(b, b + 32)[:, None, None], (32, 256, 256)),
                          np.broadcast_to(g, (32, 256, 256)), np.broadcast_to(r, (32, 256, 256))],
                         axis=-1).astype(np.uint8).reshape(32 * 256, 256, 3)
        np.testing.assert_array_equal(kern.channels(image, space == "yuv"), convert_colour(image, space))  # type: ignore[arg-type]


def speckled_stats(seed: int) -> NDArray[np.float64]:
    """Region statistics of a field of one-pixel and few-pixel specks and some larger blobs, two
    classes: many fragments within the merge gap of each other, as along a field line's edges."""
    rng = np.random.default_rng(seed)
    image = np.zeros((90, 140, 3), np.uint8)
    for _ in range(12):
        v, u, h, w = rng.integers(0, 80), rng.integers(0, 130), rng.integers(2, 9), rng.integers(2, 9)
        image[v : v + h, u : u + w] = (255, 255, 255) if rng.random() < 0.5 else (0, 0, 255)
    specks = rng.random(image.shape[:2]) < 0.08
    image[specks] = np.where(rng.random((int(specks.sum()), 1)) < 0.5, [255, 255, 255], [0, 0, 255])
    classes = {"white": ColourClass(lo=(200, 0, 0), hi=(255, 255, 255)),
               "red": ColourClass(lo=(50, 0, 200), hi=(120, 120, 255))}
    seg = Segmenter(classes, "yuv", RegionParams())
    runs, counts = seg.runs(image)
    flat, label, n = kern.connect_runs(runs, counts, True)
    return kern.region_stats(flat, label, int(n[0]))


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(("gap", "density"), [(1.0, 0.6), (0.0, 0.3), (2.5, 0.4), (40.0, 0.05)])
def test_merge_kernel_equals_reference_among_many_specks(seed: int, gap: float, density: float) -> None:
    stats = speckled_stats(seed)
    assert len(stats) > 300 and set(stats[:, kern.R_CLASS]) == {0.0, 1.0}
    ref = merge_reference(stats, gap, density)
    got = stats.copy()
    alive = kern.merge_regions(got, gap, density)
    assert len(ref) < len(stats), "the case merges"
    np.testing.assert_array_equal(got[alive], ref)  # the same merges in the same order: the same sums


@pytest.mark.parametrize("space", ["yuv", "bgr"])
def test_light_per_cell_equals_the_numpy_reference(space: str) -> None:
    """Gains per cell of a 3 x 4 grid (some saturating, some darkening) applied before the boxes:
    the kernel's classification and runs equal the reference's exactly; no gains: the image as it is."""
    image = every_colour(5)
    h, w = image.shape[:2]
    gains = np.random.default_rng(4).uniform(0.5, 1.6, (3, 4, 3))
    classes = wide_classes()
    seg = Segmenter(classes, space, RegionParams())  # type: ignore[arg-type]
    seg.set_light(gains, w, h)
    bits = classify_reference(image, list(classes.values()), space, gains)  # type: ignore[arg-type]
    np.testing.assert_array_equal(seg.classify(image), bits)
    runs, counts = seg.runs(image)
    got = [[tuple(int(x) for x in runs[i, k]) for k in range(counts[i])] for i in range(h)]
    assert got == runs_reference(bits)
    assert not np.array_equal(bits, classify_reference(image, list(classes.values()), space))  # type: ignore[arg-type]
    seg.set_light(None, w, h)
    np.testing.assert_array_equal(seg.classify(image), classify_reference(image, list(classes.values()), space))  # type: ignore[arg-type]


def test_light_applies_only_where_marked() -> None:
    """Gains with ``where`` (bands of rows x columns, as many bands in each row of cells): the pixels
    of marked band columns are classified as the reference classifies the lit image, the others as it
    classifies the image as it is."""
    image = every_colour(5)
    h, w = image.shape[:2]
    gains = np.random.default_rng(5).uniform(0.5, 1.6, (3, 4, 3))
    classes = wide_classes()
    bands = 3 * 4
    where = np.random.default_rng(6).uniform(size=(bands, w)) < 0.5
    seg = Segmenter(classes, "yuv", RegionParams())
    seg.set_light(gains, w, h, where)
    lit = classify_reference(image, list(classes.values()), "yuv", gains)
    plain = classify_reference(image, list(classes.values()), "yuv")
    per_pixel = where[np.minimum(np.arange(h) * bands // h, bands - 1)]
    np.testing.assert_array_equal(seg.classify(image), np.where(per_pixel, lit, plain))
    assert not np.array_equal(lit[per_pixel], plain[per_pixel]) and not np.array_equal(lit, plain)
