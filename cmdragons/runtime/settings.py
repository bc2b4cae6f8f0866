"""All configuration concerns of a run, loaded together from one config folder.

``configs/<concern>.yaml`` for each concern below; a file left out takes its defaults, an unknown
file in the folder is an error (most likely a typo in its name). Each physical fact is configured
once: a parameter that needs one stated elsewhere (the robot's limits, the ball model, the command
latency) is a ``derived`` field, filled in from its source when the settings are loaded.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cmdragons.camera import CameraModel, CamerasParams, cameras_from_config
from cmdragons.config import ConfigError, apply_override, default_config_dir, load_yaml, parse, resolve_derived
from cmdragons.control.motion import ControlParams
from cmdragons.geometry import Field, LeagueParams
from cmdragons.planning.registry import PlannerParams
from cmdragons.runtime.params import RuntimeParams
from cmdragons.runtime.ssl.params import ProtocolParams
from cmdragons.safety.registry import SafetyParams
from cmdragons.team import TeamParams
from cmdragons.tracking.tracker import TrackerParams
from sim.params import SimParams
from strategy.plays import StrategyParams
from vision.pipeline import VisionParams

__all__ = ["CONCERNS", "TEAM_CONCERNS", "Settings", "load_settings", "load_team_settings"]

CONCERNS: dict[str, type] = {
    "field": LeagueParams,
    "cameras": CamerasParams,
    "sim": SimParams,
    "planner": PlannerParams,
    "control": ControlParams,
    "safety": SafetyParams,
    "tracker": TrackerParams,
    "strategy": StrategyParams,
    "team": TeamParams,
    "vision": VisionParams,
    "runtime": RuntimeParams,
    "protocols": ProtocolParams,
}

# the concerns a team may have its own of in a match (its brain and its tracker); the field, the
# simulator, the cameras and vision are the match's
TEAM_CONCERNS: tuple[str, ...] = ("planner", "control", "safety", "tracker", "strategy", "team")


@dataclass(frozen=True)
class Settings:
    config_dir: Path
    field: LeagueParams
    cameras: CamerasParams
    sim: SimParams
    planner: PlannerParams
    control: ControlParams
    safety: SafetyParams
    tracker: TrackerParams
    strategy: StrategyParams
    team: TeamParams
    vision: VisionParams
    runtime: RuntimeParams
    protocols: ProtocolParams

    def field_geometry(self) -> Field:
        return Field(self.field)

    def camera_models(self) -> list[CameraModel]:
        return cameras_from_config(self.cameras, self.field)


def load_settings(config_dir: str | Path | None = None, overrides: Sequence[str] = ()) -> Settings:
    """Load every concern from ``config_dir`` (default: see :func:`default_config_dir`) and apply
    ``--set`` overrides. Raises :class:`ConfigError` naming the file and key of any problem."""
    folder = Path(config_dir) if config_dir is not None else default_config_dir()
    if not folder.is_dir():
        raise ConfigError(folder, "", "config folder not found")
    for path in sorted(folder.glob("*.yaml")):
        if path.stem not in CONCERNS:
            raise ConfigError(path, "", f"unknown config file; allowed: {', '.join(f'{c}.yaml' for c in CONCERNS)}")
    raw: dict[str, dict[str, Any]] = {}
    files: dict[str, str] = {}
    for name in CONCERNS:
        path = folder / f"{name}.yaml"
        raw[name] = load_yaml(path) if path.exists() else {}
        files[name] = str(path)
    touched: dict[str, list[str]] = {}
    for assignment in overrides:
        apply_override(raw, assignment)
        touched.setdefault(assignment.partition(".")[0], []).append(assignment)
    parsed: dict[str, Any] = {}
    for name, cls in CONCERNS.items():
        origin = files[name]
        if name in touched:
            origin += " (with --set " + ", ".join(touched[name]) + ")"
        parsed[name] = parse(cls, raw[name], file=origin)

    def lookup(source: str) -> Any:
        concern, *path = source.split(".")
        value = parsed[concern]
        for part in path:
            value = getattr(value, part)
        return value

    # facts configured once (field.robot limits, the ball model, ...) filled in where they are used
    return Settings(config_dir=folder, **{name: resolve_derived(obj, lookup) for name, obj in parsed.items()})


def load_team_settings(config_dir: str | Path | None, overrides: Sequence[str], team_overrides: Sequence[str],
                       flag: str = "--opponent-set") -> Settings:
    """The settings of one team of a match: the match's (``config_dir`` with ``overrides``) with
    ``team_overrides`` on top, each of which must set a concern of :data:`TEAM_CONCERNS` (a team has
    its own brain and tracker, not its own field or simulator). Raises :class:`ConfigError` naming
    ``flag`` and the key."""
    for assignment in team_overrides:
        key = assignment.partition("=")[0]
        if key.partition(".")[0] not in TEAM_CONCERNS:
            raise ConfigError(flag, key, "a team's own config covers its brain and tracker only; allowed concerns: "
                              + ", ".join(TEAM_CONCERNS) + " (the match's field, sim, cameras and vision: --set)")
    return load_settings(config_dir, [*overrides, *team_overrides])
