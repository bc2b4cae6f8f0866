"""The auto-referee as stages: its own tracker over every camera's detections and the referee on it.

With an outside simulator our referee judges the tracked world (:class:`sim.autoref.AutoRef`) and
drives the match: its game state on ``referee`` (which the brains follow and
:class:`~cmdragons.runtime.ssl.stages.RefereeOutStage` sends as the league's Referee packets), its
calls on ``referee/events``, and with ``referee.place_by: teleport`` the teleports its restarts want
on ``teleport`` (what the outside simulator's table sends as its simulator's teleports); with
``place_by: robots`` the teams place the ball and it asks for no teleport. Watching passively (beside
the simulator's referee on the truth, to judge it) it writes the same under ``autoref/``, read by
nobody but the one judging it.

:func:`autoref_rows` gives a set-up's table its rows: the neutral tracker (``tracker/autoref`` ->
``world/autoref``, every detection, no team's commands, the estimate at capture time) and the
autoref stage.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from cmdragons.geometry import Team
from cmdragons.messages import GameEvents, GameState, StageSummary, Teleport, WorldState
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.stages import TrackerStage
from cmdragons.runtime.topics import Contract, Port, summary_port
from cmdragons.tracking import Tracker
from sim.autoref import AutoRef

if TYPE_CHECKING:
    from cmdragons.runtime.match import Entry
    from cmdragons.runtime.settings import Settings

__all__ = ["PASSIVE", "WORLD", "AutorefStage", "autoref_rows"]

WORLD = "world/autoref"  # the autoref's own tracked world
PASSIVE = "autoref/"  # the prefix of a passive autoref's topics


class AutorefStage(BaseStage):
    """The referee on ``world/autoref``: per world state, the game state, the frame's calls and a
    restart's teleport (``teleports``: when the referee may place the ball itself). ``prefix``: ""
    when it drives the match, :data:`PASSIVE` when it only watches."""

    @staticmethod
    def declare(prefix: str = "", teleports: bool = True) -> Contract:
        return Contract("autoref", (Port(WORLD, WorldState),),
                        (Port(prefix + "referee", GameState), Port(prefix + "referee/events", GameEvents,
                                                                       sometimes=True),
                         *((Port(prefix + "teleport", Teleport, sometimes=True),) if teleports else ()),
                         summary_port("autoref")))

    def __init__(self, autoref: AutoRef, prefix: str = "", teleports: bool = True) -> None:
        self.contract = self.declare(prefix, teleports)
        self.autoref = autoref
        self.prefix = prefix
        self.teleports = teleports

    def start(self, publish: Publish) -> None:
        teleport = self.autoref.start()
        if self.teleports:
            publish(self.prefix + "teleport", teleport)
        publish(self.prefix + "referee", self.autoref.state())

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        world: WorldState = message
        teleport = self.autoref.observe(world)
        if self.autoref.calls:
            publish(self.prefix + "referee/events", GameEvents(world.t, tuple(self.autoref.calls)))
        if teleport is not None and self.teleports:
            publish(self.prefix + "teleport", teleport)
        publish(self.prefix + "referee", self.autoref.state())

    def summarize(self, publish: Publish) -> None:
        publish(f"summary/{self.name}", StageSummary(self.name, self.autoref.summary()))


def _tracker(settings: Settings, detection_topics: Sequence[str]) -> TrackerStage:
    # the estimate at the capture time: a referee judges what was, not what will be; our simulator's
    # cameras capture together, SSL-Vision's packets each at their own time (as our team's tracker takes them)
    tracker = Tracker(dataclasses.replace(settings.tracker, latency_s=0.0))
    synchronized = settings.protocols.perception != "ssl_vision"
    return TrackerStage("autoref", tracker, detection_topics, take_commands=False, synchronized=synchronized)


def _autoref(settings: Settings, keys: Sequence[tuple[Team, int]], prefix: str, teleports: bool) -> AutorefStage:
    return AutorefStage(AutoRef(settings.field_geometry(), keys, settings.sim.referee), prefix, teleports)


def autoref_rows(settings: Settings, detection_topics: Sequence[str], keys: Sequence[tuple[Team, int]],
                 passive: bool = False) -> list[Entry]:
    """The autoref's rows of a set-up's table: its tracker over ``detection_topics`` (every camera's,
    taken in this order each frame) and the referee on it, for the match's robots ``keys`` (team,
    id). It drives the match (writes ``referee``, ``referee/events``, and ``teleport`` with
    ``sim.referee.place_by: teleport``), or with ``passive`` only watches (the same under
    ``autoref/``). Both run on the ``referee`` node. With ``protocols.referee.source:
    game_controller`` a real game controller referees (its packets through
    :class:`~cmdragons.runtime.ssl.stages.RefereeInStage`) and a driving autoref has no rows."""
    from cmdragons.runtime.match import Entry

    if settings.protocols.referee.source == "game_controller" and not passive:
        return []
    prefix = PASSIVE if passive else ""
    teleports = settings.sim.referee.place_by == "teleport"
    topics = tuple(detection_topics)
    return [Entry(TrackerStage.declare("autoref", topics, take_commands=False), "referee",
                  functools.partial(_tracker, settings, topics)),
            Entry(AutorefStage.declare(prefix, teleports), "referee",
                  functools.partial(_autoref, settings, tuple(keys), prefix, teleports))]
