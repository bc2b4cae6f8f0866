"""Topics and stage contracts: what each stage reads and writes, with the message each topic carries.

A stage states its contract once (:class:`Contract`: its name, the topics it reads and the topics it
writes, each a :class:`Port` with its message type), from the same arguments it is built with. A
set-up (the embedded match, a distributed node, replay, ...) is a table of contracts
(:func:`check_wiring` refuses one where a topic read has no writer, or is written with another
type than it is read with, naming both stages), and the topic reference of docs/architecture.md
(:func:`topic_table`, over the key space :func:`key_space`) is derived from the contracts, never
written again; the wire reads a message by the protobuf type it travels with, and a node takes the
type of plain bytes from an outside client from its stages' contracts.

Topic patterns: an exact topic (``world/blue``), a prefix ending in ``/*`` (``detections/*`` matches
``detections/0`` and ``detections/1``), or ``*`` for every topic.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["ANY", "Contract", "Port", "WiringError", "check_wiring", "key_space", "overlap", "summary_port",
           "topic_matches", "topic_table"]


def topic_matches(pattern: str, topic: str) -> bool:
    """Whether ``topic`` falls under ``pattern`` (exact, ``prefix/*`` or ``*``)."""
    if pattern == "*":
        return True
    if pattern.endswith("/*"):
        return topic.startswith(pattern[:-1])
    return pattern == topic


def overlap(a: str, b: str) -> bool:
    """Whether two topic patterns have a topic in common."""
    return topic_matches(a, b) or topic_matches(b, a) or (
        a.endswith("/*") and b.endswith("/*") and (a.startswith(b[:-1]) or b.startswith(a[:-1])))


class _Any:
    """The type of a port that takes every message (loggers, taps, viewers)."""

    def __repr__(self) -> str:
        return "ANY"


ANY: Any = _Any


@dataclass(frozen=True)
class Port:
    """One topic (or pattern) a stage reads or writes and the message type on it (:data:`ANY`: a
    reader that takes whatever comes). ``sometimes``: written only when something happens (a
    referee's call), not every frame."""

    topic: str
    type: Any
    sometimes: bool = False


@dataclass(frozen=True)
class Contract:
    """A stage's name, the topics it reads (in the order it subscribes, which fixes the order of
    delivery) and the topics it writes."""

    name: str
    reads: tuple[Port, ...] = ()
    writes: tuple[Port, ...] = ()

    @property
    def inputs(self) -> tuple[str, ...]:
        return tuple(p.topic for p in self.reads)


def summary_port(name: str) -> Port:
    """Where a stage publishes its figures of the run (``summary/<name>``)."""
    from cmdragons.messages import StageSummary

    return Port(f"summary/{name}", StageSummary)


class WiringError(ValueError):
    """A set-up whose stages do not fit: a topic read that no stage writes, or written with another type."""


def check_wiring(contracts: Sequence[Contract], outside: Iterable[Port] = ()) -> None:
    """Refuse a set-up whose contracts do not fit: every port read with a message type must be
    written by a stage (or come from ``outside``: the runtime's clock, a log being replayed, other
    processes) with that type; a pattern read (``commands/*``) needs one writer under it. Readers of
    :data:`ANY` take what comes. Raises :class:`WiringError` naming the reader, the topic and the
    writer."""
    writers = [(c.name, p) for c in contracts for p in c.writes] + [("outside", p) for p in outside]
    seen: dict[str, tuple[str, Any]] = {}
    for name, p in writers:
        if "*" in p.topic:
            continue
        other = seen.setdefault(p.topic, (name, p.type))
        if other[1] is not p.type:
            raise WiringError(f"topic {p.topic!r} is written as {p.type.__name__} by {name!r} and as "
                              f"{other[1].__name__} by {other[0]!r}")
    for c in contracts:
        for r in c.reads:
            if r.type is ANY:
                continue
            found = [(name, p) for name, p in writers if overlap(r.topic, p.topic)]
            if not found:
                raise WiringError(f"stage {c.name!r} reads topic {r.topic!r} ({r.type.__name__}), which no stage "
                                  "writes")
            for name, p in found:
                if p.type is not r.type:
                    raise WiringError(f"stage {c.name!r} reads topic {r.topic!r} as {r.type.__name__}, but stage "
                                      f"{name!r} writes {p.topic!r} as {p.type.__name__}")


def _pattern(topic: str) -> str:
    """A concrete topic's family: from its first part that names a camera or a team on (any part of
    a stage's summary), ``*``."""
    parts = topic.split("/")
    if parts[0] == "summary":
        return "summary/*"
    for i, part in enumerate(parts[1:], 1):
        if part.isdigit() or part in ("blue", "yellow"):
            return "/".join(parts[:i]) + "/*"
    return topic


def _key(topic: str) -> str:
    return topic if "*" in topic else _pattern(topic)


def key_space(contracts: Iterable[Contract]) -> tuple[tuple[str, Any], ...]:
    """Topic pattern -> message type of every topic the contracts write (a camera's, a team's or a
    stage's topics as one pattern), exact topics before the patterns that would take them."""
    out: dict[str, Any] = {}
    for c in contracts:
        for p in c.writes:
            key = _key(p.topic)
            if out.setdefault(key, p.type) is not p.type:
                raise WiringError(f"topics {key!r} carry two message types: {out[key].__name__} and "
                                  f"{p.type.__name__}")
    exact = sorted(k for k in out if "*" not in k)
    return tuple((k, out[k]) for k in [*exact, *sorted((k for k in out if "*" in k), key=lambda k: (-len(k), k))])


def topic_table(contracts: Iterable[Contract]) -> str:
    """The topic reference (markdown): each topic pattern, its message and the stages that write
    and read it (a camera's, a team's or a stage's topics as one pattern, stage names likewise)."""
    contracts = list(contracts)
    rows = []
    for key, cls in key_space(contracts):
        if key.startswith("summary/"):
            continue
        writers = sorted({_pattern(c.name) for c in contracts for p in c.writes if _key(p.topic) == key})
        readers = sorted({_pattern(c.name) for c in contracts for p in c.reads
                          if p.type is not ANY and _key(p.topic) == key})
        rows.append(f"| `{key}` | `{cls.__name__}` | {', '.join(writers)} | {', '.join(readers)} |")
    return "\n".join(["| topic | message | written by | read by |", "|---|---|---|---|", *rows,
                      "| `summary/<stage>` | `StageSummary` | every stage, on request | the match summary |"])
