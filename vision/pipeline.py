"""One camera image -> one :class:`~cmdragons.messages.DetectionFrame`: CMVision regions, then
robot patterns and the ball (Bruce's thesis, appendix A), then the field mask: nothing further
past the field lines than ``field_margin_m`` (default the boundary width, the walls) is reported.

:class:`VisionParams` is ``configs/vision.yaml``: the colour space, the colour classes (threshold
boxes), which class plays which role, and the region, pattern and ball parameters.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from cmdragons.camera import CameraModel
from cmdragons.config import Validated
from cmdragons.geometry import TEAMS, Field, LeagueParams, Team
from cmdragons.messages import DetectionFrame
from vision import _kernels as kern
from vision.cmvision import (
    MAX_CLASSES,
    ColourClass,
    ColourSpace,
    RegionParams,
    Regions,
    Segmenter,
    SplitRule,
)
from vision.light import LightFollower, LightParams
from vision.patterns import BallParams, PatternMatcher, PatternParams, RegionGeometry, detect_ball
from vision.tune import AutoTuneParams

__all__ = ["ColourRoles", "VisionParams", "VisionPipeline", "default_colours"]


def default_colours() -> dict[str, ColourClass]:
    """Boxes (YUV) for the simulator's default colours, derived by ``cmdragons vision tune`` (margin
    16) from recordings with truth (seed 11, not the bench's): 2 s at the bench's low, default and
    high noise levels and 6 s at the default level (a kick: a moving, blurred ball), each recorded
    lossless (PNG) and as H.264 in 4:2:0 at crf 18 and 23; one set of boxes for lossless and
    compressed frames alike (4:2:0 pulls a small dot's chroma toward
    grey, so the boxes reach further toward it than lossless frames alone would ask)."""
    return {
        "orange": ColourClass(lo=(80, 40, 147), hi=(165, 112, 221), min_area_px=6),
        "blue": ColourClass(lo=(63, 155, 45), hi=(131, 223, 108), min_area_px=6),
        "yellow": ColourClass(lo=(157, 0, 122), hi=(238, 74, 181), min_area_px=6),
        "pink": ColourClass(lo=(99, 118, 151), hi=(181, 183, 226), min_area_px=6),
        "green": ColourClass(lo=(112, 46, 30), hi=(200, 119, 108), min_area_px=6),
    }


@dataclass(frozen=True)
class ColourRoles(Validated):
    """Which colour class is which part of the scene (names under ``colours``)."""

    ball: str = "orange"
    blue: str = "blue"  # team colour of the blue team's centre dot
    yellow: str = "yellow"
    pink: str = "pink"  # id dots
    green: str = "green"


@dataclass(frozen=True)
class VisionParams(Validated):
    """configs/vision.yaml."""

    colour_space: ColourSpace = "yuv"  # the space the colour boxes are given in
    colours: Mapping[str, ColourClass] = field(default_factory=default_colours)  # at most 32; order is priority
    roles: ColourRoles = ColourRoles()
    regions: RegionParams = RegionParams()
    patterns: PatternParams = PatternParams()
    ball: BallParams = BallParams()
    light: LightParams = LightParams()  # colour classes that follow the light, per cell of a grid
    auto_tune: AutoTuneParams = AutoTuneParams()  # what ``tune --auto`` takes for a marker, a dot and a ball
    # height of the pattern plane per team, m; a team left out: the robot height of configs/field.yaml
    robot_height_m: Mapping[Team, float] = field(default_factory=dict)
    # the field mask: a detection further than this past the field lines is dropped (m; null: the
    # boundary width of configs/field.yaml, the walls; a negative value: no mask)
    field_margin_m: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if len(self.colours) > MAX_CLASSES:
            raise ValueError(f"colours: at most {MAX_CLASSES} colour classes, got {len(self.colours)}")
        for role in ("ball", "blue", "yellow", "pink", "green"):
            name = getattr(self.roles, role)
            if name not in self.colours:
                raise ValueError(
                    f"roles.{role}: unknown colour {name!r}; colours defined: {', '.join(self.colours) or 'none'}"
                )
        if self.field_margin_m is not None and self.field_margin_m > 20.0:
            raise ValueError(f"field_margin_m must be at most 20 m (negative: no mask), got {self.field_margin_m}")
        for team, h in self.robot_height_m.items():
            if not 0.01 <= h <= 1.0:
                raise ValueError(f"robot_height_m.{team} must be 0.01 to 1.0 m, got {h}")


class VisionPipeline:
    """Detections of one camera: construct once per camera, then :meth:`process` each frame."""

    def __init__(self, params: VisionParams, league: LeagueParams, camera: CameraModel) -> None:
        self.params, self.league, self.camera = params, league, camera
        roles = params.roles
        names = list(params.colours)
        self.classes = {role: names.index(getattr(roles, role)) for role in ("ball", "blue", "yellow", "pink", "green")}
        self.grid = camera.pixel_rays_grid()
        # an id dot's radius in the image (at the nadir: the scale changes little over a frame)
        depth = camera.center[2] - league.robot.height_m
        self.dot_radius_px = league.pattern.id_dot_diameter_m / 2 * camera.f / depth
        # id-dot regions larger than any dot can look anywhere in the image are split (a dot joined
        # to a light segment of its colour on a real cover)
        dot_px = math.pi * (league.pattern.id_dot_diameter_m / 2) ** 2 / (self._smallest_pixel_area() * depth**2)
        max_area = np.full(len(names), np.inf)
        max_area[[self.classes["pink"], self.classes["green"]]] = params.patterns.max_area_fraction * dot_px
        split = SplitRule(max_area, open_radius_px=0.6 * self.dot_radius_px)
        self.segmenter = Segmenter(params.colours, params.colour_space, params.regions, split)
        self.heights: dict[Team, float] = {t: params.robot_height_m.get(t, league.robot.height_m) for t in TEAMS}
        self.matcher = PatternMatcher(league.pattern, params.patterns)
        dots = np.array(league.pattern.dot_positions_m)
        self.pattern_radius_m = float(np.max(np.hypot(dots[:, 0], dots[:, 1]))) + league.pattern.id_dot_diameter_m / 2
        f = Field(league)
        margin = f.dims.boundary_width_m if params.field_margin_m is None else params.field_margin_m
        # half extents of the field mask (inf: none)
        self.mask_half_m = (f.half_length + margin, f.half_width + margin) if margin >= 0.0 else (math.inf, math.inf)
        self.goal_half_m = (f.half_length + f.dims.goal_depth_m, f.goal_half_width)  # inside both goals
        self.last_regions: Regions | None = None
        self.light: LightFollower | None = None
        self.lift_where: NDArray[np.bool_] | None = None
        if params.light.follow:
            self.light = LightFollower(params.light, league, camera, self.heights)
            if params.light.measure == "carpet" and math.isfinite(self.mask_half_m[0]):
                self.lift_where = self._lift_where(params.light.carpet_band_px)

    def _lift_where(self, band_px: int) -> NDArray[np.bool_]:
        """(bands of rows, width) bool: where the carpet's lift applies, the bands of ``band_px``
        rows (as many in each row of the light's cells) and the columns holding a pixel that sees
        the field mask or a goal at the carpet's level; the floor past it is not the carpet and is
        taken as it is (lifted, a wooden floor passes for pink)."""
        g = self.grid.astype(np.float64)
        c = self.camera.center
        ax, ay = np.abs(c[0] + c[2] * g[..., 0]), np.abs(c[1] + c[2] * g[..., 1])
        (mx, my), (gx, gy) = self.mask_half_m, self.goal_half_m
        inside = ((ax <= mx) & (ay <= my)) | ((ax <= gx) & (ay <= gy))
        h = self.camera.height
        ny = self.params.light.grid[1]
        nb = ny * max(1, math.ceil(h / ny / band_px))
        band = np.minimum(np.arange(h) * nb // h, nb - 1)
        out = np.zeros((nb, self.camera.width), dtype=bool)
        np.logical_or.at(out, band, inside)
        return out

    def _smallest_pixel_area(self) -> float:
        """The smallest field area of one pixel per metre of descent squared over the image (where
        objects look largest), from the ray grid sampled every 8 pixels."""
        g = self.grid[::8, ::8].astype(np.float64)
        du, dv = (g[:-1, 1:] - g[:-1, :-1]) / 8.0, (g[1:, :-1] - g[:-1, :-1]) / 8.0
        return float(np.min(np.abs(du[..., 0] * dv[..., 1] - du[..., 1] * dv[..., 0])))

    def in_field(self, x: float, y: float) -> bool:
        """Whether field point (x, y) m lies inside the field mask (the field lines plus the margin)."""
        return abs(x) <= self.mask_half_m[0] and abs(y) <= self.mask_half_m[1]

    def ball_in_field(self, x: float, y: float) -> bool:
        """Whether a ball centred at (x, y) m lies inside the field mask or inside a goal (a ball in
        the goal is a goal; a lab's field between walls has its goals past the mask): a ball at the
        mask's edge (a wall) or at a goal's back or side has its centre a radius inside it."""
        r = self.league.ball.radius_m
        ax, ay = abs(x), abs(y)
        return (ax <= self.mask_half_m[0] - r and ay <= self.mask_half_m[1] - r) or \
            (ax <= self.goal_half_m[0] - r and ay <= self.goal_half_m[1] - r)

    @property
    def shape(self) -> tuple[int, int, int]:
        return (self.camera.height, self.camera.width, 3)

    def process(self, image: NDArray[np.uint8], frame_number: int, t_capture: float) -> DetectionFrame:
        """Ball and robots (field frame, m, rad) in ``image`` (H, W, 3) BGR uint8 of this camera.

        Raises ValueError for an image of the wrong shape or type (callers that read frames from
        disk check first and count such frames).
        """
        if image.shape != self.shape or image.dtype != np.uint8:
            raise ValueError(f"camera {self.camera.id}: expected a uint8 image of shape {self.shape}, "
                             f"got {image.dtype} {image.shape}")
        regions = self.segmenter.regions(image)
        self.last_regions = regions
        geo = RegionGeometry(regions, self.camera, self.grid)
        robots = self.matcher.detect(geo, self.classes, self.heights, lambda px: self._is_pink(image, px))
        # a ball seen beside a robot lies outside its top: only a misread marker is well inside
        balls = detect_ball(geo, image, self.classes["ball"], self.league.ball.radius_m, robots, self.heights,
                            self.pattern_radius_m * 0.8, self.params.ball, self.ball_in_field)
        robots = [r for r in robots if self.in_field(r.x, r.y)]
        if self.light is not None:
            gains = self.light.observe(image, robots, balls)
            if gains is not None:
                self.segmenter.set_light(gains, self.camera.width, self.camera.height, self.lift_where)
        # no wall clock here: the frame is "sent" at its capture time (latency is the runtime's)
        return DetectionFrame(self.camera.id, frame_number, t_capture, t_capture, tuple(balls),
                              tuple(sorted(robots, key=lambda r: (r.team, r.id))))

    def _is_pink(self, image: NDArray[np.uint8], pixel: NDArray[np.float64]) -> bool | None:
        """The id-dot colour at ``pixel`` (u, v): the mean colour of the pixels within 0.7 of the
        dot's radius, pink or green by which box's centre is nearer in the two colour channels
        (each box's half-width the unit); None off the image or more than two half-widths from
        both, or where the two are nearly as far (a colour between them: a dot hidden under
        something grey or white, or washed out). A mean over the dot rather than a vote of
        thresholded pixels: 4:2:0 video pulls a small dot's pixels out of their box (toward the
        black cover), but keeps its mean colour on its side of grey."""
        if not np.all(np.isfinite(pixel)):
            return None
        r = max(1.0, 0.7 * self.dot_radius_px)
        j0, j1 = int(pixel[0] - r), int(pixel[0] + r) + 1
        i0, i1 = int(pixel[1] - r), int(pixel[1] + r) + 1
        if not (0 <= i0 and i1 <= image.shape[0] and 0 <= j0 and j1 <= image.shape[1]):
            return None
        v, u = np.mgrid[i0:i1, j0:j1] + 0.5
        inside = (u - pixel[0]) ** 2 + (v - pixel[1]) ** 2 <= r * r
        yuv = self.params.colour_space == "yuv"
        # the kernels' conversion (the same as convert_colour's, without its per-call overhead)
        if self.light is None:
            mean = kern.channels(image[i0:i1, j0:j1][inside][None], yuv)[0].mean(axis=0)
        else:  # as the classes see it, its cell's gains applied
            bgr = self.light.corrected(image[i0:i1, j0:j1][inside].astype(np.float64).mean(axis=0),
                                       (float(pixel[0]), float(pixel[1])))
            px = np.minimum(np.maximum(np.round(bgr), 0.0), 255.0).astype(np.uint8)
            mean = kern.channels(px[None, None], yuv)[0, 0].astype(np.float64)
        reach = []
        for role in ("pink", "green"):
            box = self.params.colours[getattr(self.params.roles, role)]
            lo, hi = np.array(box.lo[1:], dtype=np.float64), np.array(box.hi[1:], dtype=np.float64)
            reach.append(float(np.max(np.abs(mean[1:] - (lo + hi) / 2.0) / np.maximum((hi - lo) / 2.0, 1.0))))
        if min(reach) > 2.0 or min(reach) > 0.75 * max(reach):
            return None
        return reach[0] < reach[1]
