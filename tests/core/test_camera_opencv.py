"""The camera model against OpenCV's projection, through the (rvec, tvec) conversion."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest

from cmdragons.camera import CameraModel, CameraParams, opencv_extrinsics, params_from_opencv

CAMERAS = [
    CameraParams(),
    CameraParams(position_m=(-2.3, 0.4, 4.1), yaw_rad=-1.5708, tilt_x_rad=0.05, tilt_y_rad=-0.08, focal_px=611.0,
                 k1=-0.03, k2=0.004),
    CameraParams(position_m=(1.0, -1.0, 3.5), yaw_rad=2.8, tilt_x_rad=-0.2, tilt_y_rad=0.3, focal_px=900.0,
                 principal_point_px=(500.0, 390.0), k1=0.02),
]  # fmt: skip


@pytest.mark.parametrize("params", CAMERAS)
def test_opencv_projection_equals_the_model_and_the_pose_round_trips(params: CameraParams) -> None:
    model = CameraModel(params)
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(-1.5, 1.5, (50, 2)) + model.center[:2], rng.uniform(0, 0.2, 50)])
    rvec, tvec = opencv_extrinsics(model)
    k = np.array([[params.focal_px, 0, params.principal_point_px[0] - 0.5],
                  [0, params.focal_px, params.principal_point_px[1] - 0.5], [0, 0, 1]])
    cv_px, _ = cv2.projectPoints(pts, rvec, tvec, k, np.array([params.k1, params.k2, 0.0, 0.0]))
    np.testing.assert_allclose(cv_px.reshape(-1, 2) + 0.5, model.project(pts), atol=1e-6)
    back = params_from_opencv(rvec, tvec, dataclasses.replace(params, position_m=(0.0, 0.0, 1.0), yaw_rad=0.0))
    np.testing.assert_allclose(back.position_m, params.position_m, atol=1e-9)
    np.testing.assert_allclose([back.yaw_rad, back.tilt_x_rad, back.tilt_y_rad],
                               [params.yaw_rad, params.tilt_x_rad, params.tilt_y_rad], atol=1e-9)
