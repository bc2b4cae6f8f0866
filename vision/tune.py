"""Colour tuning: threshold boxes (thesis A.1.3) from labelled pixels.

Samples come from a user's labels -- a few spots clicked on a real frame, each a colour name, a
pixel position and a radius -- or from a recording's truth, where every visible dot and the ball
are known exactly. Each colour's box spans a central share of its samples per channel of the
colour space, widened by a margin for light the samples did not see.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.config import ConfigError
from cmdragons.geometry import LeagueParams
from cmdragons.recording import RecordingReader
from vision.cmvision import ColourClass, ColourSpace, convert_colour
from vision.sources import open_sources

__all__ = ["Label", "read_yaml_any", "boxes_from_samples", "read_labels", "samples_from_labels", "samples_from_truth"]

Samples = dict[str, list[NDArray[np.int32]]]


@dataclass(frozen=True)
class Label:
    """A labelled spot: colour name, pixel (u, v) of its centre, radius in pixels, and the image
    it is on (index into the images given, default the first)."""

    colour: str
    pixel: tuple[float, float]
    radius_px: float
    image: int = 0


def read_yaml_any(path: str | Path) -> Any:
    """A YAML or JSON file (JSON is YAML) whose top level may be a list; raises ConfigError."""
    try:
        return yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise ConfigError(path, "", f"cannot read: {exc}") from None


def read_labels(path: str | Path) -> list[Label]:
    """A YAML (or JSON) list of ``{colour, pixel: [u, v], radius, image}``; raises ConfigError."""
    data = read_yaml_any(path)
    if isinstance(data, dict):
        data = data.get("labels")
    if not isinstance(data, list) or not data:
        raise ConfigError(path, "", "expected a list of labels {colour, pixel: [u, v], radius}")
    out = []
    for k, item in enumerate(data):
        try:
            u, v = item["pixel"]
            out.append(Label(str(item["colour"]), (float(u), float(v)), float(item.get("radius", 3.0)),
                             int(item.get("image", 0))))  # fmt: skip
        except (KeyError, TypeError, ValueError) as exc:
            raise ConfigError(path, f"[{k}]", f"bad label {item!r}: {exc}") from None
    return out


def _disc(image: NDArray[np.uint8], centre: tuple[float, float], radius: float) -> NDArray[np.uint8]:
    """Pixels (n, 3) whose centres lie within ``radius`` of ``centre`` (u, v)."""
    h, w = image.shape[:2]
    u, v = centre
    i0, i1 = max(0, int(v - radius)), min(h, int(math.ceil(v + radius)) + 1)
    j0, j1 = max(0, int(u - radius)), min(w, int(math.ceil(u + radius)) + 1)
    if i0 >= i1 or j0 >= j1:
        return np.zeros((0, 3), np.uint8)
    vv, uu = np.mgrid[i0:i1, j0:j1] + 0.5
    inside = (uu - u) ** 2 + (vv - v) ** 2 <= radius * radius
    out: NDArray[np.uint8] = image[i0:i1, j0:j1][inside]
    return out


def samples_from_labels(images: Sequence[NDArray[np.uint8]], labels: Iterable[Label], space: ColourSpace) -> Samples:
    out: Samples = {}
    for lab in labels:
        if not 0 <= lab.image < len(images):
            raise ValueError(f"label {lab} names image {lab.image}, but {len(images)} image(s) were given")
        px = _disc(images[lab.image], lab.pixel, lab.radius_px)
        out.setdefault(lab.colour, []).append(convert_colour(px[None], space)[0])
    return out


def samples_from_truth(recording: Path, league: LeagueParams, roles: Mapping[str, str], space: ColourSpace,
                       max_frames: int = 60, inner_fraction: float = 0.5) -> Samples:  # fmt: skip
    """Samples of every pattern dot and the ball a recording's truth says are visible: the inner
    ``inner_fraction`` of each dot's radius, in up to ``max_frames`` frames per camera. ``roles``
    maps ball, blue, yellow, pink, green to colour names."""
    reader = RecordingReader(recording)
    truth = {t.frame_number: t for t in reader.truth()}
    if not truth:
        raise ValueError(f"{recording}: no truth.jsonl to tune from")
    pat, h = league.pattern, league.robot.height_m
    out: Samples = {}

    def add(name: str, image: NDArray[np.uint8], model: CameraModel, xy: NDArray[np.float64], z: float,
            r_m: float) -> None:  # fmt: skip
        px = model.project_xy(xy, z)
        r_px = inner_fraction * r_m * model.pixels_per_metre((float(xy[0]), float(xy[1])), z)
        got = _disc(image, (float(px[0]), float(px[1])), max(r_px, 0.8))
        out.setdefault(name, []).append(convert_colour(got[None], space)[0])

    numbers = sorted(truth)
    wanted = set(numbers[:: max(1, len(numbers) // max_frames)][:max_frames])
    for src in open_sources([str(recording)])[0]:
        model = src.camera or reader.camera_model(src.camera_id)
        for k, image in src.frames():
            t = truth.get(k)
            if t is None or k not in wanted or image is None or image.shape != (model.height, model.width, 3):
                continue  # bad frames are the run's business, not the tuner's
            cam = src.camera_id
            for r in t.robots:
                if cam not in r.pixels:
                    continue
                add(roles[r.team], image, model, np.array([r.x, r.y]), h, pat.center_dot_diameter_m / 2)
                c, s = math.cos(r.theta), math.sin(r.theta)
                for (dx, dy), pink in zip(pat.dot_positions_m, pat.dot_is_pink(r.id), strict=True):
                    xy = np.array([r.x + c * dx - s * dy, r.y + s * dx + c * dy])
                    add(roles["pink" if pink else "green"], image, model, xy, h, pat.id_dot_diameter_m / 2)
            seen = t.ball.pixels.get(cam)
            if seen is not None and seen[2] >= 0.95 and t.ball.z < 2.0 * league.ball.radius_m:
                add(roles["ball"], image, model, np.array([t.ball.x, t.ball.y]), league.ball.radius_m,
                    league.ball.radius_m)  # fmt: skip
    return out


def boxes_from_samples(samples: Samples, share: float = 0.998, margin: int = 8,
                       min_area_px: int = 6) -> dict[str, ColourClass]:  # fmt: skip
    """Per colour, the box holding the central ``share`` of its samples in each channel, widened
    by ``margin`` grey levels."""
    out = {}
    tail = (1.0 - share) / 2.0 * 100.0
    for name, parts in samples.items():
        px = np.concatenate(parts, axis=0)
        if len(px) < 10:
            raise ValueError(f"colour {name!r}: only {len(px)} samples; label more or larger spots")
        lo = np.clip(np.floor(np.percentile(px, tail, axis=0)) - margin, 0, 255).astype(int)
        hi = np.clip(np.ceil(np.percentile(px, 100.0 - tail, axis=0)) + margin, 0, 255).astype(int)
        out[name] = ColourClass(lo=(int(lo[0]), int(lo[1]), int(lo[2])), hi=(int(hi[0]), int(hi[1]), int(hi[2])),
                                min_area_px=min_area_px)  # fmt: skip
    return out
