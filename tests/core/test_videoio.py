"""cmdragons.videoio: H.264 and FFV1 round trips, and files that break off."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from cmdragons.videoio import VideoError, VideoWriter, read_video, video_info

W, H, N = 320, 240, 90


def frames() -> list[NDArray[np.uint8]]:
    """A moving orange square on a textured green carpet, N frames."""
    rng = np.random.default_rng(3)
    base = np.zeros((H, W, 3), np.uint8)
    base[:] = (40, 110, 30)
    base = np.clip(base + rng.normal(0, 3, base.shape), 0, 255).astype(np.uint8)
    out = []
    for k in range(N):
        img = base.copy()
        img[100:130, 20 + 2 * k : 50 + 2 * k] = (0, 128, 255)
        out.append(img)
    return out


def write(path: Path, codec: str, crf: int | None = None) -> list[NDArray[np.uint8]]:
    imgs = frames()
    with VideoWriter(path, W, H, 60.0, codec, crf) as w:  # type: ignore[arg-type]
        for img in imgs:
            w.write(img)
    return imgs


def test_ffv1_is_lossless(tmp_path: Path) -> None:
    imgs = write(tmp_path / "a.mkv", "ffv1")
    got = list(read_video(tmp_path / "a.mkv"))
    assert [k for k, _ in got] == list(range(N))
    assert all(np.array_equal(g, i) for (_, g), i in zip(got, imgs, strict=True))
    assert video_info(tmp_path / "a.mkv")["codec"] == "ffv1"


@pytest.mark.parametrize(("name", "crf", "max_mean_err"), [("a.mp4", 0, 3.0), ("a.mp4", 18, 3.5), ("a.mkv", 23, 4.0)])
def test_h264_round_trip_is_close_and_420(tmp_path: Path, name: str, crf: int, max_mean_err: float) -> None:
    imgs = write(tmp_path / name, "h264", crf)
    info = video_info(tmp_path / name)
    assert (info["codec"], info["pix_fmt"], info["width"], info["height"]) == ("h264", "yuv420p", W, H)
    assert info["fps"] == pytest.approx(60.0)
    got = list(read_video(tmp_path / name))
    assert len(got) == N
    err = [float(np.mean(np.abs(g.astype(int) - i))) for (_, g), i in zip(got, imgs, strict=True)]
    assert max(err) < max_mean_err  # grey levels, mean over the frame (4:2:0 alone costs ~2.3 on this texture)
    # no colour cast: the mean of the frame keeps its grey level (FFmpeg's own scaler loses ~2)
    bias = np.mean([g.astype(float).mean(axis=(0, 1)) - i.mean(axis=(0, 1))
                    for (_, g), i in zip(got, imgs, strict=True)], axis=0)
    assert np.all(np.abs(bias) < 0.5)


@pytest.mark.parametrize(("name", "codec"), [("cut.mp4", "h264"), ("cut.mkv", "h264"), ("cut.mkv", "ffv1")])
def test_a_cut_off_file_yields_frames_up_to_the_break_then_names_it(tmp_path: Path, name: str, codec: str) -> None:
    imgs = write(tmp_path / name, codec)
    data = (tmp_path / name).read_bytes()
    (tmp_path / name).write_bytes(data[: len(data) * 6 // 10])
    got = []
    with pytest.raises(VideoError, match=rf"{name}: .*frame (\d+)") as err:
        for k, img in read_video(tmp_path / name):
            got.append((k, img))
    assert 20 <= len(got) < N
    assert f"frame {len(got)}" in str(err.value)  # the first frame not read
    # what was read is the video's start, frame for frame
    assert all(float(np.mean(np.abs(g.astype(int) - imgs[k]))) < 3.0 for k, g in got)


def test_unreadable_and_bad_arguments_raise_video_error(tmp_path: Path) -> None:
    (tmp_path / "junk.mp4").write_bytes(b"\x00" * 1000)
    with pytest.raises(VideoError, match="junk.mp4: cannot be opened"):
        list(read_video(tmp_path / "junk.mp4"))
    with pytest.raises(VideoError, match="even width"):
        VideoWriter(tmp_path / "odd.mp4", 321, 240, 60.0)
    with pytest.raises(VideoError, match="mkv"):
        VideoWriter(tmp_path / "x.mp4", 320, 240, 60.0, "ffv1")
    with VideoWriter(tmp_path / "ok.mp4", 320, 240, 60.0) as w, pytest.raises(VideoError, match="frame 0"):
        w.write(np.zeros((10, 10, 3), np.uint8))
