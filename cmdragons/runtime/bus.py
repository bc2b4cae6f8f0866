"""Stages on topics: the bus, its transport, and what a stage is.

A stage takes messages from named topics and publishes messages to named topics, and nothing else;
no stage reads another's attributes. The bus subscribes each stage to its input topics over a
:class:`Transport` and times every call into it. The transport is the seam to a distributed runtime:
:class:`InProcessTransport` delivers in lock-step, first published first delivered, each message to
its subscribers in the order they subscribed, so the same inputs give the same run byte for byte; a
networked transport (:mod:`cmdragons.runtime.zenoh_transport`) implements the same calls and no
stage changes. Either delivers a message as it comes off the wire
(:func:`cmdragons.runtime.wire.canonical`: detections, world states and commands in the league's
32-bit floats), so a stage sees the same inputs whichever process its peers run in.

What a stage reads and writes is its :class:`~cmdragons.runtime.topics.Contract`; topic patterns
are those of :func:`~cmdragons.runtime.topics.topic_matches`.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from cmdragons.runtime.topics import Contract, topic_matches

__all__ = ["BaseStage", "Bus", "InProcessTransport", "Publish", "Stage", "Transport", "run_frames"]

Handler = Callable[[str, Any], None]
Publish = Callable[[str, Any], None]


class Transport(Protocol):
    """Moves messages from publishers to subscribers."""

    def publish(self, topic: str, message: Any) -> None: ...

    def subscribe(self, pattern: str, handler: Handler) -> None: ...

    def spin(self) -> int:
        """Deliver what is pending (in-process: until nothing is); returns how many deliveries."""
        ...

    def close(self) -> None: ...


class InProcessTransport:
    """Lock-step delivery in one process: a FIFO of published messages, delivered on :meth:`spin`."""

    def __init__(self) -> None:
        from cmdragons.runtime.wire import canonical

        self._canonical = canonical
        self._queue: deque[tuple[str, Any]] = deque()
        self._subs: list[tuple[str, Handler]] = []
        self._routes: dict[str, list[Handler]] = {}

    def publish(self, topic: str, message: Any) -> None:
        self._queue.append((topic, self._canonical(message)))

    def subscribe(self, pattern: str, handler: Handler) -> None:
        self._subs.append((pattern, handler))
        self._routes.clear()

    def _handlers(self, topic: str) -> list[Handler]:
        hs = self._routes.get(topic)
        if hs is None:
            hs = self._routes[topic] = [h for p, h in self._subs if topic_matches(p, topic)]
        return hs

    def spin(self) -> int:
        n = 0
        while self._queue:
            topic, message = self._queue.popleft()
            for handler in self._handlers(topic):
                handler(topic, message)
                n += 1
        return n

    def close(self) -> None:
        self._queue.clear()


class Stage(Protocol):
    """One part of the system on the bus.

    ``contract``: its name and the topics it reads and writes; ``inputs``: the topic patterns it
    reads (the contract's). ``start``: publish what it has before any input (a
    referee's first game state). ``on_message``: handle one input and publish the outputs.
    ``summarize``: publish its figures of the run so far (a :class:`~cmdragons.messages.StageSummary`
    on ``summary/<name>``)."""

    @property
    def contract(self) -> Contract: ...

    @property
    def name(self) -> str: ...

    @property
    def inputs(self) -> Sequence[str]: ...

    def start(self, publish: Publish) -> None: ...

    def on_message(self, topic: str, message: Any, publish: Publish) -> None: ...

    def summarize(self, publish: Publish) -> None: ...


class Bus:
    """The stages of a run over one transport, with the wall-clock time of each stage's calls.

    ``times`` holds the milliseconds spent since the last :meth:`take_times` per stage name and per
    ``<stage name>:<input pattern>``: what summaries and benchmarks read per frame."""

    def __init__(self, transport: Transport | None = None) -> None:
        self.transport: Transport = transport if transport is not None else InProcessTransport()
        self.stages: list[Stage] = []
        self.times: dict[str, float] = {}

    def add(self, stage: Stage) -> None:
        if any(s.name == stage.name for s in self.stages):
            raise ValueError(f"two stages named {stage.name!r} on one bus")
        self.stages.append(stage)
        for pattern in stage.inputs:
            self.transport.subscribe(pattern, self._timed(stage, pattern))

    def _timed(self, stage: Stage, pattern: str) -> Handler:
        times, name, publish = self.times, stage.name, self.transport.publish
        key = f"{name}:{pattern}"

        def handle(topic: str, message: Any) -> None:
            t0 = time.perf_counter()
            stage.on_message(topic, message, publish)
            ms = (time.perf_counter() - t0) * 1e3
            times[name] = times.get(name, 0.0) + ms
            times[key] = times.get(key, 0.0) + ms

        return handle

    def publish(self, topic: str, message: Any) -> None:
        self.transport.publish(topic, message)

    def start(self) -> None:
        for stage in self.stages:
            stage.start(self.transport.publish)
        self.transport.spin()

    def spin(self) -> int:
        return self.transport.spin()

    def tick(self, frame: int) -> None:
        """One frame of a lock-step set-up: the clock's tick, and all that follows it delivered."""
        from cmdragons.messages import Tick

        self.transport.publish("clock", Tick(frame))
        self.transport.spin()

    def summarize(self) -> None:
        for stage in self.stages:
            stage.summarize(self.transport.publish)
        self.transport.spin()

    def take_times(self) -> dict[str, float]:
        """Milliseconds per stage since the last call (and reset)."""
        out = dict(self.times)
        self.times.clear()
        return out

    def close(self) -> None:
        self.transport.close()


def run_frames(step: Callable[[int], None], n: int, should_stop: Callable[[], bool] = lambda: False,
               on_frame: Callable[[int], None] | None = None) -> int:
    """The frame loop of every set-up: ``step(i)`` for the frames 0 .. ``n`` - 1, ``on_frame(i)``
    after each, until ``should_stop()`` says so before a frame; the frames run."""
    for i in range(n):
        if should_stop():
            return i
        step(i)
        if on_frame is not None:
            on_frame(i)
    return n


class BaseStage:
    """Defaults for stages with nothing to start with or to summarize; name and inputs from the
    stage's contract."""

    contract: Contract = Contract("")

    @property
    def name(self) -> str:
        return self.contract.name

    @property
    def inputs(self) -> Sequence[str]:
        return self.contract.inputs

    def start(self, publish: Publish) -> None:
        return None

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        return None

    def summarize(self, publish: Publish) -> None:
        return None
