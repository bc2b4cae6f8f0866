"""numba kernels of the floor's video module: the colour conversion between BGR and H.264's planar
4:2:0 (the sorts and the median the other kernels use are :mod:`cmdragons.sorting`'s, the angle wrap
:mod:`cmdragons.angles`').

BT.601 in the limited range, chroma at the MPEG-2 sites (on the even luma columns, between each
pair of luma rows). The planar frame is flat: H * W luma bytes, then the (H / 2) x (W / 2) Cb
plane, then the Cr plane, each row after row. Plain-numpy references:
:func:`cmdragons.videoio.bgr_to_i420_reference` and :func:`cmdragons.videoio.i420_to_bgr_reference`;
a test keeps them in agreement.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _u8(x: float) -> np.uint8:
    return np.uint8(min(max(np.floor(x + 0.5), 0.0), 255.0))


@njit(cache=True)
def bgr_to_i420(image: np.ndarray, to_yuv: np.ndarray, out: np.ndarray) -> None:
    """``image`` (H, W, 3) BGR uint8 -> ``out`` (H * W * 3 / 2,) uint8. ``to_yuv`` (3, 4): rows
    Y, Cb, Cr over (B, G, R, 1). Each chroma sample low-passes the pixels around its site:
    [1, 2, 1] / 4 along the row (the left neighbour clamped at the edge), the mean of the two rows."""
    h, w = image.shape[0], image.shape[1]
    for i in range(h):
        for j in range(w):
            b, g, r = float(image[i, j, 0]), float(image[i, j, 1]), float(image[i, j, 2])
            out[i * w + j] = _u8(to_yuv[0, 0] * b + to_yuv[0, 1] * g + to_yuv[0, 2] * r + to_yuv[0, 3])
    hc, wc = h // 2, w // 2
    for i in range(hc):
        for j in range(wc):
            sb, sg, sr = 0.0, 0.0, 0.0
            left, mid, right = max(2 * j - 1, 0), 2 * j, 2 * j + 1
            for row in (2 * i, 2 * i + 1):
                sb += 0.125 * image[row, left, 0] + 0.25 * image[row, mid, 0] + 0.125 * image[row, right, 0]
                sg += 0.125 * image[row, left, 1] + 0.25 * image[row, mid, 1] + 0.125 * image[row, right, 1]
                sr += 0.125 * image[row, left, 2] + 0.25 * image[row, mid, 2] + 0.125 * image[row, right, 2]
            k = i * wc + j
            out[h * w + k] = _u8(to_yuv[1, 0] * sb + to_yuv[1, 1] * sg + to_yuv[1, 2] * sr + to_yuv[1, 3])
            out[h * w + hc * wc + k] = _u8(to_yuv[2, 0] * sb + to_yuv[2, 1] * sg + to_yuv[2, 2] * sr + to_yuv[2, 3])


@njit(cache=True)
def i420_to_bgr(planes: np.ndarray, to_bgr: np.ndarray, out: np.ndarray) -> None:
    """``planes`` (H * W * 3 / 2,) uint8 -> ``out`` (H, W, 3) BGR uint8; ``to_bgr`` (3, 4): rows
    B, G, R over (Y, Cb, Cr, 1). Chroma is interpolated linearly at each pixel's position on the
    chroma grid: column x / 2, row y / 2 - 1 / 4 (edges replicated)."""
    h, w = out.shape[0], out.shape[1]
    hc, wc = h // 2, w // 2
    u_at, v_at = h * w, h * w + hc * wc
    for i in range(h):
        cy = 0.5 * i - 0.25
        i0 = int(np.floor(cy))
        fy = cy - i0
        i1 = min(i0 + 1, hc - 1)
        i0 = max(i0, 0)
        for j in range(w):
            j0 = j >> 1
            fx = 0.5 * (j & 1)
            j1 = min(j0 + 1, wc - 1)
            a00, a01, a10, a11 = (1.0 - fy) * (1.0 - fx), (1.0 - fy) * fx, fy * (1.0 - fx), fy * fx
            k00, k01, k10, k11 = i0 * wc + j0, i0 * wc + j1, i1 * wc + j0, i1 * wc + j1
            cb = (a00 * planes[u_at + k00] + a01 * planes[u_at + k01] + a10 * planes[u_at + k10]
                  + a11 * planes[u_at + k11])
            cr = (a00 * planes[v_at + k00] + a01 * planes[v_at + k01] + a10 * planes[v_at + k10]
                  + a11 * planes[v_at + k11])
            y = float(planes[i * w + j])
            for ch in range(3):
                out[i, j, ch] = _u8(to_bgr[ch, 0] * y + to_bgr[ch, 1] * cb + to_bgr[ch, 2] * cr + to_bgr[ch, 3])

