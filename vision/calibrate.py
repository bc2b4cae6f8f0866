"""Camera calibration from pixel <-> field correspondences (field-line corners and intersections).

The pose comes first from ``cv2.solvePnP`` with the focal length guessed, converted to our
parameters (:func:`cmdragons.camera.params_from_opencv`); then every parameter of the shared
camera model (pose, focal length, k1, k2; the principal point optionally) is refined by least
squares on the reprojection error in pixels, through :class:`cmdragons.camera.CameraModel` itself.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from cmdragons.camera import CameraModel, CameraParams, params_from_opencv
from cmdragons.config import ConfigError
from vision.tune import read_yaml_any

__all__ = ["CalibrationResult", "calibrate", "read_correspondences"]


@dataclass(frozen=True)
class CalibrationResult:
    params: CameraParams
    rms_px: float  # reprojection error
    max_px: float


def read_correspondences(path: str | Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A YAML list of ``{pixel: [u, v], field: [x, y] or [x, y, z]}`` (metres; z 0 on the carpet)."""
    data: Any = read_yaml_any(path)
    items = data.get("points") if isinstance(data, dict) else data
    if not isinstance(items, list) or len(items) < 6:
        raise ConfigError(path, "points", "expected a list of at least 6 {pixel: [u, v], field: [x, y(, z)]}")
    px, xyz = [], []
    for k, item in enumerate(items):
        try:
            u, v = item["pixel"]
            f = [float(x) for x in item["field"]]
            px.append((float(u), float(v)))
            xyz.append((f[0], f[1], f[2] if len(f) > 2 else 0.0))
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise ConfigError(path, f"points[{k}]", f"bad point {item!r}: {exc}") from None
    return np.array(px), np.array(xyz)


def _model(x: NDArray[np.float64], base: CameraParams, fit_principal: bool, fit_height: bool) -> CameraModel:
    yaw, tx, ty, px, py, f, k1, k2 = x[:8]
    pz = x[8] if fit_height else base.position_m[2]
    rest = x[9:] if fit_height else x[8:]
    pp = (float(rest[0]), float(rest[1])) if fit_principal else base.principal_point_px
    return CameraModel(dataclasses.replace(
        base, position_m=(float(px), float(py), float(pz)), yaw_rad=float(yaw), tilt_x_rad=float(tx),
        tilt_y_rad=float(ty), focal_px=float(f), k1=float(k1), k2=float(k2), principal_point_px=pp,
    ))


def calibrate(pixels: NDArray[np.float64], field: NDArray[np.float64], guess: CameraParams,
              fit_principal: bool = False, fit_height: bool | None = None) -> CalibrationResult:
    """Fit one camera to correspondences ``pixels`` (n, 2) <-> ``field`` (n, 3), starting from
    ``guess`` (its resolution, focal length and principal point are the starting intrinsics).

    A camera looking straight down at points on one plane sees the same image from height h with
    focal length f as from k h with k f: the height cannot be fitted. ``fit_height`` None fits
    it only when the points span at least 0.5 m in height; otherwise the guess's height (a tape
    measure's) is kept and the focal length absorbs the scale.
    """
    if fit_height is None:
        fit_height = float(np.ptp(field[:, 2])) >= 0.5
    k = np.array([[guess.focal_px, 0, guess.principal_point_px[0]], [0, guess.focal_px, guess.principal_point_px[1]],
                  [0, 0, 1]])
    # OpenCV measures pixels from the centre of the top-left pixel; our model from its corner
    ok, rvec, tvec = cv2.solvePnP(field.astype(np.float64), (pixels - 0.5).astype(np.float64), k - [[0, 0, 0.5],
                                  [0, 0, 0.5], [0, 0, 0]], np.zeros(4), flags=cv2.SOLVEPNP_ITERATIVE)
    start = (
        params_from_opencv(np.asarray(rvec, np.float64).ravel(), np.asarray(tvec, np.float64).ravel(), guess)
        if ok
        else guess
    )
    if not fit_height:  # keep the measured height, scale the focal length to the solved distance
        scale = guess.position_m[2] / max(start.position_m[2], 0.3)
        start = dataclasses.replace(start, position_m=(*start.position_m[:2], guess.position_m[2]),
                                    focal_px=guess.focal_px * scale)
    x0 = [start.yaw_rad, start.tilt_x_rad, start.tilt_y_rad, *start.position_m[:2], start.focal_px, start.k1, start.k2]
    if fit_height:
        x0.append(start.position_m[2])
    if fit_principal:
        x0 += list(start.principal_point_px)

    def residual(x: NDArray[np.float64]) -> NDArray[np.float64]:
        err: NDArray[np.float64] = (_model(x, guess, fit_principal, fit_height).project(field) - pixels).ravel()
        return np.nan_to_num(err, nan=1e4)

    sol = least_squares(residual, np.array(x0, dtype=np.float64), x_scale="jac", method="trf")
    params = _model(sol.x, guess, fit_principal, fit_height).params
    err = np.hypot(*(CameraModel(params).project(field) - pixels).T)
    return CalibrationResult(params, float(np.sqrt(np.mean(err**2))), float(err.max()))
