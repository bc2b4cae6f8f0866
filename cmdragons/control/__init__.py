"""Motion control (Bruce 2006 appendix B.4): time-optimal trapezoidal profiles in 1D and 2D, the
per-robot velocity command for the next frame period, path following and latency compensation."""

from cmdragons.control.latency import LatencyCompensator
from cmdragons.control.motion import (
    ControlParams,
    MotionParams,
    MotionTarget,
    PathParams,
    follow_path,
    motion_command,
    motion_commands,
)
from cmdragons.control.trapezoid import Profile1D, Profile2D, TrapezoidParams, trapezoid_1d, trapezoid_2d

__all__ = [
    "ControlParams",
    "LatencyCompensator",
    "MotionParams",
    "MotionTarget",
    "PathParams",
    "Profile1D",
    "Profile2D",
    "TrapezoidParams",
    "follow_path",
    "motion_command",
    "motion_commands",
    "trapezoid_1d",
    "trapezoid_2d",
]
