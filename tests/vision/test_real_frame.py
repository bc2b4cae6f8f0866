"""The real lab frame of ../shared/realdata (a webcam over a taped lab field, six printed covers of
the blue team, one with a dot hidden under a white blob, orange 84 mm balls; hand-checked truth
beside it), read through a camera model and colour boxes written here by hand for that frame (a
downward camera 3 m up, 309 px/m on the carpet; boxes from the truth's dots, 1st to 99th
percentile widened by 12 grey levels). Skipped where ../shared is not there.

Tolerances: a cover within 15 px of its truth pixel (5 cm) with the right id, heading within 5°.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import cv2
import pytest

from cmdragons.camera import CameraModel, CameraParams
from cmdragons.geometry import LeagueParams
from vision.cmvision import ColourClass
from vision.pipeline import VisionParams, VisionPipeline

REALDATA = Path(__file__).resolve().parents[2].parent / "shared" / "realdata"
FRAME = REALDATA / "lab_frame_lights_on.jpg"

pytestmark = pytest.mark.skipif(not FRAME.exists(), reason=f"the real lab frame is not here ({FRAME})")

PX_PER_M, HEIGHT_M = 309.0, 3.0
CAMERA = CameraParams(id=0, position_m=(30.0 / PX_PER_M, 10.0 / PX_PER_M, HEIGHT_M), focal_px=PX_PER_M * HEIGHT_M,
                      principal_point_px=(960.0, 540.0), resolution_px=(1920, 1080))
COLOURS = {
    "orange": ColourClass(lo=(164, 38, 138), hi=(237, 79, 187), min_area_px=10),
    "blue": ColourClass(lo=(77, 165, 40), hi=(143, 210, 93), min_area_px=10),
    "yellow": ColourClass(lo=(250, 0, 0), hi=(255, 1, 1), min_area_px=10),  # no yellow team in the frame
    "pink": ColourClass(lo=(101, 112, 155), hi=(164, 160, 230), min_area_px=10),
    "green": ColourClass(lo=(147, 85, 66), hi=(217, 119, 111), min_area_px=10),
}


def _lab() -> LeagueParams:
    """The lab's field (5.3 x 3.4 m between the tape's outer edges, walls 0.12 m past them) and its
    84 mm balls."""
    base = LeagueParams()
    div = dataclasses.replace(base.divisions["B"], length_m=5.3, width_m=3.4, boundary_width_m=0.12)
    return dataclasses.replace(base, divisions={"B": div}, ball=dataclasses.replace(base.ball, radius_m=0.042))


def test_the_six_covers_and_the_balls_of_the_real_frame() -> None:
    image = cv2.imread(str(FRAME), cv2.IMREAD_COLOR)
    truth = json.loads((REALDATA / "ground_truth.json").read_text())[FRAME.name]
    base = VisionParams()
    # covers lying on the carpet; the lab's eight covers carry ids 0-7; a hidden dot allowed
    params = VisionParams(colours=COLOURS, robot_height_m={"blue": 0.01, "yellow": 0.01},
                          patterns=dataclasses.replace(base.patterns, min_dots=3, ids_in_play=tuple(range(8))),
                          ball=dataclasses.replace(base.ball, max_balls=8))
    det = VisionPipeline(params, _lab(), CameraModel(CAMERA)).process(image, 0, 0.0)
    assert len(det.robots) == 6
    for t in truth["robots"]:
        (r,) = [r for r in det.robots if math.hypot(r.pixel[0] - t["pixel"][0], r.pixel[1] - t["pixel"][1]) < 15.0]
        assert r.id == t["id"] and r.team == "blue", (t, r)
        assert abs(math.remainder(r.theta - math.radians(t["heading"]), 2 * math.pi)) < math.radians(5.0)
        # the cover with its dot hidden: read from the ids in play, at a lower confidence
        assert (r.confidence <= 0.5 * base.patterns.table_confidence) == ("note" in t)
    # the orange balls: on the field and in the left goal; nothing on the floor outside the field
    on_field, in_goal = truth["balls"][0]["pixel"], truth["balls"][1]["pixel"]
    assert sorted(min(math.hypot(b.pixel[0] - p[0], b.pixel[1] - p[1]) for p in (on_field, in_goal)) < 5.0
                  for b in det.balls) == [True, True]
