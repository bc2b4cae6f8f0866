"""``cmdragons vision calibrate`` and ``cmdragons vision tune``: argument handling and config writing
around :mod:`vision.calibrate` and :mod:`vision.tune`.

Both rewrite a file the user edits, so both go through ruamel.yaml's round trip: every comment,
key order and flow style of the file stays; only the values the command derives change.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from typing import Any

import cv2
import numpy as np
import yaml
from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq

from cmdragons.camera import CameraParams, CamerasParams
from cmdragons.config import ConfigError, to_plain

__all__ = ["main"]


def _parser(command: str) -> argparse.ArgumentParser:
    if command == "calibrate":
        about = "fit one camera's parameters to pixel <-> field correspondences"
        p = argparse.ArgumentParser(prog="cmdragons vision calibrate", description=about)
        p.add_argument("points", metavar="POINTS.yaml", help="list of {pixel: [u, v], field: [x, y(, z)]} (m)")
        p.add_argument("--camera", type=int, default=0, help="camera id to write (default 0)")
        p.add_argument("--resolution", type=int, nargs=2, default=None, metavar=("W", "H"))
        p.add_argument("--focal", type=float, default=None, help="focal length guess, px (default: from configs)")
        p.add_argument("--fit-principal-point", action="store_true", help="also fit the principal point")
        p.add_argument("--out", metavar="FILE", default=None, help="cameras.yaml to write (default: the config's)")
    else:
        about = "derive colour threshold boxes from labelled spots or a recording's truth"
        p = argparse.ArgumentParser(prog="cmdragons vision tune", description=about)
        p.add_argument("images", nargs="+", metavar="IMAGE", help="images, or one recording folder with truth.jsonl")
        p.add_argument(
            "--labels", metavar="FILE", default=None, help="YAML/JSON list of {colour, pixel, radius, image}"
        )
        p.add_argument("--margin", type=int, default=16, help="grey levels added around the samples (default 16)")
        p.add_argument("--out", metavar="FILE", default=None, help="vision.yaml to write (default: the config's)")
    return p


def main(command: str, argv: Sequence[str], common: Callable[[argparse.ArgumentParser], None]) -> int:
    """Run ``cmdragons vision <command> ARGV``; ``common`` adds the --config and --set options."""
    from cmdragons.runtime.settings import load_settings

    parser = _parser(command)
    common(parser)
    args = parser.parse_args(list(argv))
    settings = load_settings(args.config, args.set)
    try:
        return _calibrate(args, settings) if command == "calibrate" else _tune(args, settings)
    except (ValueError, OSError) as exc:
        if isinstance(exc, ConfigError):
            raise
        print(f"cmdragons vision {command}: {exc}", file=sys.stderr)
        return 2


def _calibrate(args: argparse.Namespace, settings: object) -> int:
    from vision.calibrate import calibrate, read_correspondences

    models = {m.id: m for m in settings.camera_models()}  # type: ignore[attr-defined]
    guess = models[args.camera].params if args.camera in models else CameraParams(id=args.camera)
    if args.resolution:
        w, h = args.resolution
        guess = dataclasses.replace(guess, resolution_px=(w, h), principal_point_px=(w / 2, h / 2))
    if args.focal:
        guess = dataclasses.replace(guess, focal_px=args.focal)
    pixels, field = read_correspondences(args.points)
    result = calibrate(pixels, field, guess, args.fit_principal_point)
    out = Path(args.out) if args.out else settings.config_dir / "cameras.yaml"  # type: ignore[attr-defined]
    others = tuple(m.params for i, m in sorted(models.items()) if i != args.camera)
    cams = CamerasParams(layout="list", cameras=tuple(sorted((*others, result.params), key=lambda c: c.id)))
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(yaml.safe_dump(to_plain(cams), sort_keys=False), encoding="utf-8")
    print(f"calibrate: camera {args.camera} from {len(pixels)} points, reprojection RMS {result.rms_px:.3f} px "
          f"(max {result.max_px:.3f}) -> {out}")  # fmt: skip
    return 0


def _tune(args: argparse.Namespace, settings: object) -> int:
    from vision.tune import boxes_from_samples, read_labels, samples_from_labels, samples_from_truth

    vis = settings.vision  # type: ignore[attr-defined]
    first = Path(args.images[0])
    if args.labels is None:
        if not (first.is_dir() and (first / "truth.jsonl").exists()):
            raise ValueError("give --labels, or recording folders with truth.jsonl")
        roles = {r: getattr(vis.roles, r) for r in ("ball", "blue", "yellow", "pink", "green")}
        samples: dict[str, list[np.ndarray]] = {}
        for folder in args.images:
            for name, parts in samples_from_truth(Path(folder), settings.field, roles, vis.colour_space).items():  # type: ignore[attr-defined]
                samples.setdefault(name, []).extend(parts)
    else:
        images = []
        for name in args.images:
            img = cv2.imread(name, cv2.IMREAD_COLOR)
            if img is None:
                raise ValueError(f"{name}: cannot be read as an image")
            images.append(np.asarray(img, dtype=np.uint8))
        samples = samples_from_labels(images, read_labels(args.labels), vis.colour_space)
    boxes = boxes_from_samples(samples, margin=args.margin)
    source = settings.config_dir / "vision.yaml"  # type: ignore[attr-defined]
    out = Path(args.out) if args.out else source
    doc = _load_round_trip(out if out.exists() else source)
    colours = doc.setdefault("colours", CommentedMap())
    for name, box in boxes.items():
        n = sum(len(p) for p in samples[name])
        entry = colours.get(name)
        was = f"lo {list(entry['lo'])} hi {list(entry['hi'])}" if entry and "lo" in entry and "hi" in entry else "(new)"
        print(f"tune: {name:8s} {n:7d} labelled pixels: {was} -> lo {list(box.lo)} hi {list(box.hi)}")
        if entry is None:
            entry = colours[name] = _flow(CommentedMap(min_area_px=box.min_area_px))
        for key, value in (("lo", box.lo), ("hi", box.hi)):
            if isinstance(entry.get(key), CommentedSeq):
                entry[key][:] = list(value)  # in place: keeps the list's flow style and comments
            else:
                entry[key] = _flow(CommentedSeq(list(value)))
    _write_round_trip(doc, out, _check_vision)
    print(f"tune: only the colour boxes changed -> {out}")
    return 0


def _yaml() -> YAML:
    rt = YAML(typ="rt")
    rt.preserve_quotes = True
    rt.width = 4096  # never fold a long comment line
    return rt


def _load_round_trip(path: Path) -> Any:
    """A YAML file as ruamel's round-trip document (a mapping that keeps comments and order)."""
    try:
        doc = _yaml().load(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ValueError(f"{path}: cannot be read ({exc})") from None
    except Exception as exc:  # ruamel's parser and scanner errors share no base class but Exception
        raise ConfigError(path, "", f"not valid YAML: {exc}") from None
    if doc is None:
        doc = CommentedMap()
    if not isinstance(doc, CommentedMap):
        raise ConfigError(path, "", "expected a mapping at the top level")
    return doc


def _flow(node: Any) -> Any:
    node.fa.set_flow_style()
    return node


def _check_vision(data: dict[str, Any], path: Path) -> None:
    """An edited vision.yaml parses (raises ConfigError otherwise)."""
    from cmdragons.config import parse
    from vision.pipeline import VisionParams

    parse(VisionParams, data, file=path)


def _write_round_trip(doc: Any, path: Path, check: Callable[[dict[str, Any], Path], None]) -> None:
    """Write ``doc`` to ``path`` after ``check`` accepted it as plain data (a bad result never
    replaces a good file)."""
    import io

    buf = io.StringIO()
    _yaml().dump(doc, buf)
    text = buf.getvalue()
    check(yaml.safe_load(text) or {}, path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
