"""Motion control (Bruce 2006 appendix B.4): time-optimal trapezoidal profiles in 1D and 2D, the
per-robot velocity command for the next frame period, path following, the braking trajectory."""

from cmdragons.control.motion import (
    ControlParams,
    MotionParams,
    MotionTarget,
    PathParams,
    follow_path,
    motion_command,
    motion_commands,
    predict_braking,
)
from cmdragons.control.trapezoid import Profile1D, Profile2D, TrapezoidParams, trapezoid_1d, trapezoid_2d

__all__ = [
    "ControlParams",
    "MotionParams",
    "MotionTarget",
    "PathParams",
    "Profile1D",
    "Profile2D",
    "TrapezoidParams",
    "follow_path",
    "motion_command",
    "motion_commands",
    "predict_braking",
    "trapezoid_1d",
    "trapezoid_2d",
]
