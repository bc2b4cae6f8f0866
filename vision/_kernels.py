"""numba kernels of CMVision (Bruce's thesis, appendix A.1): classify, run-length encode,
connect runs into regions, region statistics and density-based merging.

Every kernel has a plain-numpy reference in :mod:`vision.cmvision` and a test that both agree.
Pixel coordinates are (u, v) = (column, row) of the pixel's top-left corner; centroids are
reported at pixel centres (+0.5) by the wrappers, not here.

First-run compile: arrays are made by ``np.empty`` and filled in loops, and sorting and the median
are the floor's (:func:`cmdragons.sorting.argsort_stable`, :func:`cmdragons.sorting.median`),
because numba compiles each use of
``np.zeros``, ``np.ones``, ``np.full``, ``np.arange``, ``np.argsort`` and ``np.median`` (per
signature) anew, a tenth of a second to seconds each, for no run-time gain.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from cmdragons.sorting import argsort_stable, median

# region table columns (float64), filled by `region_stats` and `merge_regions`
R_CLASS, R_AREA, R_SUM_U, R_SUM_V, R_SUM_UU, R_SUM_VV, R_SUM_UV, R_U0, R_V0, R_U1, R_V1 = range(11)
R_COLS = 11


@numba.njit(cache=True, inline="always")
def _yuv_row(src: np.ndarray, c0: np.ndarray, c1: np.ndarray, c2: np.ndarray) -> None:
    """Y, U, V of one row of interleaved (b, g, r) bytes: the fixed-point (x 256) full-range YCbCr of
    ``vision.cmvision._CONVERSIONS["yuv"]``, its coefficients written in as constants (LLVM turns the
    x 128 into shifts and needs no table of coefficients: a third less time than the same map read
    from an array). Every step is cast back to int32 so that LLVM keeps 32-bit lanes (numba widens
    integer arithmetic to int64, which halves the lanes). No clamp below: Y lies in 0..255 (the
    coefficients are positive and sum to 256), U and V in 1..256 (one positive coefficient of 128),
    so only U and V are clamped at 255."""
    r128, hi, eight = np.int32(128), np.int32(255), np.int32(8)
    for j in range(c0.shape[0]):
        b, g, r = np.int32(src[3 * j]), np.int32(src[3 * j + 1]), np.int32(src[3 * j + 2])
        y = np.int32(np.int32(29) * b) + np.int32(np.int32(150) * g) + np.int32(np.int32(77) * r)
        u = np.int32(b << np.int32(7)) - np.int32(np.int32(85) * g) - np.int32(np.int32(43) * r)
        v = np.int32(r << np.int32(7)) - np.int32(np.int32(107) * g) - np.int32(np.int32(21) * b)
        c0[j] = np.uint8(np.int32(np.int32(y + r128) >> eight))
        c1[j] = np.uint8(min(np.int32(np.int32(np.int32(u + r128) >> eight) + r128), hi))
        c2[j] = np.uint8(min(np.int32(np.int32(np.int32(v + r128) >> eight) + r128), hi))


@numba.njit(cache=True, inline="always")
def _bgr_row(src: np.ndarray, c0: np.ndarray, c1: np.ndarray, c2: np.ndarray) -> None:
    """The channels of one row of interleaved (b, g, r) bytes, unchanged (the "bgr" space)."""
    for j in range(c0.shape[0]):
        c0[j], c1[j], c2[j] = src[3 * j], src[3 * j + 1], src[3 * j + 2]


@numba.njit(cache=True)
def channels(image: np.ndarray, yuv: bool) -> np.ndarray:
    """The image (H, W, 3) BGR uint8 in YUV (``yuv``) or BGR, as ``classify`` computes it: the
    kernel side of :func:`vision.cmvision.convert_colour` (for the tests)."""
    h, w = image.shape[0], image.shape[1]
    flat = image.reshape(h, w * 3)
    out = np.empty((h, w, 3), np.uint8)
    c0, c1, c2 = np.empty(w, np.uint8), np.empty(w, np.uint8), np.empty(w, np.uint8)
    for i in range(h):
        if yuv:
            _yuv_row(flat[i], c0, c1, c2)
        else:
            _bgr_row(flat[i], c0, c1, c2)
        for j in range(w):
            out[i, j, 0], out[i, j, 1], out[i, j, 2] = c0[j], c1[j], c2[j]
    return out


@numba.njit(cache=True, inline="always")
def _screen_row(c0: np.ndarray, c1: np.ndarray, c2: np.ndarray, screen: np.ndarray, hit: np.ndarray) -> bool:
    """``hit[j] = 1`` where the three channels of pixel ``j`` lie in the box of one class: rows of
    ``screen`` are ``(lo0, width0, lo1, width1, lo2, width2)`` per class, a range
    ``[lo, lo + width]``. One vectorised pass per class, each range test one unsigned compare.
    Returns whether the row has any hit."""
    w = c1.shape[0]
    hit[:w] = 0
    for k in range(screen.shape[0]):
        lo0, w0, lo1, w1, lo2, w2 = screen[k, 0], screen[k, 1], screen[k, 2], screen[k, 3], screen[k, 4], screen[k, 5]
        for j in range(w):
            hit[j] |= (np.uint8(np.uint8(c0[j] - lo0) <= w0) & np.uint8(np.uint8(c1[j] - lo1) <= w1)
                       & np.uint8(np.uint8(c2[j] - lo2) <= w2))
    words = hit.view(np.uint64)
    acc = np.uint64(0)
    for q in range(words.shape[0]):
        acc |= words[q]
    return bool(acc != 0)


@numba.njit(cache=True, inline="always")
def _lowest_bit(m: np.uint32) -> int:
    k = 0
    while (m & np.uint32(1)) == 0:
        m >>= np.uint32(1)
        k += 1
    return k


@numba.njit(cache=True, inline="always")
def _put_run(runs: np.ndarray, n: int, start: int, end: int, cls: int) -> int:
    # a row with more runs than ``runs`` holds keeps its first ones
    if n < runs.shape[0]:
        runs[n, 0] = start
        runs[n, 1] = end
        runs[n, 2] = cls
        n += 1
    return n


@numba.njit(cache=True, inline="always")
def _classify_row(lut: np.ndarray, c0: np.ndarray, c1: np.ndarray, c2: np.ndarray, hit: np.ndarray,
                  out: np.ndarray, runs: np.ndarray) -> int:
    """Finish one screened row: at each hit, the full class bit set (all three tables); writes it
    to ``out`` (non-zero entries only) and runs of one class to ``runs``, a pixel taking its lowest
    class (config order is priority). Blocks of 8 pixels without a hit are skipped whole, so the
    encoding touches only screened pixels and the ends of runs. Returns the number of runs."""
    w = c1.shape[0]
    words = hit.view(np.uint64)
    n = 0
    cur = -1
    start = 0
    j = 0
    while j < w:
        if (j & 7) == 0 and words[j >> 3] == 0:
            if cur >= 0:
                n = _put_run(runs, n, start, j - 1, cur)
                cur = -1
            j += 8
            continue
        m = np.uint32(0)
        if hit[j]:
            m = lut[0, c0[j]] & lut[1, c1[j]] & lut[2, c2[j]]
            out[j] = m
        cls = -1 if m == 0 else _lowest_bit(m)
        if cls != cur:
            if cur >= 0:
                n = _put_run(runs, n, start, j - 1, cur)
            cur = cls
            start = j
        j += 1
    if cur >= 0:
        n = _put_run(runs, n, start, w - 1, cur)
    return n


@numba.njit(cache=True, nogil=True)
def classify(image: np.ndarray, yuv: bool, lut: np.ndarray, screen: np.ndarray, bits: np.ndarray,
             runs: np.ndarray, counts: np.ndarray, gains: np.ndarray, row_cell: np.ndarray, row0: int,
             row1: int) -> None:
    """Classification (thesis A.1.3) and run-length encoding in one pass over rows [row0, row1) of
    the image.

    A pixel's bit set is ``lut[0, c0] & lut[1, c1] & lut[2, c2]``: the classes whose threshold box
    holds it, in YUV (``yuv``) or BGR. All three channels are computed for every pixel (vectorised
    rows) and screened against ``screen`` (k, 6) uint8, each class's box (``vision.cmvision._screen_boxes``): a pixel
    passes when one class holds it, so the screen is exact and the table look-ups and the
    run-length encoding touch only the few pixels of some class; a row without one is done after
    the screen. (One or two channels screened the carpet out while the boxes were tuned on
    lossless frames; boxes that reach toward grey for compressed video hold the carpet's U in the
    green id dots' range, its Y and U in the ball's, its Y and V in the blue centre dots'.)

    The bit sets are written to ``bits`` (H, W) when it has H rows (else ``bits`` is unused). When
    ``runs`` has H rows, ``runs[row, k] = (u_start, u_end inclusive, class)`` and ``counts[row]``
    runs: pixels of no class make no runs; a row with more runs than ``runs.shape[1]`` keeps the
    first.

    The light per cell of a grid over the image: when ``gains`` (R, W * 3) int32 has rows, each
    byte of row ``i`` is first scaled by ``gains[row_cell[i]]`` (x 256, rounded, saturated at 255),
    the row of cells holding it (:meth:`vision.cmvision.Segmenter.set_light`); no rows: the image as it is.

    Serial, without the GIL: the caller may run bands of rows on threads at once (rows are
    independent; :class:`vision.cmvision.Segmenter` does for large images). numba's own parallel
    loop costs seconds more to compile and, on a 2-core machine shared with other jobs, ran no
    faster (1920x1200, load average 2 to 3: 2.2 ms median either way).
    """
    h, w = image.shape[0], image.shape[1]
    flat = image.reshape(h, w * 3)
    keep_bits, encode = bits.shape[0] == h, runs.shape[0] == h
    c0 = np.empty(w, np.uint8)
    c1 = np.empty(w, np.uint8)
    c2 = np.empty(w, np.uint8)
    hit = np.empty((w + 7) // 8 * 8, np.uint8)  # whole 8-pixel words; the tail stays 0
    for j in range(hit.shape[0]):
        hit[j] = 0
    row = np.empty(w, np.uint32)
    no_runs = np.empty((0, 3), np.int32)
    lit = gains.shape[0] > 0
    scaled = np.empty(w * 3, np.uint8)
    half, top, eight = np.int32(128), np.int32(255), np.int32(8)
    for i in range(row0, row1):
        out = bits[i] if keep_bits else row
        if keep_bits:
            out[:] = 0
        src = flat[i]
        if lit:
            g = gains[row_cell[i]]
            for q in range(w * 3):
                scaled[q] = np.uint8(min(np.int32(np.int32(np.int32(src[q]) * g[q] + half) >> eight), top))
            src = scaled
        if yuv:
            _yuv_row(src, c0, c1, c2)
        else:
            _bgr_row(src, c0, c1, c2)
        n = 0
        if _screen_row(c0, c1, c2, screen, hit):
            n = _classify_row(lut, c0, c1, c2, hit, out, runs[i] if encode else no_runs)
        if encode:
            counts[i] = n


@numba.njit(cache=True)
def _find(parent: np.ndarray, a: int) -> int:
    root = a
    while parent[root] != root:
        root = parent[root]
    while parent[a] != root:  # path compression
        nxt = parent[a]
        parent[a] = root
        a = nxt
    return root


@numba.njit(cache=True)
def connect_runs(runs: np.ndarray, counts: np.ndarray, eight: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flatten the per-row runs and join runs of one class that touch across neighbouring rows
    (4- or 8-connectivity) by union-find (thesis A.1.4).

    Returns ``flat`` (n, 4): row, u_start, u_end, class; ``label`` (n,): region index of each run,
    regions numbered in order of their first run (raster order); ``n_regions`` as a 1-array.
    """
    h = counts.shape[0]
    offsets = np.empty(h + 1, np.int64)
    offsets[0] = 0
    for i in range(h):
        offsets[i + 1] = offsets[i] + counts[i]
    n = offsets[h]
    flat = np.empty((n, 4), dtype=np.int32)
    for i in range(h):
        for k in range(counts[i]):
            idx = offsets[i] + k
            flat[idx, 0] = i
            flat[idx, 1] = runs[i, k, 0]
            flat[idx, 2] = runs[i, k, 1]
            flat[idx, 3] = runs[i, k, 2]
    parent = np.empty(n, np.int64)
    for p in range(n):
        parent[p] = p
    slack = 1 if eight else 0
    for i in range(1, h):
        q = offsets[i - 1]
        q_end = offsets[i]
        for p in range(offsets[i], offsets[i + 1]):
            ps, pe = flat[p, 1], flat[p, 2]
            # runs of the row above that end before this one starts can touch no later run
            while q < q_end and flat[q, 2] < ps - slack:
                q += 1
            qq = q
            while qq < q_end and flat[qq, 1] <= pe + slack:
                if flat[qq, 3] == flat[p, 3]:
                    ra, rb = _find(parent, p), _find(parent, qq)
                    if ra != rb:
                        if ra < rb:
                            parent[rb] = ra
                        else:
                            parent[ra] = rb
                qq += 1
    label = np.empty(n, np.int64)
    region_of_root = np.empty(n, np.int64)
    for p in range(n):
        region_of_root[p] = -1
    count = 0
    for p in range(n):
        root = _find(parent, p)
        if region_of_root[root] < 0:
            region_of_root[root] = count
            count += 1
        label[p] = region_of_root[root]
    n_regions = np.empty(1, np.int64)
    n_regions[0] = count
    return flat, label, n_regions


@numba.njit(cache=True)
def region_stats(flat: np.ndarray, label: np.ndarray, n_regions: int) -> np.ndarray:
    """Per region: class, area, sums of u, v, u^2, v^2, uv and the bounding box (thesis A.1.5),
    from the runs in closed form (sums of integer ranges), u and v at pixel corners."""
    out = np.empty((n_regions, R_COLS), np.float64)
    for k in range(n_regions):
        for c in range(R_COLS):
            out[k, c] = 0.0
        out[k, R_U0] = 1e18
        out[k, R_V0] = 1e18
        out[k, R_U1] = -1.0
        out[k, R_V1] = -1.0
    for p in range(flat.shape[0]):
        k = label[p]
        v = float(flat[p, 0])
        s = float(flat[p, 1])
        e = float(flat[p, 2])
        n = e - s + 1.0
        su = n * (s + e) / 2.0
        suu = (e * (e + 1.0) * (2.0 * e + 1.0) - (s - 1.0) * s * (2.0 * s - 1.0)) / 6.0
        out[k, R_CLASS] = flat[p, 3]
        out[k, R_AREA] += n
        out[k, R_SUM_U] += su
        out[k, R_SUM_V] += n * v
        out[k, R_SUM_UU] += suu
        out[k, R_SUM_VV] += n * v * v
        out[k, R_SUM_UV] += su * v
        out[k, R_U0] = min(out[k, R_U0], s)
        out[k, R_U1] = max(out[k, R_U1], e)
        out[k, R_V0] = min(out[k, R_V0], v)
        out[k, R_V1] = max(out[k, R_V1], v)
    return out


@numba.njit(cache=True)
def disc_fits(flat: np.ndarray, half_widths: np.ndarray) -> bool:
    """Whether a structuring element fits inside one region anywhere (the region's erosion by the
    element is not empty, so neither is its opening): ``flat`` (n, 4) the region's runs (row,
    u_start, u_end inclusive, class); ``half_widths`` (2r + 1,) the element's rows, row ``k``
    covering columns ``-half_widths[k] .. half_widths[k]`` around the centre at row offset
    ``k - r`` (-1: an empty row). Lets :func:`vision.cmvision.split_region` pass by the regions no
    dot fits in (thin lines) without building their masks; its reference is ``cv2.erode``."""
    r = (half_widths.shape[0] - 1) // 2
    widest, k0, k1 = -1, half_widths.shape[0], -1  # the element's widest row, its first and last rows
    for k in range(half_widths.shape[0]):
        if half_widths[k] >= 0:
            widest, k0, k1 = max(widest, half_widths[k]), min(k0, k), k
    if widest < 0:
        return True  # an empty element fits everywhere
    v0, v1, u0, u1 = flat[0, 0], flat[0, 0], flat[0, 1], flat[0, 2]
    longest = 0
    for p in range(flat.shape[0]):
        v0, v1 = min(v0, flat[p, 0]), max(v1, flat[p, 0])
        u0, u1 = min(u0, flat[p, 1]), max(u1, flat[p, 2])
        longest = max(longest, flat[p, 2] - flat[p, 1] + 1)
    if longest < 2 * widest + 1 or v1 - v0 < k1 - k0:
        return False  # no run holds the element's widest row, or too few rows for its height
    hh, ww = v1 - v0 + 1, u1 - u0 + 1
    # per pixel, the length of the region's run through it up to it from the left and from the right
    left = np.empty((hh, ww), np.int32)
    right = np.empty((hh, ww), np.int32)
    for i in range(hh):
        for j in range(ww):
            left[i, j] = 0
            right[i, j] = 0
    for p in range(flat.shape[0]):
        i, a, b = flat[p, 0] - v0, flat[p, 1] - u0, flat[p, 2] - u0
        for j in range(a, b + 1):
            left[i, j] = j - a + 1
            right[i, j] = b - j + 1
    # centres whose element rows all lie within the box
    for i in range(r - k0, hh + r - k1):
        for j in range(ww):
            fits = True
            for k in range(k0, k1 + 1):
                hw = half_widths[k]
                if hw >= 0 and (left[i + k - r, j] <= hw or right[i + k - r, j] <= hw):
                    fits = False
                    break
            if fits:
                return True
    return False


# side of the grid cells (px) that `merge_regions` files the regions' bounding boxes in
MERGE_CELL_PX = 16


@numba.njit(cache=True)
def _box_cells(lo: float, hi: float, n_cells: int) -> tuple[int, int]:
    """The range of grid cells (inclusive, clipped to the grid) that ``[lo, hi]`` (px) overlaps."""
    c0 = int(math.floor(lo / MERGE_CELL_PX)) if lo > 0.0 else 0
    c1 = int(math.floor(hi / MERGE_CELL_PX)) if hi > 0.0 else 0
    return min(c0, n_cells - 1), min(c1, n_cells - 1)


@numba.njit(cache=True)
def _file_boxes(stats: np.ndarray, nu: int, nv: int, slots: np.ndarray, items: np.ndarray) -> None:
    """Each region's index into every grid cell its bounding box overlaps (cells row by row, ``nu``
    per row): with no ``items``, count them per cell into ``slots``; else write them to
    ``items[slots[cell]]``, advancing ``slots`` (each cell's first position)."""
    for k in range(stats.shape[0]):
        cu0, cu1 = _box_cells(stats[k, R_U0], stats[k, R_U1], nu)
        cv0, cv1 = _box_cells(stats[k, R_V0], stats[k, R_V1], nv)
        for cv in range(cv0, cv1 + 1):
            for cu in range(cu0, cu1 + 1):
                c = cv * nu + cu
                if items.shape[0] > 0:
                    items[slots[c]] = k
                slots[c] += 1


@numba.njit(cache=True)
def _next_merge_candidate(stats: np.ndarray, i: int, after: int, rank: np.ndarray, alive: np.ndarray,
                          cell_start: np.ndarray, cell_items: np.ndarray, nu: int, nv: int,
                          max_gap_px: float) -> int:
    """The smallest rank above ``after`` of a live region of region ``i``'s class whose bounding box
    is at most ``max_gap_px`` from ``i``'s (per axis), or -1: looked up in the grid cells that the
    box of ``i`` grown by the gap overlaps (a region within the gap overlaps that grown box)."""
    reach = max_gap_px + 1.0
    cu0, cu1 = _box_cells(stats[i, R_U0] - reach, stats[i, R_U1] + reach, nu)
    cv0, cv1 = _box_cells(stats[i, R_V0] - reach, stats[i, R_V1] + reach, nv)
    best = -1
    for cv in range(cv0, cv1 + 1):
        for cu in range(cu0, cu1 + 1):
            c = cv * nu + cu
            for q in range(cell_start[c], cell_start[c + 1]):
                j = cell_items[q]
                r = rank[j]
                if r <= after or (best >= 0 and r >= best) or not alive[j] or stats[j, R_CLASS] != stats[i, R_CLASS]:
                    continue
                gap_u = max(stats[j, R_U0] - stats[i, R_U1], stats[i, R_U0] - stats[j, R_U1]) - 1.0
                gap_v = max(stats[j, R_V0] - stats[i, R_V1], stats[i, R_V0] - stats[j, R_V1]) - 1.0
                if gap_u <= max_gap_px and gap_v <= max_gap_px:
                    best = r
    return best


@numba.njit(cache=True)
def merge_regions(stats: np.ndarray, max_gap_px: float, min_density: float) -> np.ndarray:
    """Density-based merging (thesis A.1.6): two regions of one class whose bounding boxes are at
    most ``max_gap_px`` apart are joined when the joined region still fills at least
    ``min_density`` of its bounding box. Larger regions absorb smaller ones, in one greedy pass:
    in order of decreasing area (equal areas in table order), each live region tries every later
    live region in that order, its box growing with each one it absorbs.

    The regions' boxes are filed in a grid of ``MERGE_CELL_PX`` cells, so that each region looks
    only at the few regions near its box instead of all later ones (a frame's hundreds of
    one-pixel regions along line edges made that pass quadratic); the result is the same pass.

    Merges ``stats`` in place and returns a mask of the regions that survive.
    """
    n = stats.shape[0]
    alive = np.empty(n, np.bool_)
    for k in range(n):
        alive[k] = True
    if n < 2:
        return alive
    order = argsort_stable(-stats[:, R_AREA])
    rank = np.empty(n, np.int64)
    for a in range(n):
        rank[order[a]] = a
    u_max, v_max = 0.0, 0.0
    for k in range(n):
        u_max, v_max = max(u_max, stats[k, R_U1]), max(v_max, stats[k, R_V1])
    nu, nv = int(u_max) // MERGE_CELL_PX + 1, int(v_max) // MERGE_CELL_PX + 1
    counts = np.empty(nu * nv, np.int64)
    for c in range(nu * nv):
        counts[c] = 0
    _file_boxes(stats, nu, nv, counts, np.empty(0, np.int64))
    cell_start = np.empty(nu * nv + 1, np.int64)
    cell_start[0] = 0
    for c in range(nu * nv):
        cell_start[c + 1] = cell_start[c] + counts[c]
    cell_items = np.empty(cell_start[nu * nv], np.int64)
    _file_boxes(stats, nu, nv, cell_start[:-1].copy(), cell_items)
    for a in range(n):
        i = order[a]
        if not alive[i]:
            continue
        b = _next_merge_candidate(stats, i, a, rank, alive, cell_start, cell_items, nu, nv, max_gap_px)
        while b >= 0:
            j = order[b]
            u0 = min(stats[i, R_U0], stats[j, R_U0])
            u1 = max(stats[i, R_U1], stats[j, R_U1])
            v0 = min(stats[i, R_V0], stats[j, R_V0])
            v1 = max(stats[i, R_V1], stats[j, R_V1])
            box = (u1 - u0 + 1.0) * (v1 - v0 + 1.0)
            if (stats[i, R_AREA] + stats[j, R_AREA]) >= min_density * box:
                for c in range(R_AREA, R_SUM_UV + 1):
                    stats[i, c] += stats[j, c]
                stats[i, R_U0], stats[i, R_U1], stats[i, R_V0], stats[i, R_V1] = u0, u1, v0, v1
                alive[j] = False
            b = _next_merge_candidate(stats, i, b, rank, alive, cell_start, cell_items, nu, nv, max_gap_px)
    return alive


@numba.njit(cache=True)
def region_rays(grid: np.ndarray, pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ray (dx, dy) per metre of descent at each pixel position (n, 2), bilinear in the camera's
    per-pixel ray grid (H, W, 2) sampled at pixel centres; and the area (m^2 per px, per metre of
    descent squared) that one pixel covers there, from the grid's local Jacobian."""
    h, w = grid.shape[0], grid.shape[1]
    n = pixels.shape[0]
    rays = np.empty((n, 2))
    area = np.empty(n)
    for k in range(n):
        fu = min(max(pixels[k, 0] - 0.5, 0.0), w - 1.000001)
        fv = min(max(pixels[k, 1] - 0.5, 0.0), h - 1.000001)
        j, i = int(fu), int(fv)
        a, b = fu - j, fv - i
        for c in range(2):
            top = (1.0 - a) * grid[i, j, c] + a * grid[i, j + 1, c]
            bottom = (1.0 - a) * grid[i + 1, j, c] + a * grid[i + 1, j + 1, c]
            rays[k, c] = (1.0 - b) * top + b * bottom
        # derivatives along u and v over this grid cell
        du0 = (1.0 - b) * (grid[i, j + 1, 0] - grid[i, j, 0]) + b * (grid[i + 1, j + 1, 0] - grid[i + 1, j, 0])
        du1 = (1.0 - b) * (grid[i, j + 1, 1] - grid[i, j, 1]) + b * (grid[i + 1, j + 1, 1] - grid[i + 1, j, 1])
        dv0 = (1.0 - a) * (grid[i + 1, j, 0] - grid[i, j, 0]) + a * (grid[i + 1, j + 1, 0] - grid[i, j + 1, 0])
        dv1 = (1.0 - a) * (grid[i + 1, j, 1] - grid[i, j, 1]) + a * (grid[i + 1, j + 1, 1] - grid[i, j + 1, 1])
        area[k] = abs(du0 * dv1 - du1 * dv0)
    return rays, area


@numba.njit(cache=True)
def ball_centre(image: np.ndarray, box: np.ndarray, margin: int) -> tuple[float, float, float, float]:
    """The ball's sub-pixel centre (u, v at pixel centres) in ``image`` (H, W, 3) uint8 around its
    region's bounding box ``box`` (u0, v0, u1, v1 inclusive): the centroid of each pixel's ball
    coverage over the box grown by ``margin`` px. An edge pixel's colour is a linear mix
    ``p * ball + q * background`` (coverage 1 - q; p also carries the shade and light, so the
    ball's colour is only a direction), unmixed by least squares with the background the median of
    the one-pixel ring around the window and the ball's colour the mean of the box shrunk by one
    pixel; coverage is clipped to 0..1. Also returns the coverage's sum (px: the ball's visible
    area) and the centre's standard deviation per axis (px) from false coverage: the ring's pixels
    are background, so their coverage (its positive part, what the clipping keeps) is what each
    window pixel may carry wrongly, spread over the window as the centroid's lever arms weigh it
    (sqrt(sum of squared distances to the centre per axis) / coverage sum). NaN when the two
    colours cannot be told apart. The reference is :func:`vision.patterns.ball_centre_reference`."""
    h, w = image.shape[0], image.shape[1]
    u0, v0, u1, v1 = int(box[0]), int(box[1]), int(box[2]), int(box[3])
    wu0, wv0, wu1, wv1 = max(u0 - margin, 0), max(v0 - margin, 0), min(u1 + margin, w - 1), min(v1 + margin, h - 1)
    ru0, rv0, ru1, rv1 = max(wu0 - 1, 0), max(wv0 - 1, 0), min(wu1 + 1, w - 1), min(wv1 + 1, h - 1)
    ring = np.empty((3, (ru1 - ru0 + 1) * (rv1 - rv0 + 1)))
    n = 0
    for i in range(rv0, rv1 + 1):
        for j in range(ru0, ru1 + 1):
            if wv0 <= i <= wv1 and wu0 <= j <= wu1:
                continue
            for c in range(3):
                ring[c, n] = image[i, j, c]
            n += 1
    if n == 0:
        return np.nan, np.nan, np.nan, np.nan
    bg = np.empty(3)
    for c in range(3):
        bg[c] = median(ring[c, :n])
    iu0, iv0, iu1, iv1 = u0 + 1, v0 + 1, u1 - 1, v1 - 1
    if iu0 > iu1 or iv0 > iv1:
        iu0, iv0, iu1, iv1 = u0, v0, u1, v1
    ball = np.empty(3)
    for c in range(3):
        ball[c] = 0.0
    for i in range(iv0, iv1 + 1):
        for j in range(iu0, iu1 + 1):
            for c in range(3):
                ball[c] += image[i, j, c]
    bb = ball[0] * ball[0] + ball[1] * ball[1] + ball[2] * ball[2]
    if bb <= 0.0:
        return np.nan, np.nan, np.nan, np.nan
    k = (bg[0] * ball[0] + bg[1] * ball[1] + bg[2] * ball[2]) / bb
    g0, g1, g2 = bg[0] - k * ball[0], bg[1] - k * ball[1], bg[2] - k * ball[2]  # background, off the ball's colour
    den = bg[0] * g0 + bg[1] * g1 + bg[2] * g2
    if den < 1.0:
        return np.nan, np.nan, np.nan, np.nan
    sw, su, sv = 0.0, 0.0, 0.0
    nw, pu, pv, puu, pvv = 0.0, 0.0, 0.0, 0.0, 0.0  # the window's pixel positions: count, sums, sums of squares
    for i in range(wv0, wv1 + 1):
        for j in range(wu0, wu1 + 1):
            q = (image[i, j, 0] * g0 + image[i, j, 1] * g1 + image[i, j, 2] * g2) / den
            a = min(max(1.0 - q, 0.0), 1.0)
            sw += a
            su += a * j
            sv += a * i
            nw += 1.0
            pu += j
            pv += i
            puu += j * j
            pvv += i * i
    if sw <= 0.0:
        return np.nan, np.nan, np.nan, np.nan
    cu, cv = su / sw, sv / sw
    false2 = 0.0
    for m in range(n):
        a = max(1.0 - (ring[0, m] * g0 + ring[1, m] * g1 + ring[2, m] * g2) / den, 0.0)
        false2 += a * a
    lever2 = 0.5 * (puu - 2.0 * cu * pu + nw * cu * cu + pvv - 2.0 * cv * pv + nw * cv * cv)
    return cu + 0.5, cv + 0.5, sw, math.sqrt(false2 / n * max(lever2, 0.0)) / sw


@numba.njit(cache=True, inline="always")
def _procrustes_sums(centre: np.ndarray, w_centre: float, obs: np.ndarray, w_obs: np.ndarray,
                     slots: np.ndarray) -> tuple[float, float, float, float, float, float, float, float]:
    """The weighted 2D Procrustes sums of a pattern whose centre dot sits at the template origin
    and whose k id dots sit at ``slots`` (k, 2), against the observed centre and dots ``obs``
    (k, 2): total weight, the observations' and the template's weighted means, the cross and dot
    sums of the centred pairs (the best rotation is their angle) and the template's weighted
    spread about its mean."""
    k = obs.shape[0]
    wsum = w_centre
    mox, moy = w_centre * centre[0], w_centre * centre[1]
    mtx, mty = 0.0, 0.0
    for i in range(k):
        wsum += w_obs[i]
        mox += w_obs[i] * obs[i, 0]
        moy += w_obs[i] * obs[i, 1]
        mtx += w_obs[i] * slots[i, 0]
        mty += w_obs[i] * slots[i, 1]
    mox, moy, mtx, mty = mox / wsum, moy / wsum, mtx / wsum, mty / wsum
    # the centre dot: template (0, 0) against the observed centre
    cross = w_centre * ((-mtx) * (centre[1] - moy) - (-mty) * (centre[0] - mox))
    dot = w_centre * ((-mtx) * (centre[0] - mox) + (-mty) * (centre[1] - moy))
    spread = w_centre * (mtx * mtx + mty * mty)
    for i in range(k):
        tx, ty = slots[i, 0] - mtx, slots[i, 1] - mty
        ox, oy = obs[i, 0] - mox, obs[i, 1] - moy
        cross += w_obs[i] * (tx * oy - ty * ox)
        dot += w_obs[i] * (tx * ox + ty * oy)
        spread += w_obs[i] * (tx * tx + ty * ty)
    return wsum, mox, moy, mtx, mty, cross, dot, spread


@numba.njit(cache=True)
def fit_pattern(centre: np.ndarray, w_centre: float, obs: np.ndarray, w_obs: np.ndarray,
                slots: np.ndarray) -> tuple[float, float, float, float]:
    """Weighted least-squares rigid fit (2D Procrustes) of a pattern whose centre dot sits at the
    template origin and whose k id dots sit at ``slots`` (k, 2), to the observed centre and dots
    ``obs`` (k, 2). Returns heading, x, y and the weighted RMS residual (m)."""
    wsum, mox, moy, mtx, mty, cross, dot, _ = _procrustes_sums(centre, w_centre, obs, w_obs, slots)
    theta = np.arctan2(cross, dot)
    c, s = np.cos(theta), np.sin(theta)
    px, py = mox - (c * mtx - s * mty), moy - (s * mtx + c * mty)
    err = w_centre * ((px - centre[0]) ** 2 + (py - centre[1]) ** 2)
    for i in range(obs.shape[0]):
        ex = c * slots[i, 0] - s * slots[i, 1] + px - obs[i, 0]
        ey = s * slots[i, 0] + c * slots[i, 1] + py - obs[i, 1]
        err += w_obs[i] * (ex * ex + ey * ey)
    return theta, px, py, np.sqrt(err / wsum)


@numba.njit(cache=True)
def fit_score(centre: np.ndarray, w_centre: float, obs: np.ndarray, w_obs: np.ndarray, slots: np.ndarray) -> float:
    """What ranks the assignments of :func:`fit_pattern`, without its trigonometry: the weighted
    squared residual of the best rotation less the observations' own spread (the same for every
    assignment of the same dots), ``sum w |t - mt|^2 - 2 |(dot, cross)|``."""
    _, _, _, _, _, cross, dot, spread = _procrustes_sums(centre, w_centre, obs, w_obs, slots)
    return spread - 2.0 * math.sqrt(cross * cross + dot * dot)


# pattern match table columns, filled by `match_patterns`
M_OK, M_X, M_Y, M_THETA, M_RES, M_PINK, M_MISSING, M_DOTS, M_AREA, M_VERDICT, M_ID, M_CONF = range(12)
M_COLS = 12
# verdicts: rejected, a robot, a robot if the missing dot's colour (read from the image by the
# caller) completes a known id
V_REJECT, V_ROBOT, V_READ_MISSING = 0, 1, 2
FULL_DOT_AREA = 0.9  # share of a dot's expected area at which its area confidence is whole


@numba.njit(cache=True, inline="always")
def _verdict(row: np.ndarray, id_of_code: np.ndarray, max_res: float, res_scale: float, min_conf: float) -> None:
    """A fitted row's verdict, robot id (``id_of_code`` at the pink bits; -1 unknown) and
    confidence: the fit residual against the pattern noise (``exp(-(res / res_scale)^2 / 2)``)
    times the share of its expected area the smallest dot shows, up to ``FULL_DOT_AREA`` (a dot's
    blurred rim falls out of its class: 90% of it counts whole), so that a dot at the smallest area
    the matcher accepts still gives a confidence in proportion; halved where a dot is missing. A
    fit above ``max_res``, an unknown code or a confidence below ``min_conf`` is rejected."""
    row[M_VERDICT], row[M_ID], row[M_CONF] = V_REJECT, -1.0, 0.0
    if row[M_RES] > max_res:
        return
    area_conf = min(1.0, max(0.0, row[M_AREA] / FULL_DOT_AREA))
    q = row[M_RES] / res_scale
    c = math.exp(-0.5 * (q * q)) * area_conf
    if row[M_MISSING] >= 0:
        c *= 0.5
    if c < min_conf:
        return
    row[M_CONF] = c
    if row[M_MISSING] >= 0:
        row[M_VERDICT] = V_READ_MISSING
        return
    row[M_ID] = id_of_code[int(row[M_PINK])]
    if row[M_ID] >= 0:
        row[M_VERDICT] = V_ROBOT


MAX_CANDIDATES = 6  # id-dot candidates per centre dot tried in every choice of four, nearest the ring first


@numba.njit(cache=True, inline="always")
def _popcount(x: int) -> int:
    n = 0
    while x:
        x &= x - 1
        n += 1
    return n


@numba.njit(cache=True)
def _best_assignment(centre: np.ndarray, w_centre: float, obs: np.ndarray, w_obs: np.ndarray, slots: np.ndarray,
                     assign: np.ndarray, t: np.ndarray) -> int:
    """The row of ``assign`` (slot per observed dot) whose fit of the k = len(obs) dots ranks best
    (:func:`fit_score`); ``t`` (k_max, 2) is scratch."""
    k = obs.shape[0]
    best_score, best = np.inf, -1
    for a in range(assign.shape[0]):
        # an assignment of k dots: its first k slots distinct (rows repeat for k < k_max)
        for i in range(k):
            t[i, 0] = slots[assign[a, i], 0]
            t[i, 1] = slots[assign[a, i], 1]
        score = fit_score(centre, w_centre, obs, w_obs, t[:k])
        if score < best_score:
            best_score, best = score, a
    return best


@numba.njit(cache=True)
def match_patterns(cxy: np.ndarray, cw: np.ndarray, dxy: np.ndarray, dw: np.ndarray, dpink: np.ndarray,
                   dgood: np.ndarray, slots: np.ndarray, assign: np.ndarray, search_r: float, min_dots: int,
                   id_of_code: np.ndarray, max_res: float, res_scale: float,
                   min_conf: float) -> np.ndarray:
    """For each centre dot (field xy (n, 2), area weight (n,)), the id dots within ``search_r``
    (at most as many as the pattern has slots, those nearest the pattern's ring), fitted to the
    template under every assignment of dots to slots (``assign`` (m, k_max): slot per observed
    dot; rows for fewer dots use the leading columns). Thesis A.2.2-A.2.3.

    Row per centre: ok, x, y, theta, residual, pink slots as bits, the slot left empty (or -1),
    dots used, the smallest area weight among the dots (1 = as expected), and the verdict, id and
    confidence of :func:`_verdict` (a centre without its dots: rejected).
    """
    n_c, k_max = cxy.shape[0], slots.shape[0]
    out = np.empty((n_c, M_COLS))
    for c in range(n_c):
        for col in range(M_COLS):
            out[c, col] = 0.0
    ring = 0.0
    for s in range(k_max):
        ring += np.sqrt(slots[s, 0] ** 2 + slots[s, 1] ** 2) / k_max
    near = np.empty(dxy.shape[0], np.int64)
    off = np.empty(dxy.shape[0])
    obs = np.empty((k_max, 2))
    w_obs = np.empty(k_max)
    t = np.empty((k_max, 2))
    for c in range(n_c):
        m = 0
        for d in range(dxy.shape[0]):
            r = np.sqrt((dxy[d, 0] - cxy[c, 0]) ** 2 + (dxy[d, 1] - cxy[c, 1]) ** 2)
            if dgood[d] and r <= search_r:
                near[m] = d
                off[m] = abs(r - ring)
                m += 1
        if m < min_dots:
            continue
        # nearest the ring first; ties keep index order, as numba's argsort does for up to 15 values
        order = argsort_stable(off[:m])
        k = min(m, k_max)
        # more candidates than slots (a light part of a real cover passing for a dot): every choice
        # of k among the MAX_CANDIDATES nearest the ring is fitted, the smallest residual kept
        n_cand = min(m, MAX_CANDIDATES)
        best_res, best, best_pick = np.inf, -1, 0
        for pick in range(1 << n_cand):
            if _popcount(pick) != k or (m <= k_max and pick != (1 << k) - 1):
                continue
            i = 0
            for j in range(n_cand):
                if (pick >> j) & 1:
                    obs[i, 0] = dxy[near[order[j]], 0]
                    obs[i, 1] = dxy[near[order[j]], 1]
                    w_obs[i] = dw[near[order[j]]]
                    i += 1
            a = _best_assignment(cxy[c], cw[c], obs[:k], w_obs[:k], slots, assign, t)
            for i in range(k):
                t[i, 0] = slots[assign[a, i], 0]
                t[i, 1] = slots[assign[a, i], 1]
            res = fit_pattern(cxy[c], cw[c], obs[:k], w_obs[:k], t[:k])[3]
            if res < best_res:
                best_res, best, best_pick = res, a, pick
        chosen = np.empty(k, np.int64)
        i = 0
        for j in range(n_cand):
            if (best_pick >> j) & 1:
                chosen[i] = order[j]
                i += 1
        min_w = cw[c]
        for i in range(k):
            obs[i, 0] = dxy[near[chosen[i]], 0]
            obs[i, 1] = dxy[near[chosen[i]], 1]
            w_obs[i] = dw[near[chosen[i]]]
            min_w = min(min_w, w_obs[i])
            t[i, 0] = slots[assign[best, i], 0]
            t[i, 1] = slots[assign[best, i], 1]
        bt, bx, by, best_res = fit_pattern(cxy[c], cw[c], obs[:k], w_obs[:k], t[:k])
        pink = 0
        used = 0
        for i in range(k):
            used |= 1 << assign[best, i]
            if dpink[near[chosen[i]]]:
                pink |= 1 << assign[best, i]
        missing = -1
        for s in range(k_max):
            if not (used >> s) & 1:
                missing = s
        out[c, M_OK] = 1.0
        out[c, M_X], out[c, M_Y], out[c, M_THETA], out[c, M_RES] = bx, by, bt, best_res
        out[c, M_PINK], out[c, M_MISSING], out[c, M_DOTS], out[c, M_AREA] = pink, missing, k, min_w
        _verdict(out[c], id_of_code, max_res, res_scale, min_conf)
    return out


@numba.njit(cache=True)
def distinct_robots(xy: np.ndarray, conf: np.ndarray, key: np.ndarray, distance: float) -> np.ndarray:
    """Indices of the detections kept, most confident first (ties in index order): one of a key
    (team and id) already kept, or closer than ``distance`` to a kept one, is the same robot seen
    twice and is dropped. (A dozen detections: picked by selection, most confident left first.)"""
    n = conf.shape[0]
    taken = np.empty(n, np.bool_)
    for k in range(n):
        taken[k] = False
    kept = np.empty(n, np.int64)
    m = 0
    for _ in range(n):
        k = -1
        for j in range(n):
            if not taken[j] and (k < 0 or conf[j] > conf[k]):
                k = j
        taken[k] = True
        same = False
        for b in range(m):
            j = kept[b]
            if key[j] == key[k] or math.hypot(xy[j, 0] - xy[k, 0], xy[j, 1] - xy[k, 1]) < distance:
                same = True
                break
        if not same:
            kept[m] = k
            m += 1
    return kept[:m]


@numba.njit(cache=True)
def ball_candidates(area: np.ndarray, moments: np.ndarray, bbox: np.ndarray, rays: np.ndarray,
                    pixel_area: np.ndarray, cam: np.ndarray, ball_radius: float, robot_xy: np.ndarray,
                    robot_z: np.ndarray, pattern_radius: float, min_area: float, max_area: float,
                    max_elongation: float, min_fill: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Which orange regions (their areas, central moments, boxes, rays and pixel areas) are ball
    candidates: an area on the ball's plane within ``min_area``..``max_area`` of the ball's, the
    moments' axes no longer than ``max_elongation`` to one, at least ``min_fill`` of the box, and
    none inside a robot's pattern (seen on the plane of that robot's top, ``robot_xy``/``robot_z``,
    within ``pattern_radius``). Returns keep, the area ratio and the elongation."""
    n = area.shape[0]
    keep = np.empty(n, np.bool_)
    ratio = np.empty(n)
    elong = np.empty(n)
    depth = cam[2] - ball_radius
    ball_area = math.pi * ball_radius**2
    for k in range(n):
        ratio[k] = area[k] * pixel_area[k] * (depth * depth) / ball_area
        tr, det = moments[k, 0] + moments[k, 1], moments[k, 0] * moments[k, 1] - moments[k, 2] ** 2
        disc = math.sqrt(max(tr * tr / 4.0 - det, 0.0))
        elong[k] = math.sqrt((tr / 2.0 + disc) / max(tr / 2.0 - disc, 1e-6))
        fill = area[k] / ((bbox[k, 2] - bbox[k, 0] + 1.0) * (bbox[k, 3] - bbox[k, 1] + 1.0))
        keep[k] = min_area <= ratio[k] <= max_area and elong[k] <= max_elongation and fill >= min_fill
        for r in range(robot_xy.shape[0]):
            if not keep[k]:
                break
            down = cam[2] - robot_z[r]
            x, y = cam[0] + down * rays[k, 0], cam[1] + down * rays[k, 1]
            keep[k] = math.hypot(x - robot_xy[r, 0], y - robot_xy[r, 1]) >= pattern_radius
    return keep, ratio, elong
