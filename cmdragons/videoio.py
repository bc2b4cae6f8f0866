"""Video files: writing camera recordings and match videos, reading any common container.

The one module that imports PyAV (FFmpeg's libraries, shipped in its wheels). Frames are BGR
uint8 (H, W, 3), as OpenCV and the renderer hold them.

Writing: H.264 in yuv420p (4:2:0 chroma, what browsers and phones play; quality by x264's
constant rate factor ``crf``, 0 best to 51 worst, ~18 visually lossless, 23 x264's default) in
.mp4 or .mkv, or FFV1 (lossless, BGR as stored) in .mkv.

Reading: :func:`read_video` yields ``(frame_index, image)`` and, when the file ends early (a
recording cut off, a corrupt packet), stops at the last frame that decoded whole and raises
:class:`VideoError` naming the file and the first frame it could not read, so that a caller
keeps everything before it.
"""

from __future__ import annotations

from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from types import TracebackType
from typing import Any, Literal

import av
import numpy as np
from numpy.typing import NDArray

import cmdragons._kernels as kern

__all__ = [
    "CODECS",
    "Codec",
    "H264RoundTrip",
    "VideoError",
    "VideoWriter",
    "bgr_to_i420",
    "bgr_to_i420_reference",
    "i420_to_bgr",
    "i420_to_bgr_reference",
    "read_video",
    "video_info",
]

Codec = Literal["h264", "ffv1"]
CODECS: tuple[Codec, ...] = ("h264", "ffv1")
_ENCODERS: dict[str, tuple[str, str]] = {"h264": ("libx264", "yuv420p"), "ffv1": ("ffv1", "bgr0")}
DEFAULT_CRF = 18  # x264's constant rate factor taken when none is given: visually lossless


class VideoError(RuntimeError):
    """A video file that cannot be written, opened or read to its end."""


class VideoWriter:
    """Frames (H, W, 3) BGR uint8 of one size into ``path``: H.264 (yuv420p; ``crf`` 0..51, default
    18) or FFV1 (lossless; the container must be .mkv). Width and height must be even for H.264
    in 4:2:0. A context manager; :meth:`close` flushes the encoder and finishes the file."""

    def __init__(self, path: str | Path, width: int, height: int, fps: float, codec: Codec = "h264",
                 crf: int | None = None) -> None:
        self.path = Path(path)
        if codec not in _ENCODERS:
            raise VideoError(f"{self.path}: unknown codec {codec!r}; choose one of {', '.join(CODECS)}")
        if codec == "ffv1" and self.path.suffix.lower() != ".mkv":
            raise VideoError(f"{self.path}: FFV1 is written into .mkv files only")
        if codec == "h264" and (width % 2 or height % 2):
            raise VideoError(f"{self.path}: H.264 in 4:2:0 needs an even width and height, got {width}x{height}")
        if crf is not None and not (codec == "h264" and 0 <= crf <= 51):
            raise VideoError(f"{self.path}: crf must be 0 to 51 and only applies to h264, got {crf} for {codec}")
        if not (fps > 0.0 and width > 0 and height > 0):
            raise VideoError(f"{self.path}: bad video size {width}x{height} at {fps} frames per second")
        self.width, self.height, self.fps, self.codec = width, height, fps, codec
        self.crf = (DEFAULT_CRF if crf is None else crf) if codec == "h264" else None
        self.frames = 0
        encoder, pix_fmt = _ENCODERS[codec]
        options: dict[str, str] = {}
        if codec == "h264":
            # one key frame a second keeps a cut-off file readable up to its last second
            options = {"crf": str(self.crf), "preset": "veryfast", "g": str(max(1, round(fps)))}
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            # MP4 in fragments (an index per key frame, none at the end): a file cut off while being
            # written still opens and reads up to its last whole fragment
            fmt_options = {"movflags": "frag_keyframe+empty_moov+default_base_moof"} if self.path.suffix.lower() in (
                ".mp4", ".mov") else {}
            container: Any = av.open(str(self.path), mode="w", options=fmt_options)
            stream: Any = container.add_stream(encoder, rate=Fraction(fps).limit_denominator(1001), options=options)
        except (av.FFmpegError, OSError) as exc:
            raise VideoError(f"{self.path}: cannot be opened for writing ({exc})") from None
        stream.width, stream.height, stream.pix_fmt = width, height, pix_fmt
        if codec == "h264":  # say what the samples are: BT.601 (SMPTE 170M) in the limited range
            ctx = stream.codec_context
            ctx.colorspace, ctx.color_primaries, ctx.color_trc, ctx.color_range = 6, 6, 6, 1
        self._container, self._stream = container, stream
        self._closed = False

    def write(self, image: NDArray[np.uint8]) -> None:
        """Append one frame (H, W, 3) BGR uint8 of the writer's size."""
        if self._closed:
            raise VideoError(f"{self.path}: written after close")
        if image.shape != (self.height, self.width, 3) or image.dtype != np.uint8:
            raise VideoError(f"{self.path}: frame {self.frames} is {image.dtype} {image.shape}, "
                             f"expected uint8 ({self.height}, {self.width}, 3)")
        if self.codec == "h264":
            frame = av.VideoFrame.from_ndarray(bgr_to_i420(image), format="yuv420p")
        else:
            frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(image), format="bgr24")
        frame.pts = self.frames
        self._mux(self._stream.encode(frame))
        self.frames += 1

    def _mux(self, packets: Any) -> None:
        try:
            self._container.mux(packets)
        except (av.FFmpegError, OSError) as exc:
            raise VideoError(f"{self.path}: frame {self.frames} could not be written ({exc})") from None

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            self._mux(self._stream.encode(None))
        finally:
            self._container.close()

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def video_info(path: str | Path) -> dict[str, Any]:
    """What the first video stream of ``path`` holds: codec, pix_fmt, width, height, fps and the
    frame count its container states (0 when it states none)."""
    try:
        with av.open(str(path)) as c:
            if not c.streams.video:
                raise VideoError(f"{path}: no video stream")
            s = c.streams.video[0]
            rate = s.average_rate or s.guessed_rate
            return {"codec": s.codec_context.name, "pix_fmt": s.codec_context.pix_fmt, "width": s.width,
                    "height": s.height, "fps": float(rate) if rate else None, "frames": int(s.frames)}
    except av.FFmpegError as exc:
        raise VideoError(f"{path}: cannot be opened as a video ({exc})") from None


# BT.601 in the limited range (Y 16..235, Cb and Cr 16..240), rows Y, Cb, Cr over (B, G, R, 1)
_TO_YUV = np.array([[24.966, 128.553, 65.481, 16.0 * 255.0], [112.0, -74.203, -37.797, 128.0 * 255.0],
                    [-18.214, -93.786, 112.0, 128.0 * 255.0]], dtype=np.float64) / 255.0
# and back: rows B, G, R over (Y, Cb, Cr, 1)
_TO_BGR = np.linalg.inv(np.vstack([_TO_YUV, [0.0, 0.0, 0.0, 1.0]]))[:3]


def bgr_to_i420(image: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """BGR (H, W, 3) uint8, H and W even -> planar 4:2:0 (H * 3 / 2, W) uint8 as H.264 stores it:
    BT.601 in the limited range, each chroma sample where the standard puts it (MPEG-2 siting: on
    the even luma columns, between each pair of luma rows), low-passed to that grid ([1, 2, 1] / 4
    along rows, the mean of the two rows). Point samples or 2 x 2 means at another place shift a
    colour by half a pixel against its brightness (OpenCV's own I420 conversion does, by +0.5 px
    in u and v), which moves every colour blob's centre."""
    h, w = image.shape[:2]
    out = np.empty(h * w * 3 // 2, np.uint8)
    kern.bgr_to_i420(np.ascontiguousarray(image), _TO_YUV, out)
    return out.reshape(h * 3 // 2, w)


def i420_to_bgr(planes: NDArray[np.uint8], h: int, w: int) -> NDArray[np.uint8]:
    """Planar 4:2:0 (H * W * 3 / 2 bytes, any shape) uint8 (BT.601, limited range, MPEG-2 chroma
    siting) -> BGR (H, W, 3) uint8, the chroma interpolated linearly at every pixel's true
    position: the inverse of :func:`bgr_to_i420` up to the chroma resolution lost."""
    out = np.empty((h, w, 3), np.uint8)
    kern.i420_to_bgr(np.ascontiguousarray(planes).reshape(-1), _TO_BGR, out)
    return out


def _u8(x: NDArray[np.float64]) -> NDArray[np.uint8]:
    return np.clip(np.floor(x + 0.5), 0, 255).astype(np.uint8)


def bgr_to_i420_reference(image: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Plain numpy of :func:`bgr_to_i420` (the kernel's arithmetic, in float64)."""
    h, w = image.shape[:2]
    px = np.concatenate([image.astype(np.float64), np.ones((h, w, 1))], axis=-1)
    y = _u8(px @ _TO_YUV[0])
    pair = 0.5 * (px[0::2] + px[1::2])  # between the rows
    left = np.concatenate([pair[:, :1], pair[:, 1:-1:2]], axis=1)  # column 2j - 1, 0 at the edge
    site = 0.25 * left + 0.5 * pair[:, 0::2] + 0.25 * pair[:, 1::2]
    return np.concatenate([y.ravel(), _u8(site @ _TO_YUV[1]).ravel(), _u8(site @ _TO_YUV[2]).ravel()]).reshape(
        h * 3 // 2, w)


def i420_to_bgr_reference(planes: NDArray[np.uint8], h: int, w: int) -> NDArray[np.uint8]:
    """Plain numpy of :func:`i420_to_bgr`."""
    flat = planes.reshape(-1).astype(np.float64)
    hc, wc = h // 2, w // 2
    y = flat[: h * w].reshape(h, w)
    c = np.stack([flat[h * w : h * w + hc * wc].reshape(hc, wc), flat[h * w + hc * wc :].reshape(hc, wc)], axis=-1)
    up = np.concatenate([c[:1], c[:-1]], axis=0)  # rows sit 1/4 of a chroma row off their sample
    down = np.concatenate([c[1:], c[-1:]], axis=0)
    rows = np.empty((h, wc, 2))
    rows[0::2] = 0.75 * c + 0.25 * up
    rows[1::2] = 0.75 * c + 0.25 * down
    full = np.empty((h, w, 2))
    full[:, 0::2] = rows  # even columns on the sample, odd ones halfway to the next
    full[:, 1::2] = 0.5 * (rows + np.concatenate([rows[:, 1:], rows[:, -1:]], axis=1))
    yuv1 = np.concatenate([y[..., None], full, np.ones((h, w, 1))], axis=-1)
    return _u8(yuv1 @ _TO_BGR.T)


def _bgr(frame: Any) -> NDArray[np.uint8]:
    """A decoded frame as BGR uint8: 4:2:0 video by :func:`i420_to_bgr` (the inverse of the
    writer's conversion; FFmpeg's default scaler darkens by ~2 grey levels and replicates the
    chroma), any other pixel format by FFmpeg's scaler."""
    if frame.format.name == "yuv420p" and frame.width % 2 == 0 and frame.height % 2 == 0:
        return i420_to_bgr(frame.to_ndarray(), frame.height, frame.width)
    return np.ascontiguousarray(frame.to_ndarray(format="bgr24"), dtype=np.uint8)


def _stated_frames(container: Any, stream: Any) -> tuple[int, bool]:
    """The number of frames the container says it holds (0: it says nothing) and whether the
    count is exact (an index) or from the stated duration (Matroska, +-1 frame)."""
    if int(stream.frames) > 0:
        return int(stream.frames), True
    rate = stream.average_rate or stream.guessed_rate
    if container.duration and rate:
        return round(container.duration / av.time_base * float(rate)), False
    return 0, False


def read_video(path: str | Path) -> Iterator[tuple[int, NDArray[np.uint8]]]:
    """Every frame of the first video stream of ``path`` as ``(frame_index, BGR uint8)``, in
    order. A file that cannot be opened raises :class:`VideoError` at once; one that breaks off
    (truncated, a corrupt packet, fewer frames than its container states) yields every frame
    before the break and then raises :class:`VideoError` naming the file and that frame."""
    try:
        container: Any = av.open(str(path))
    except (av.FFmpegError, OSError) as exc:
        raise VideoError(f"{path}: cannot be opened as a video ({exc})") from None
    k = 0
    try:
        if not container.streams.video:
            raise VideoError(f"{path}: no video stream")
        stream = container.streams.video[0]
        stated, exact = _stated_frames(container, stream)
        try:
            for packet in container.demux(stream):
                if packet.is_corrupt:
                    raise VideoError(f"{path}: frame {k} is corrupt; read frames 0 to {k - 1}")
                for frame in packet.decode():
                    if frame.is_corrupt:
                        raise VideoError(f"{path}: frame {k} is corrupt; read frames 0 to {k - 1}")
                    yield k, _bgr(frame)
                    k += 1
        except av.FFmpegError as exc:
            raise VideoError(f"{path}: frame {k} cannot be decoded ({exc}); read frames 0 to {k - 1}") from None
        if stated and k < stated - (0 if exact else 1):
            raise VideoError(f"{path}: ends at frame {k} of the {stated} it states (truncated?); "
                             f"read frames 0 to {k - 1}")
    finally:
        container.close()


class H264RoundTrip:
    """Frames through an H.264 encoder and decoder in memory, one frame in, the same frame out
    (x264 without look-ahead or B-frames, on one thread: the same bytes every run)."""

    def __init__(self, width: int, height: int, crf: int) -> None:
        self.enc: Any = av.CodecContext.create("libx264", "w")
        self.enc.width, self.enc.height, self.enc.pix_fmt = width, height, "yuv420p"
        self.enc.time_base = Fraction(1, 60)
        self.enc.options = {"crf": str(crf), "preset": "veryfast", "tune": "zerolatency", "threads": "1"}
        self.dec: Any = av.CodecContext.create("h264", "r")
        self.dec.thread_count = 1
        self.n = 0
        self.h, self.w = height, width

    def __call__(self, image: NDArray[np.uint8]) -> NDArray[np.uint8]:
        frame = av.VideoFrame.from_ndarray(bgr_to_i420(image), format="yuv420p")
        frame.pts = self.n
        self.n += 1
        out = image
        for packet in self.enc.encode(frame):
            for decoded in self.dec.decode(packet):
                out = i420_to_bgr(decoded.to_ndarray(), self.h, self.w)
        return out
