"""Safe navigation (Bruce 2006 ch. 5): Dynamics Safety Search, the dynamic window as its comparison,
and no safety as the baseline, behind ``make_safe(commands, world) -> commands``."""

from cmdragons.safety.base import CHANGED, KEPT, STOP_ASKED, STOPPED, Safety, SafetyResult, StaticObstacles
from cmdragons.safety.dss import DSSParams, DynamicsSafetySearch
from cmdragons.safety.dynamic_window import DynamicWindow, DynamicWindowParams
from cmdragons.safety.registry import SAFETY, NoSafety, SafetyParams, make_safety

__all__ = [
    "CHANGED",
    "KEPT",
    "SAFETY",
    "STOPPED",
    "STOP_ASKED",
    "DSSParams",
    "DynamicWindow",
    "DynamicWindowParams",
    "DynamicsSafetySearch",
    "NoSafety",
    "Safety",
    "SafetyParams",
    "SafetyResult",
    "StaticObstacles",
    "make_safety",
]
