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
from cmdragons.config import ConfigError

__all__ = ["main"]


def _parser(command: str) -> argparse.ArgumentParser:
    if command == "calibrate":
        about = ("fit one camera's parameters to the field lines in an image (--lines) or to pixel <-> field "
                 "correspondences (POINTS.yaml); writes cameras.yaml, keeping its comments")
        p = argparse.ArgumentParser(prog="cmdragons vision calibrate", description=about)
        p.add_argument("points", metavar="POINTS.yaml", nargs="?", default=None,
                       help="list of {pixel: [u, v], field: [x, y(, z)]} (m); not with --lines")
        p.add_argument("--lines", metavar="IMAGE", default=None,
                       help="calibrate from the white field lines of this camera image (configs/field.yaml's field)")
        p.add_argument("--camera", type=int, default=0, help="camera id to write (default 0)")
        p.add_argument("--height", type=float, default=None, metavar="M",
                       help="--lines: the camera's measured height above the carpet, m (default: the camera's in "
                       "configs; kept: one plane's lines cannot tell it from the focal length)")
        p.add_argument("--sees", type=float, nargs=4, default=None, metavar=("X0", "Y0", "X1", "Y1"),
                       help="--lines: the field rectangle the image roughly covers, m (default: what the camera "
                       "in configs sees)")
        p.add_argument("--reach", type=float, default=0.4, metavar="M",
                       help="--lines: how far off the rough start's position may be, m (default 0.4)")
        p.add_argument("--overlay", metavar="FILE.png", default=None,
                       help="--lines: the fitted field drawn on the image (default IMAGE_calibration.png beside it)")
        p.add_argument("--resolution", type=int, nargs=2, default=None, metavar=("W", "H"))
        p.add_argument("--focal", type=float, default=None,
                       help="focal length, px (default: from configs); with --lines it is taken as known: a fit "
                       "more than 5%% off it is refused")
        p.add_argument("--fit-principal-point", action="store_true", help="also fit the principal point")
        p.add_argument("--out", metavar="FILE", default=None, help="cameras.yaml to write (default: the config's)")
    else:
        about = ("derive colour threshold boxes with nothing labelled (--auto: from a calibrated camera's frames), "
                 "from labelled spots or from a recording's truth; warns where two classes overlap")
        p = argparse.ArgumentParser(prog="cmdragons vision tune", description=about)
        p.add_argument("images", nargs="+", metavar="IMAGE",
                       help="images (or with --auto a video), or one recording folder with truth.jsonl")
        p.add_argument("--auto", action="store_true",
                       help="learn every colour from the frames of a calibrated camera (cameras.yaml, --camera): the "
                       "robots' patterns and the ball found by their sizes and the pattern's geometry")
        p.add_argument("--camera", type=int, default=0, help="--auto: the camera id in cameras.yaml (default 0)")
        p.add_argument("--frames", type=int, default=10, help="--auto: frames of a video used, spread over its "
                       "first 3 s (default 10)")
        p.add_argument(
            "--labels", metavar="FILE", default=None, help="YAML/JSON list of {colour, pixel, radius, image}"
        )
        p.add_argument("--margin", type=int, default=16, help="grey levels added around the samples (default 16)")
        p.add_argument("--out", metavar="FILE", default=None, help="vision.yaml to write (default: the config's)")
    return p


def main(command: str, argv: Sequence[str], common: Callable[[argparse.ArgumentParser, str], None]) -> int:
    """Run ``cmdragons vision <command> ARGV``; ``common`` adds the --config and --set options."""
    from cmdragons.runtime.settings import load_settings

    parser = _parser(command)
    common(parser, "vision.colour_space=bgr" if command == "tune" else "cameras.auto.height_m=3.5")
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
    if (args.lines is None) == (args.points is None):
        raise ValueError("give either POINTS.yaml or --lines IMAGE")
    image = None
    if args.lines is not None:
        read = cv2.imread(args.lines, cv2.IMREAD_COLOR)
        if read is None:
            raise ValueError(f"{args.lines}: cannot be read as an image")
        image = np.asarray(read, dtype=np.uint8)
        if args.resolution is None:
            args.resolution = (image.shape[1], image.shape[0])
    if args.resolution:
        w, h = args.resolution
        if tuple(guess.resolution_px) != (w, h):
            sx = w / guess.resolution_px[0]
            guess = dataclasses.replace(guess, resolution_px=(w, h), principal_point_px=(w / 2, h / 2),
                                        focal_px=guess.focal_px * sx)
    if args.focal:
        guess = dataclasses.replace(guess, focal_px=args.focal)
    if image is not None:
        from vision.field_lines import LineFitParams, calibrate_from_lines, draw_field, rough_start

        height = args.height if args.height is not None else guess.position_m[2]
        if not 0.3 < height < 50.0:
            raise ValueError(f"--height must be 0.3 to 50 m, got {height}")
        sees = tuple(args.sees) if args.sees else _footprint(guess)
        if not (abs(sees[2] - sees[0]) >= 0.2 and abs(sees[3] - sees[1]) >= 0.2):
            raise ValueError(f"--sees must be a field rectangle X0 Y0 X1 Y1 at least 0.2 m each way, got {list(sees)}")
        start = rough_start(guess, height, sees)
        if args.focal:
            start = dataclasses.replace(start, focal_px=args.focal)
        try:
            fit_params = LineFitParams(reach_m=args.reach, known_focal_px=args.focal or 0.0)
        except ValueError as exc:
            raise ValueError(f"--reach: {exc}") from None
        fit = calibrate_from_lines(image, settings.field, start, fit_params)  # type: ignore[attr-defined]
        params, rms, worst = fit.params, fit.rms_px, fit.max_px
        what = (f"{fit.points} line centres on {fit.lines_seen} lines ({fit.found:.0%} of those in view found; "
                f"tape {fit.line_width_px:.1f} px wide)")
        overlay = Path(args.overlay) if args.overlay else Path(args.lines).with_name(
            Path(args.lines).stem + "_calibration.png")
        overlay.parent.mkdir(parents=True, exist_ok=True)
        if not cv2.imwrite(str(overlay), draw_field(image, params, settings.field, fit)):  # type: ignore[attr-defined]
            raise ValueError(f"could not write {overlay}")
    else:
        pixels, field = read_correspondences(args.points)
        result = calibrate(pixels, field, guess, args.fit_principal_point)
        params, rms, worst, what = result.params, result.rms_px, result.max_px, f"{len(pixels)} points"
    source = settings.config_dir / "cameras.yaml"  # type: ignore[attr-defined]
    out = Path(args.out) if args.out else source
    _write_cameras(out, source, params, [m.params for m in models.values()])
    p = params
    print(f"calibrate: camera {p.id} from {what}: position {[round(v, 4) for v in p.position_m]} m, yaw "
          f"{p.yaw_rad:.4f} rad, tilts {p.tilt_x_rad:.4f} {p.tilt_y_rad:.4f} rad, focal {p.focal_px:.2f} px, "
          f"k1 {p.k1:.4f} k2 {p.k2:.4f}; reprojection RMS {rms:.3f} px (max {worst:.3f}) -> {out}")
    if image is not None:
        for note in fit.notes:
            print(f"calibrate: note: {note}")
        print(f"calibrate: the fitted field, the line centres used and each line's RMS drawn on the image -> {overlay}")
    return 0


def _footprint(params: CameraParams) -> tuple[float, float, float, float]:
    """The field rectangle (x0, y0, x1, y1) a camera's image covers on the carpet."""
    from cmdragons.camera import CameraModel

    m = CameraModel(params)
    corners = m.unproject(np.array([[0.0, 0.0], [m.width, 0.0], [0.0, m.height], [m.width, m.height]]), 0.0)
    return (float(corners[:, 0].min()), float(corners[:, 1].min()), float(corners[:, 0].max()),
            float(corners[:, 1].max()))


def _camera_map(p: CameraParams, entry: Any = None) -> Any:
    """``p`` as cameras.yaml writes it, into ``entry`` (a round-trip mapping, its comments kept)."""
    entry = CommentedMap() if entry is None else entry
    values: dict[str, Any] = {
        "id": p.id, "position_m": [round(v, 5) for v in p.position_m], "yaw_rad": round(p.yaw_rad, 6),
        "tilt_x_rad": round(p.tilt_x_rad, 6), "tilt_y_rad": round(p.tilt_y_rad, 6), "focal_px": round(p.focal_px, 3),
        "principal_point_px": [round(v, 3) for v in p.principal_point_px], "k1": round(p.k1, 6), "k2": round(p.k2, 6),
        "resolution_px": list(p.resolution_px),
    }
    for key, value in values.items():
        if isinstance(value, list):
            if isinstance(entry.get(key), CommentedSeq):
                entry[key][:] = value
            else:
                entry[key] = _flow(CommentedSeq(value))
        else:
            entry[key] = value
    return entry


def _write_cameras(out: Path, source: Path, params: CameraParams, current: list[CameraParams]) -> None:
    """Put camera ``params`` into cameras.yaml ``out`` (an existing file is updated, a new one
    starts from ``source``) with ``layout: list``: an entry of the same id is updated in place,
    every other line and comment stays; a file that was on the automatic layout gets the other
    cameras in force (``current``) listed too, so that none is lost."""
    doc = _load_round_trip(out if out.exists() else source) if (out.exists() or source.exists()) else CommentedMap()
    was_list = doc.get("layout") == "list"
    doc["layout"] = "list"
    cams = doc.get("cameras")
    if not isinstance(cams, CommentedSeq) or not cams or cams.fa.flow_style():
        old = list(cams) if isinstance(cams, list) else []
        cams = CommentedSeq(old)
        doc["cameras"] = cams
    if not was_list:  # the automatic cameras were in force: keep them, as calibrated so far
        for other in current:
            if other.id != params.id and not any(isinstance(c, dict) and c.get("id") == other.id for c in cams):
                cams.append(_camera_map(other))
    for entry in cams:
        if isinstance(entry, dict) and entry.get("id") == params.id:
            _camera_map(params, entry)
            break
    else:
        cams.append(_camera_map(params))
    order = sorted(cams, key=lambda c: int(c.get("id", 0)) if isinstance(c, dict) else 0)
    cams[:] = order
    _write_round_trip(doc, out, _check_cameras)


def _check_cameras(data: dict[str, Any], path: Path) -> None:
    """An edited cameras.yaml parses (raises ConfigError otherwise)."""
    from cmdragons.config import parse

    parse(CamerasParams, data, file=path)


def _tune(args: argparse.Namespace, settings: object) -> int:
    from vision.tune import learn_boxes, read_labels, samples_from_labels, samples_from_truth

    vis = settings.vision  # type: ignore[attr-defined]
    first = Path(args.images[0])
    background: dict[str, np.ndarray] = {}
    light: dict[str, tuple[float, float]] = {}
    samples: dict[str, list[np.ndarray]]
    if args.auto:
        samples, background, light = _auto_samples(args, settings)
    elif args.labels is None:
        if not (first.is_dir() and (first / "truth.jsonl").exists()):
            raise ValueError("give --labels, or recording folders with truth.jsonl")
        roles = {r: getattr(vis.roles, r) for r in ("ball", "blue", "yellow", "pink", "green")}
        samples = {}
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
    boxes, warnings = learn_boxes(samples, background, light, vis.colours, vis.colour_space, args.margin,
                                  saturation_reach=vis.light.saturation_reach, max_overlap=vis.auto_tune.max_overlap)
    for line in warnings:
        print(f"tune: warning: {line}", file=sys.stderr)
    changed = {n for n, b in boxes.items() if n in samples or b != vis.colours.get(n)}
    source = settings.config_dir / "vision.yaml"  # type: ignore[attr-defined]
    out = Path(args.out) if args.out else source
    doc = _load_round_trip(out if out.exists() else source)
    colours = doc.setdefault("colours", CommentedMap())
    for name, box in ((n, boxes[n]) for n in boxes if n in changed):
        n = sum(len(p) for p in samples.get(name, []))
        entry = colours.get(name)
        was = f"lo {list(entry['lo'])} hi {list(entry['hi'])}" if entry and "lo" in entry and "hi" in entry else "(new)"
        why = f"{n:7d} {'sampled' if args.auto else 'labelled'} pixels" if n else "  kept apart from the others"
        print(f"tune: {name:8s} {why}: {was} -> lo {list(box.lo)} hi {list(box.hi)}")
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


def _auto_samples(args: argparse.Namespace,
                  settings: Any) -> tuple[dict[str, list[np.ndarray]], dict[str, np.ndarray],
                                          dict[str, tuple[float, float]]]:
    """``tune --auto``: samples per colour name from the frames given, the background's, and per
    colour name the light's spread its box must reach."""
    from cmdragons.camera import CameraModel
    from cmdragons.videoio import read_video, video_info
    from vision.tune import auto_samples

    images: list[np.ndarray] = []
    for name in args.images:
        img = cv2.imread(name, cv2.IMREAD_COLOR)
        if img is not None:
            images.append(np.asarray(img, dtype=np.uint8))
            continue
        info = video_info(name)  # a video: --frames frames spread over its first 3 s
        span = int(3.0 * (info["fps"] or 30.0))
        if info["frames"]:
            span = min(span, info["frames"])
        for k, frame in read_video(name):
            if k >= span or len(images) >= args.frames:
                break
            if k % max(1, span // args.frames) == 0:
                images.append(frame)
    if not images:
        raise ValueError(f"{', '.join(args.images)}: no frame could be read")
    models = {m.id: m for m in settings.camera_models()}
    if args.camera not in models:
        raise ValueError(f"camera {args.camera} is not in cameras.yaml: calibrate it first (vision calibrate)")
    params = models[args.camera].params
    h, w = images[0].shape[:2]
    if (w, h) != tuple(params.resolution_px):
        s = w / params.resolution_px[0]
        if abs(h / params.resolution_px[1] - s) > 1e-3:
            raise ValueError(f"the frames are {w}x{h} px, camera {args.camera} is {params.resolution_px[0]}x"
                             f"{params.resolution_px[1]}: calibrate it at this size (vision calibrate --lines)")
        params = dataclasses.replace(params, resolution_px=(w, h), focal_px=params.focal_px * s,
                                     principal_point_px=(params.principal_point_px[0] * s,
                                                         params.principal_point_px[1] * s))
    vis = settings.vision
    rep = auto_samples(images, CameraModel(params), settings.field, vis.colour_space, vis.auto_tune)
    print(f"tune: --auto: {len(images)} frame(s): {rep.patterns} robot patterns, {rep.balls} balls found")
    names = {role: getattr(vis.roles, role) for role in ("ball", "blue", "yellow", "pink", "green")}
    for role, n in rep.left_out.items():
        print(f"tune: --auto: {n} blob(s) taken for {role} ({names[role]}) left out: their hue is more than "
              f"{vis.auto_tune.max_hue_off_deg:g} deg off the others' (auto_tune.max_hue_off_deg)", file=sys.stderr)
    for role in names:
        if role not in rep.samples:
            print(f"tune: --auto: nothing seen of {role} ({names[role]}): its box stays as it is", file=sys.stderr)
    return ({names[r]: parts for r, parts in rep.samples.items()}, rep.background,
            {names[r]: v for r, v in rep.light.items()})


def _yaml() -> YAML:
    rt = YAML(typ="rt")
    rt.preserve_quotes = True
    rt.width = 4096  # never fold a long comment line
    rt.representer.add_representer(float, _represent_float)
    return rt


def _represent_float(representer: Any, value: float) -> Any:
    """Floats in plain decimals: ``-4e-05`` is a string to YAML 1.1 readers (PyYAML), ``-0.00004``
    a number to every reader."""
    text = f"{value:.7f}".rstrip("0")
    return representer.represent_scalar("tag:yaml.org,2002:float", text + "0" if text.endswith(".") else text)


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
