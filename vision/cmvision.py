"""CMVision, the colour machine vision library (Bruce's thesis, appendix A.1).

An image (H, W, 3) BGR uint8 becomes colour regions in four steps:

1. Thresholding (A.1.3): each colour class is a box ``lo <= c <= hi`` in a colour space (YUV by
   default, A.1.2). The boxes are compiled into three tables of 256 bit masks, one per channel,
   so one pass classifies every pixel into up to 32 classes with three look-ups and two ANDs.
   All three channels are computed in vectorised rows and screened against every class's box
   first: most of a field (carpet, lines, the robots' black covers) fails there, so the look-ups
   and the run-length encoding touch only the few pixels of some class.
2. Run-length encoding: runs of one class along each row.
3. Connected regions (A.1.4): runs that touch across rows are joined by union-find.
4. Region statistics (A.1.5): area, centroid, bounding box, second moments; density-based merging
   of nearby fragments (A.1.6); a minimum area per class; regions sorted by area.

A region too large for what its class marks (:class:`SplitRule`: a dot that touches a light segment
of its colour on a real robot cover, the two joined into one region) is opened by a disc, a
morphological opening that keeps the parts a disc of that radius fits in and drops the thin ones
and the necks between them; the round parts that remain become regions of their own, and the rest
is dropped.

Pixel coordinates: (u, v) = (column, row); a centroid is reported at pixel centres, so the
centre of pixel (i, j) is (j + 0.5, i + 0.5), as in :mod:`cmdragons.camera`.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from cmdragons.config import Validated, setting
from vision import _kernels as kern

__all__ = [
    "MAX_CLASSES",
    "ColourClass",
    "ColourSpace",
    "RegionParams",
    "Regions",
    "Segmenter",
    "SplitRule",
    "build_lut",
    "classify_reference",
    "convert_colour",
    "merge_reference",
    "regions_reference",
    "runs_reference",
]

MAX_CLASSES = 32
ColourSpace = Literal["yuv", "bgr"]

# Fixed-point (x 256) maps from (b, g, r) to each channel, plus an offset: YUV is the full-range
# YCbCr of JPEG (what most cameras deliver as "YUV"), BGR passes the channels through.
_CONVERSIONS: dict[str, NDArray[np.int32]] = {
    "yuv": np.array([[29, 150, 77, 0], [128, -85, -43, 128], [-21, -107, 128, 128]], dtype=np.int32),
    "bgr": np.array([[256, 0, 0, 0], [0, 256, 0, 0], [0, 0, 256, 0]], dtype=np.int32),
}


@dataclass(frozen=True)
class ColourClass(Validated):
    """One colour class: a box in the colour space (channel order of the space, 0..255 each)."""

    lo: tuple[int, int, int] = setting((0, 0, 0), lo=0, hi=255)
    hi: tuple[int, int, int] = setting((255, 255, 255), lo=0, hi=255)
    min_area_px: int = setting(4, lo=1, hi=1_000_000)  # smaller regions are dropped as noise

    def __post_init__(self) -> None:
        super().__post_init__()
        if any(a > b for a, b in zip(self.lo, self.hi, strict=True)):
            raise ValueError(f"colour box lo {list(self.lo)} must not exceed hi {list(self.hi)} in any channel")


@dataclass(frozen=True)
class RegionParams(Validated):
    """How runs become regions."""

    connectivity: int = setting(8, choices=(4, 8))  # neighbouring pixels that join a region
    merge_gap_px: float = setting(1.0, lo=0.0, hi=50.0)  # bounding boxes at most this far apart may merge
    merge_min_density: float = setting(0.6, lo=0.0, hi=1.0)  # merged area / merged bounding-box area, at least
    max_runs_per_row: int = setting(256, lo=8, hi=8192)  # more runs in a row are dropped (pure noise)
    # images of at least this many pixels are classified in bands of rows on this many threads at
    # once (the same runs either way); smaller ones on one
    threads: int = setting(2, lo=1, hi=64)
    threads_min_pixels: int = setting(1_500_000, lo=0, hi=10**9)


@dataclass(frozen=True)
class SplitRule:
    """Which regions :class:`Segmenter` splits, pixels: those of a class larger than its
    ``max_area_px`` (inf: never), opened by a disc of ``open_radius_px``; of the parts, those no
    more elongated than ``max_elongation`` (ratio of the second moments' axes) are kept."""

    max_area_px: NDArray[np.float64]  # per class
    open_radius_px: float
    max_elongation: float = 1.6


def _half_widths(element: NDArray[np.uint8]) -> NDArray[np.int64]:
    """Per row of a structuring element symmetric about its centre column, how far it reaches to
    each side of that column (-1: an empty row), as :func:`vision._kernels.disc_fits` takes it."""
    c = element.shape[1] // 2
    out = np.full(element.shape[0], -1, dtype=np.int64)
    for k, row in enumerate(element):
        on = np.flatnonzero(row)
        if on.size:
            if on[0] + on[-1] != 2 * c or on.size != on[-1] - on[0] + 1:
                raise ValueError("structuring element rows must be contiguous and centred")
            out[k] = c - on[0]
    return out


@functools.cache
def _disc(radius_px: int) -> tuple[NDArray[np.uint8], NDArray[np.int64]]:
    """OpenCV's disc of that radius (px) and its rows' half widths (:func:`_half_widths`)."""
    import cv2

    disc = np.asarray(cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius_px + 1, 2 * radius_px + 1)),
                      dtype=np.uint8)
    half = _half_widths(disc)
    disc.flags.writeable = half.flags.writeable = False  # shared by every call
    return disc, half


def split_region(flat: NDArray[np.int32], rule: SplitRule) -> NDArray[np.float64]:
    """The round parts of one region given by its runs ``flat`` (n, 4: row, u_start, u_end, class)
    after an opening by a disc of ``rule.open_radius_px``: rows of the region table
    (:mod:`vision._kernels` layout, u and v at pixel corners), possibly none."""
    import cv2

    r = max(1, int(round(rule.open_radius_px)))
    disc, half = _disc(r)
    if not kern.disc_fits(flat, half):
        return np.zeros((0, kern.R_COLS))  # the opening is empty: no round part (a thin line)
    u0, v0 = int(flat[:, 1].min()) - r, int(flat[:, 0].min()) - r
    mask = np.zeros((int(flat[:, 0].max()) - v0 + r + 1, int(flat[:, 2].max()) - u0 + r + 1), np.uint8)
    for row, a, b, _ in flat:
        mask[row - v0, a - u0 : b - u0 + 1] = 1
    n, labels = cv2.connectedComponents(cv2.morphologyEx(mask, cv2.MORPH_OPEN, disc), connectivity=8)
    rows = regions_reference(labels.astype(np.int64) - 1, np.full(labels.shape, int(flat[0, 3]), np.int64))
    if n <= 1:
        return rows
    # back to image coordinates: shift the sums and the boxes by the crop's corner
    a, su, sv = rows[:, kern.R_AREA], rows[:, kern.R_SUM_U].copy(), rows[:, kern.R_SUM_V].copy()
    rows[:, kern.R_SUM_U] += a * u0
    rows[:, kern.R_SUM_V] += a * v0
    rows[:, kern.R_SUM_UU] += 2 * u0 * su + a * u0 * u0
    rows[:, kern.R_SUM_VV] += 2 * v0 * sv + a * v0 * v0
    rows[:, kern.R_SUM_UV] += u0 * sv + v0 * su + a * u0 * v0
    rows[:, [kern.R_U0, kern.R_U1]] += u0
    rows[:, [kern.R_V0, kern.R_V1]] += v0
    m = Regions.from_stats(rows).moments
    tr, det = m[:, 0] + m[:, 1], m[:, 0] * m[:, 1] - m[:, 2] ** 2
    disc_ = np.sqrt(np.maximum(tr * tr / 4.0 - det, 0.0))
    elong = np.sqrt((tr / 2.0 + disc_) / np.maximum(tr / 2.0 - disc_, 1e-6))
    return rows[elong <= rule.max_elongation]


def convert_colour(image: NDArray[np.uint8], space: ColourSpace) -> NDArray[np.int32]:
    """The image (H, W, 3) BGR in ``space``, channels 0..255: the plain-numpy reference of the
    kernels' conversion (the same fixed-point arithmetic)."""
    conv = _CONVERSIONS[space]
    px = image.astype(np.int32)
    out = np.empty(image.shape, dtype=np.int32)
    for k in range(3):
        c = (px[..., 0] * conv[k, 0] + px[..., 1] * conv[k, 1] + px[..., 2] * conv[k, 2] + 128) >> 8
        out[..., k] = np.clip(c + conv[k, 3], 0, 255)
    return out


def build_lut(classes: Sequence[ColourClass]) -> NDArray[np.uint32]:
    """Per channel, a table of 256 bit masks: bit k of ``lut[c, x]`` is set when value ``x`` of
    channel ``c`` lies in class k's range (thesis A.1.3, figure A.3)."""
    if len(classes) > MAX_CLASSES:
        raise ValueError(f"at most {MAX_CLASSES} colour classes, got {len(classes)}")
    lut = np.zeros((3, 256), dtype=np.uint32)
    for k, cc in enumerate(classes):
        for c in range(3):
            lut[c, cc.lo[c] : cc.hi[c] + 1] |= np.uint32(1 << k)
    return lut


def _screen_boxes(classes: Sequence[ColourClass]) -> NDArray[np.uint8]:
    """Per class, its box as a row ``(lo0, width0, lo1, width1, lo2, width2)`` uint8, each range
    ``[lo, lo + width]``: the kernel's vectorised screen, which lets a pixel through to the table
    look-ups and the run-length encoding when one class holds it."""
    return np.array([[v for ch in range(3) for v in (c.lo[ch], c.hi[ch] - c.lo[ch])] for c in classes],
                    dtype=np.uint8).reshape(-1, 6)


def classify_reference(
    image: NDArray[np.uint8], classes: Sequence[ColourClass], space: ColourSpace,
    gains: NDArray[np.float64] | None = None,
) -> NDArray[np.uint32]:
    """Per pixel, the bit set of classes whose box holds it, by a direct threshold test; with
    ``gains`` (rows of cells, columns of cells, 3), each pixel's BGR first scaled by its cell's
    (x 256 fixed point, rounded, saturated), cells splitting the image evenly."""
    if gains is not None:
        h, w = image.shape[:2]
        ny, nx = gains.shape[:2]
        g = np.round(np.clip(gains, 0.0, 8.0) * 256.0).astype(np.int64)
        per_px = g[np.minimum(np.arange(h) * ny // h, ny - 1)][:, np.minimum(np.arange(w) * nx // w, nx - 1)]
        image = np.minimum((image.astype(np.int64) * per_px + 128) >> 8, 255).astype(np.uint8)
    c = convert_colour(image, space)
    out = np.zeros(image.shape[:2], dtype=np.uint32)
    for k, cc in enumerate(classes):
        inside = np.all((c >= np.array(cc.lo)) & (c <= np.array(cc.hi)), axis=-1)
        out[inside] |= np.uint32(1 << k)
    return out


@dataclass(frozen=True)
class Regions:
    """Colour regions of one image, sorted by class, then by area (largest first).

    Pixel units; ``centroid`` (n, 2) as (u, v) at pixel centres; ``bbox`` (n, 4) as
    u0, v0, u1, v1 inclusive pixel indices; ``moments`` (n, 3) the central second moments
    (uu, vv, uv) in px^2.
    """

    cls: NDArray[np.int64]
    area: NDArray[np.float64]
    centroid: NDArray[np.float64]
    bbox: NDArray[np.float64]
    moments: NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.cls.shape[0])

    def of_class(self, k: int) -> NDArray[np.int64]:
        """Indices of the regions of class ``k`` (largest first)."""
        return np.flatnonzero(self.cls == k)

    @staticmethod
    def from_stats(stats: NDArray[np.float64]) -> Regions:
        a = stats[:, kern.R_AREA]
        mu = stats[:, kern.R_SUM_U] / a
        mv = stats[:, kern.R_SUM_V] / a
        moments = np.stack(
            [stats[:, kern.R_SUM_UU] / a - mu * mu, stats[:, kern.R_SUM_VV] / a - mv * mv,
             stats[:, kern.R_SUM_UV] / a - mu * mv], axis=1,
        )
        bbox = stats[:, [kern.R_U0, kern.R_V0, kern.R_U1, kern.R_V1]]
        return Regions(stats[:, kern.R_CLASS].astype(np.int64), a.copy(), np.stack([mu + 0.5, mv + 0.5], axis=1),
                       bbox.copy(), moments)


def _finish(stats: NDArray[np.float64], min_area: NDArray[np.float64]) -> Regions:
    """Per-class minimum area, then sorted by class and decreasing area."""
    stats = stats[stats[:, kern.R_AREA] >= min_area[stats[:, kern.R_CLASS].astype(np.int64)]]
    order = np.lexsort((-stats[:, kern.R_AREA], stats[:, kern.R_CLASS]))
    return Regions.from_stats(stats[order])


class Segmenter:
    """CMVision over images of one size: the compiled tables and reusable run buffers."""

    def __init__(self, classes: Mapping[str, ColourClass], space: ColourSpace, params: RegionParams,
                 split: SplitRule | None = None) -> None:
        self.split = split
        self.names = list(classes)
        self.classes = [classes[n] for n in self.names]
        self.space = space
        self.params = params
        self.lut = build_lut(self.classes)
        self._screen = _screen_boxes(self.classes)
        self.min_area = np.array([c.min_area_px for c in self.classes], dtype=np.float64)
        self._runs: NDArray[np.int32] = np.zeros((0, 0, 3), dtype=np.int32)
        self._counts: NDArray[np.int64] = np.zeros(0, dtype=np.int64)
        self._no_runs = np.zeros((0, 1, 3), dtype=np.int32)  # "keep no runs" for the kernel
        self._no_bits = np.zeros((0, 1), dtype=np.uint32)
        self._pool: ThreadPoolExecutor | None = None  # the bands' threads for large images, made on first use
        self._gains: NDArray[np.int32] = np.zeros((0, 0), dtype=np.int32)  # the light per cell: none
        self._row_cell: NDArray[np.int64] = np.zeros(0, dtype=np.int64)

    def set_light(self, gains: NDArray[np.float64] | None, width: int, height: int,
                  where: NDArray[np.bool_] | None = None) -> None:
        """Colour gains per cell of a grid over images of ``width`` x ``height``: ``gains`` (rows of
        cells, columns of cells, 3) per BGR channel, each pixel's channels scaled by its cell's before
        it is classified (:func:`vision._kernels.classify`); None: none. Cells split the image evenly.
        ``where`` (bands of rows, ``width``) bool, the image's rows split evenly into bands: the
        gains apply only to the band's columns marked (elsewhere the pixels are taken as they are)."""
        if gains is None:
            self._gains, self._row_cell = np.zeros((0, 0), dtype=np.int32), np.zeros(0, dtype=np.int64)
            return
        ny, nx = gains.shape[:2]
        col_cell = np.minimum(np.arange(width) * nx // width, nx - 1)
        fixed = np.round(np.clip(gains, 0.0, 8.0) * 256.0).astype(np.int32)  # (ny, nx, 3), x 256
        if where is None:
            self._row_cell = np.minimum(np.arange(height) * ny // height, ny - 1).astype(np.int64)
            self._gains = np.ascontiguousarray(fixed[:, col_cell, :].reshape(ny, width * 3))
            return
        nb = where.shape[0]
        first = (np.arange(nb) * height + nb - 1) // nb  # each band's first row (row i is in band i * nb // height)
        band_row = np.minimum(first * ny // height, ny - 1)  # the row of cells holding it
        per = fixed[band_row][:, col_cell, :]  # (bands, width, 3)
        per = np.where(where[:, :, None], per, np.int32(256))
        self._row_cell = np.minimum(np.arange(height) * nb // height, nb - 1).astype(np.int64)
        self._gains = np.ascontiguousarray(per.reshape(nb, width * 3), dtype=np.int32)

    def index(self, name: str) -> int:
        return self.names.index(name)

    def classify(self, image: NDArray[np.uint8]) -> NDArray[np.uint32]:
        """Per pixel, the bit set of classes (bit k: class k) whose box holds it."""
        out = np.empty(image.shape[:2], dtype=np.uint32)
        kern.classify(np.ascontiguousarray(image), self.space == "yuv", self.lut, self._screen, out, self._no_runs,
                      self._counts, self._gains, self._row_cell, 0, image.shape[0])
        return out

    def runs(self, image: NDArray[np.uint8]) -> tuple[NDArray[np.int32], NDArray[np.int64]]:
        """Classification and run-length encoding in one pass: per row, runs (u0, u1, class) and
        their count (views into reused buffers, valid until the next call)."""
        h = image.shape[0]
        if self._runs.shape[0] != h or self._runs.shape[1] != self.params.max_runs_per_row:
            self._runs = np.zeros((h, self.params.max_runs_per_row, 3), dtype=np.int32)
            self._counts = np.zeros(h, dtype=np.int64)
        image = np.ascontiguousarray(image)
        yuv, threads = self.space == "yuv", self.params.threads
        if threads > 1 and h * image.shape[1] >= self.params.threads_min_pixels:
            if self._pool is None:
                self._pool = ThreadPoolExecutor(threads - 1, thread_name_prefix="cmvision")
            bands = np.linspace(0, h, threads + 1).astype(int).tolist()
            args = (image, yuv, self.lut, self._screen, self._no_bits, self._runs, self._counts, self._gains,
                    self._row_cell)
            done = [self._pool.submit(kern.classify, *args, a, b) for a, b in zip(bands[1:-1], bands[2:], strict=True)]
            # the first band in this thread
            kern.classify(*args, 0, bands[1])
            for job in done:
                job.result()
        else:
            kern.classify(image, yuv, self.lut, self._screen, self._no_bits, self._runs, self._counts, self._gains,
                          self._row_cell, 0, h)
        return self._runs, self._counts

    def regions(self, image: NDArray[np.uint8], merge: bool = True) -> Regions:
        """The colour regions of ``image`` (H, W, 3) BGR uint8."""
        runs, counts = self.runs(image)
        flat, label, n = kern.connect_runs(runs, counts, self.params.connectivity == 8)
        stats = kern.region_stats(flat, label, int(n[0]))
        if self.split is not None:
            stats = self._split(stats, flat, label, self.split)
        if merge and self.params.merge_gap_px > 0.0 and stats.shape[0] > 1:
            alive = kern.merge_regions(stats, self.params.merge_gap_px, self.params.merge_min_density)
            stats = stats[alive]
        return _finish(stats, self.min_area)


    @staticmethod
    def _split(stats: NDArray[np.float64], flat: NDArray[np.int32], label: NDArray[np.int64],
               rule: SplitRule) -> NDArray[np.float64]:
        """``stats`` (one row per label) with each region too large for its class replaced by its
        round parts (:func:`split_region`)."""
        big = np.flatnonzero(stats[:, kern.R_AREA] > rule.max_area_px[stats[:, kern.R_CLASS].astype(np.int64)])
        if big.size == 0:
            return stats
        parts = [split_region(flat[label == k], rule) for k in big]
        return np.concatenate([np.delete(stats, big, axis=0), *parts], axis=0)


def regions_reference(labels: NDArray[np.int64], cls_of_pixel: NDArray[np.int64]) -> NDArray[np.float64]:
    """Region statistics (the kernels' table layout) from a label image by plain numpy: labels
    0..n-1 per pixel, -1 for no region; ``cls_of_pixel`` the class per pixel."""
    n = int(labels.max()) + 1 if labels.size else 0
    out = np.zeros((n, kern.R_COLS))
    v, u = np.nonzero(labels >= 0)
    lab = labels[v, u]
    uf, vf = u.astype(np.float64), v.astype(np.float64)
    out[:, kern.R_AREA] = np.bincount(lab, minlength=n)
    out[:, kern.R_SUM_U] = np.bincount(lab, uf, minlength=n)
    out[:, kern.R_SUM_V] = np.bincount(lab, vf, minlength=n)
    out[:, kern.R_SUM_UU] = np.bincount(lab, uf * uf, minlength=n)
    out[:, kern.R_SUM_VV] = np.bincount(lab, vf * vf, minlength=n)
    out[:, kern.R_SUM_UV] = np.bincount(lab, uf * vf, minlength=n)
    out[:, kern.R_U0] = np.inf
    out[:, kern.R_V0] = np.inf
    out[:, kern.R_U1] = -np.inf
    out[:, kern.R_V1] = -np.inf
    np.minimum.at(out[:, kern.R_U0], lab, uf)
    np.minimum.at(out[:, kern.R_V0], lab, vf)
    np.maximum.at(out[:, kern.R_U1], lab, uf)
    np.maximum.at(out[:, kern.R_V1], lab, vf)
    out[lab, kern.R_CLASS] = cls_of_pixel[v, u]
    return out


def runs_reference(bits: NDArray[np.uint32]) -> list[list[tuple[int, int, int]]]:
    """Per row, the runs (u_start, u_end inclusive, class) of a class bit-set image, each pixel
    taking its lowest class: the plain-numpy reference of the fused kernel."""
    low = np.full(bits.shape, -1, dtype=np.int64)
    for k in range(MAX_CLASSES - 1, -1, -1):
        low[(bits >> np.uint32(k)) & np.uint32(1) == 1] = k
    out: list[list[tuple[int, int, int]]] = []
    for row in low:
        edges = np.flatnonzero(np.diff(np.concatenate([[-1], row, [-1]])) != 0)
        out.append([(int(a), int(b) - 1, int(row[a])) for a, b in zip(edges[:-1], edges[1:], strict=True)
                    if row[a] >= 0])
    return out


def merge_reference(stats: NDArray[np.float64], max_gap_px: float, min_density: float) -> NDArray[np.float64]:
    """Density-based merging by plain numpy, the reference of :func:`vision._kernels.merge_regions`:
    returns the surviving rows, merged."""
    st = stats.copy()
    alive = np.ones(len(st), dtype=bool)
    order = np.argsort(-st[:, kern.R_AREA], kind="mergesort")
    for rank, i in enumerate(order):
        if not alive[i]:
            continue
        for j in order[rank + 1 :]:
            if not alive[j] or st[j, kern.R_CLASS] != st[i, kern.R_CLASS]:
                continue
            a, b = (
                st[i, [kern.R_U0, kern.R_V0, kern.R_U1, kern.R_V1]],
                st[j, [kern.R_U0, kern.R_V0, kern.R_U1, kern.R_V1]],
            )
            gap = np.maximum(b[:2] - a[2:], a[:2] - b[2:]) - 1.0
            lo, hi = np.minimum(a[:2], b[:2]), np.maximum(a[2:], b[2:])
            if np.any(gap > max_gap_px) or st[i, kern.R_AREA] + st[j, kern.R_AREA] < min_density * np.prod(hi - lo + 1):
                continue
            st[i, kern.R_AREA : kern.R_SUM_UV + 1] += st[j, kern.R_AREA : kern.R_SUM_UV + 1]
            st[i, [kern.R_U0, kern.R_V0]], st[i, [kern.R_U1, kern.R_V1]] = lo, hi
            alive[j] = False
    return st[alive]
