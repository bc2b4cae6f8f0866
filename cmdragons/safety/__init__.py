"""Team safety (Bruce 2006 ch. 5): Dynamics Safety Search, and no safety as the baseline, behind
``make_safe(commands, world) -> commands``. (The dynamic window, §5.2, is a local navigator:
cmdragons/navigation/.)"""

from cmdragons.safety.base import CHANGED, KEPT, STOP_ASKED, STOPPED, Safety, SafetyResult
from cmdragons.safety.dss import DSSParams, DynamicsSafetySearch
from cmdragons.safety.registry import SAFETY, NoSafety, SafetyParams, make_safety

__all__ = [
    "CHANGED",
    "KEPT",
    "SAFETY",
    "STOPPED",
    "STOP_ASKED",
    "DSSParams",
    "DynamicsSafetySearch",
    "NoSafety",
    "Safety",
    "SafetyParams",
    "SafetyResult",
    "make_safety",
]
