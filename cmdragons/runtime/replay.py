"""A run's MCAP log back on the bus: ``cmdragons replay LOG.mcap``.

Every message of the bus's own schemas is published again on its topic, in log-time order, paced
at the log's time stamps (the simulation's capture times) divided by ``speed``, so a team node, a
viewer or the tracker runs against a recorded match as it ran against the live one. The replay
speaks as the match's clock does: it answers a node's ``ready`` with ``start`` and tells every node
to ``stop`` at the end. A replay from ``start_s`` on first publishes the last game state before it,
so that a team knows the game's state from the first frame.

Topics the log holds but the bus has no message for (Foxglove's scene) and the stages' summaries
are left out; ``skip`` leaves out more (the commands of a team that plays live against the log).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cmdragons.messages import NodeControl
from cmdragons.runtime.bus import Transport
from cmdragons.runtime.log import LogError, log_channels, log_span, read_log
from cmdragons.runtime.topics import topic_matches

__all__ = ["ReplayResult", "replay", "replay_span", "replay_topics"]

NEVER_REPLAYED = ("summary/*", "control/*", "clock")  # a run's end figures, and the runtime's own word
STATE_TOPICS = ("referee",)  # replayed from a later start: the last message before it comes first
_POLL_S = 0.05  # longest wait (s) between two deliveries of what the nodes say while pacing


@dataclass(frozen=True)
class ReplayResult:
    """What a replay did: messages published, the log time span replayed (s), whether it was cut short."""

    messages: int
    first_s: float
    last_s: float
    interrupted: bool


def replay_topics(path: str | Path, skip: Sequence[str] = ()) -> list[str]:
    """The bus topics of a log that a replay publishes (without the log's leading ``/``)."""
    from cmdragons.runtime.wire import is_known

    channels = log_channels(path)
    topics = sorted(t.lstrip("/") for t, schema in channels.items() if is_known(schema))
    return [t for t in topics if not any(topic_matches(p, t) for p in (*NEVER_REPLAYED, *skip))]


def replay_span(path: str | Path, start_s: float) -> tuple[float, float]:
    """The log times (s) of the log's first and last message, once it is sure a replay can start
    ``start_s`` seconds after the first; :class:`~cmdragons.runtime.log.LogError` else."""
    first, last = log_span(path)
    if not 0 <= start_s <= last - first:
        raise LogError(f"{path}: --from {start_s:g} s is beyond the log's end ({last - first:.2f} s)")
    return first, last


def replay(path: str | Path, transport: Transport, start_s: float = 0.0, speed: float = 1.0,
           skip: Sequence[str] = (), wait_for: Collection[str] = (), wait_timeout_s: float = 60.0,
           should_stop: Callable[[], bool] = lambda: False,
           on_progress: Callable[[float, int], None] | None = None, now: Callable[[], float] = time.monotonic,
           sleep: Callable[[float], None] = time.sleep) -> ReplayResult:
    """Publish the log at ``path`` on ``transport`` from ``start_s`` seconds after its first
    message on, at ``speed`` times the log's pace (s of log per s of wall clock).

    ``wait_for``: nodes (``cmdragons node`` roles) to hear ``ready`` from before the first message,
    for at most ``wait_timeout_s`` (:class:`TimeoutError`). ``on_progress(t, n)``: called after each
    message with its log time (s) and the count so far. ``now``/``sleep``: the clock the pacing
    follows (s). :class:`~cmdragons.runtime.log.LogError` for a log that cannot be read, or a
    ``start_s`` beyond its end."""
    if not speed > 0:
        raise ValueError(f"speed must be above 0, got {speed}")
    first, last = replay_span(path, start_s)
    topics = ["/" + t for t in replay_topics(path, skip)]
    ready: set[str] = set()

    def on_control(_topic: str, c: Any) -> None:
        if c.command == "ready":
            ready.add(c.node)
            transport.publish("control/clock", NodeControl("clock", "start"))

    transport.subscribe("control/*", on_control)

    def wait_until(deadline: float) -> None:
        while (left := deadline - now()) > 0 and not should_stop():
            sleep(min(left, _POLL_S))
            transport.spin()

    t_wait = now()
    while not set(wait_for) <= ready:
        if should_stop():
            return ReplayResult(0, first + start_s, first + start_s, True)
        if now() - t_wait > wait_timeout_s:
            raise TimeoutError(f"nodes {', '.join(sorted(set(wait_for) - ready))} did not say ready within "
                               f"{wait_timeout_s:.0f} s")
        wait_until(now() + _POLL_S)
    t0 = first + start_s
    n = 0
    if start_s > 0:  # the game's state as it was at the start
        state: dict[str, tuple[str, Any]] = {}
        for topic, t, message in read_log(path, ["/" + s for s in STATE_TOPICS if "/" + s in topics]):
            if t >= t0:
                break
            state[topic] = (topic, message)
        for topic, message in state.values():
            transport.publish(topic.lstrip("/"), message)
            n += 1
    wall0 = now()
    t_last = t0
    for topic, t, message in read_log(path, topics, start_s=t0):
        wait_until(wall0 + (t - t0) / speed)
        if should_stop():
            break
        transport.publish(topic.lstrip("/"), message)
        transport.spin()
        n += 1
        t_last = t
        if on_progress is not None:
            on_progress(t, n)
    interrupted = should_stop()
    transport.publish("control/clock", NodeControl("clock", "stop"))
    transport.spin()
    return ReplayResult(n, t0, t_last, interrupted)
