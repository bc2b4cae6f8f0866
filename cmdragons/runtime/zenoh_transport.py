"""The bus over eclipse-zenoh: the second :class:`~cmdragons.runtime.bus.Transport`, for stages in
separate processes (or machines).

A topic ``t`` is the key ``cmdragons/<field>/t``; a pattern ``p/*`` is ``cmdragons/<field>/p/**``.
Messages go as protobuf (:mod:`cmdragons.runtime.wire`); payloads from ``shm_min_bytes`` on (camera
frames) are written into zenoh's shared memory, so a same-host subscriber maps them instead of
copying them through a socket; a camera frame's image is copied once from its array into the
buffer, beside the message's header (:func:`~cmdragons.runtime.wire.encode_chunks`). Publishers
block rather than drop when a link is congested: a lock-step match must lose nothing. A topic that
no other node subscribes to is neither encoded nor sent (each topic's publisher is told by a
matching listener when a subscriber comes or goes).

Zenoh delivers on its own threads; this transport only queues there. :meth:`ZenohTransport.spin`
decodes and delivers in the calling thread, first received first delivered, each message to its
handlers in subscription order, as the in-process transport does. A node's own messages reach its
own stages without the network (as :func:`~cmdragons.runtime.wire.canonical` makes them, so they
equal what a remote stage gets). A message that does not decode is counted (:attr:`dropped`),
reported on stderr at most once per ``drop_report_interval_s``, and dropped.
"""

from __future__ import annotations

import queue
import sys
import threading
import time
from collections.abc import Callable, Iterable
from typing import Any, TextIO

from cmdragons.messages import MessageError
from cmdragons.runtime import wire
from cmdragons.runtime.bus import Handler
from cmdragons.runtime.params import RuntimeParams
from cmdragons.runtime.topics import ANY, Contract, topic_matches

__all__ = ["LATEST_ONLY", "RouterError", "ZenohTransport", "key_expr", "open_router", "round_trips"]


class RouterError(Exception):
    """The configured router cannot be listened on (another is there) or reached (none is)."""


def _open(params: RuntimeParams, role: str) -> Any:
    import zenoh

    try:
        return zenoh.open(params.zenoh.config(role))
    except zenoh.ZError:
        endpoint = params.zenoh.router
        if role == "router":
            raise RouterError(f"cannot listen on {endpoint} (runtime.zenoh.router): is a router running there "
                              "already?") from None
        raise RouterError(f"no zenoh router at {endpoint} (runtime.zenoh.router): start the match (or a node "
                          "with --router) first") from None


def open_router(params: RuntimeParams) -> Any:
    """A zenoh router session on the configured endpoint (the nodes are its clients); close it.
    :class:`RouterError` when the endpoint is taken."""
    return _open(params, "router")


# sensor streams: a stage that falls behind skips to the newest message of each topic instead of
# working through a backlog (in lock-step one message of each waits at a time, so none is skipped)
LATEST_ONLY: tuple[str, ...] = ("camera/*", "detections/*", "perception/*", "world/*")


def key_expr(prefix: str, pattern: str) -> str:
    """The zenoh key expression of a topic pattern under ``prefix`` (``cmdragons/<field>``)."""
    if pattern == "*":
        return f"{prefix}/**"
    if pattern.endswith("/*"):
        return f"{prefix}/{pattern[:-2]}/**"
    return f"{prefix}/{pattern}"


def _subsumes(a: str, b: str) -> bool:
    """Whether every topic of pattern ``b`` is a topic of pattern ``a``."""
    if a == "*":
        return True
    if a.endswith("/*"):
        return b.startswith(a[:-1])
    return a == b


class _Outlet:
    """One topic's publisher in this node, and whether a remote subscriber matches it: kept by a
    matching listener, so that a publish asks zenoh nothing (asking took 16-23 µs in a node, whose
    zenoh threads hold the session's tables at the time)."""

    def __init__(self, key: str, publisher: Any) -> None:
        self.key = key
        self.publisher = publisher
        self.encoding: Any = None  # the protobuf type of the topic's messages (set by the first)
        self.since = time.monotonic()  # when it was declared
        self.young = True  # until settle(): it may not know its subscribers yet
        self.heard = True
        self._known = False  # the listener has said so since the declaration
        self._lock = threading.Lock()
        self._listener = publisher.declare_matching_listener(self._changed)

    def _changed(self, status: Any) -> None:
        """Zenoh's thread: the matching status changed."""
        with self._lock:
            self.heard, self._known = bool(status.matching), True

    def settle(self) -> None:
        """The publisher has had its time to learn who subscribes: from now on :attr:`heard` is
        what the listener last said, or what the publisher says now if it has said nothing."""
        now = bool(self.publisher.matching_status.matching)  # (asked outside the lock the listener takes)
        with self._lock:
            if not self._known:  # (else the listener's word, as new as this or newer)
                self.heard, self._known = now, True
        self.young = False

    def close(self) -> None:
        self._listener.undeclare()
        self.publisher.undeclare()


class ZenohTransport:
    """Publish, subscribe and deliver over one zenoh session (a client of the configured router).

    ``session``: an open zenoh session to use (closed by the caller), else one is opened from
    ``params`` and closed by :meth:`close` (:class:`RouterError` when no router is there).
    ``name``: who this is, in reports."""

    def __init__(self, params: RuntimeParams, name: str = "node", session: Any = None,
                 err: TextIO | None = None) -> None:
        import zenoh

        self._zenoh = zenoh
        self.params = params
        self.name = name
        self.prefix = f"cmdragons/{params.field_name}"
        self._own = session is None
        self.session = _open(params, "client") if session is None else session
        self._queue: queue.SimpleQueue[tuple[str, Any, bool]] = queue.SimpleQueue()
        self._subs: list[tuple[str, Handler]] = []
        self._routes: dict[str, list[Handler]] = {}
        self._declared: dict[str, Any] = {}  # pattern -> zenoh subscriber (no two overlap)
        self._outlets: dict[str, _Outlet] = {}  # topic -> its publisher, declared on first use
        self._shm: Any = None
        self.dropped = 0
        self.superseded = 0  # messages a newer one of their topic overtook before delivery
        # topic patterns of which only the newest waiting message is delivered (a stage that falls
        # behind skips ahead, as a real team does; a logger keeps every message: ())
        self.latest_only: tuple[str, ...] = ()
        self.local_only: tuple[str, ...] = ()  # topic patterns published to this process's stages only
        # topic pattern -> the message type this node's stages read there (:meth:`expect`): how bytes
        # that come without their protobuf type (a client outside cmdragons) are read
        self._expected: list[tuple[str, type[Any]]] = []
        self.received = 0
        self.sent = 0  # messages put on the wire (a topic no other node hears is not)
        self.last_received = time.monotonic()
        self._err = err if err is not None else sys.stderr
        self._dropped_reported = 0
        self._last_report = -float("inf")

    # --- subscribing -------------------------------------------------------------------------

    def subscribe(self, pattern: str, handler: Handler) -> None:
        self._subs.append((pattern, handler))
        self._routes.clear()
        patterns = {p for p, _ in self._subs}
        wanted = {p for p in patterns if not any(q != p and _subsumes(q, p) for q in patterns)}
        for p in [p for p in self._declared if p not in wanted]:
            self._declared.pop(p).undeclare()
        for p in sorted(wanted - set(self._declared)):
            self._declared[p] = self.session.declare_subscriber(
                key_expr(self.prefix, p), self._receive, allowed_origin=self._zenoh.Locality.REMOTE)

    def expect(self, contracts: Iterable[Contract]) -> None:
        """Read bytes that come without their protobuf type (a client outside cmdragons, e.g. the
        league's RobotControl from a team's own code) as the type ``contracts`` read on their topic."""
        self._expected = [(p.topic, p.type) for c in contracts for p in c.reads if p.type is not ANY]

    def _receive(self, sample: Any) -> None:
        """Zenoh's thread: queue the raw payload (decoded in :meth:`spin`)."""
        topic = str(sample.key_expr)[len(self.prefix) + 1 :]
        self._queue.put((topic, (str(sample.encoding), sample.payload.to_bytes()), True))

    def _handlers(self, topic: str) -> list[Handler]:
        hs = self._routes.get(topic)
        if hs is None:
            hs = self._routes[topic] = [h for p, h in self._subs if topic_matches(p, topic)]
        return hs

    # --- publishing -----------------------------------------------------------------------------

    def publish(self, topic: str, message: Any) -> None:
        here = bool(self._handlers(topic))
        put = None if any(topic_matches(p, topic) for p in self.local_only) else self._sender(topic, message)
        if put is None:  # nobody else hears it: neither encoded nor sent
            if here:
                self._queue.put((topic, wire.canonical(message), False))
            return
        if here:
            local, chunks = wire.canonical_and_chunks(message)
            self._queue.put((topic, local, False))
        else:
            chunks = wire.encode_chunks(message)
        self.sent += 1
        size = sum(len(c) for c in chunks)
        zp = self.params.zenoh
        if zp.shared_memory and size >= zp.shm_min_bytes:
            put(self._in_shared_memory(chunks, size))
        else:
            put(chunks[0] if len(chunks) == 1 else b"".join(chunks))

    def _sender(self, topic: str, message: Any) -> Callable[[Any], None] | None:
        """How a message on ``topic`` goes out, or None when no other node hears it. A publisher
        learns who subscribes within ``settle_s`` (and drops what it is given before): until then
        the session's put, which routes by what the session knows already; after, the publisher's,
        which costs a quarter less, while a remote subscriber matches."""
        out = self._outlet(topic, message)
        if out.young and time.monotonic() - out.since < self.params.settle_s:
            z = self._zenoh
            return lambda payload: self.session.put(out.key, payload, encoding=out.encoding,
                                                    congestion_control=z.CongestionControl.BLOCK,
                                                    allowed_destination=z.Locality.REMOTE)
        if out.young:
            out.settle()
        return (lambda payload: out.publisher.put(payload, encoding=out.encoding)) if out.heard else None

    def reserve_shared_memory(self) -> None:
        """Make this node's shared-memory pool now (it is made on the first large payload otherwise,
        which then waits 0.1-0.2 s)."""
        if self._shm is None and self.params.zenoh.shared_memory:
            from zenoh import shm

            self._shm = shm.ShmProvider.default_backend(self.params.zenoh.shm_pool_mb << 20)

    def _in_shared_memory(self, chunks: tuple[bytes, ...], size: int) -> Any:
        """A shared-memory buffer holding ``chunks`` one after another (each copied once)."""
        from zenoh import shm

        self.reserve_shared_memory()
        buf = self._shm.alloc(size, policy=shm.BlockOn(shm.GarbageCollect()))
        at = 0
        for chunk in chunks:
            buf[at : at + len(chunk)] = chunk
            at += len(chunk)
        return buf

    def has_subscribers(self, topic: str) -> bool:
        """Whether a remote subscriber matches ``topic`` now (a peer is there to hear it)."""
        return bool(self._outlet(topic).publisher.matching_status.matching)

    def _outlet(self, topic: str, message: Any = None) -> _Outlet:
        """``topic``'s publisher; once a message is given, it also holds the message's protobuf
        type (a topic carries one type, the contracts say which) as the encoding its bytes go
        with: the receiving node decodes by it."""
        out = self._outlets.get(topic)
        if out is None:
            z = self._zenoh
            key = f"{self.prefix}/{topic}"
            pub = self.session.declare_publisher(key, congestion_control=z.CongestionControl.BLOCK,
                                                 allowed_destination=z.Locality.REMOTE)
            out = self._outlets[topic] = _Outlet(key, pub)
        if out.encoding is None and message is not None:
            out.encoding = self._zenoh.Encoding.APPLICATION_PROTOBUF.with_schema(wire.schema(message))
        return out

    # --- delivering ------------------------------------------------------------------------------

    def spin(self, timeout_s: float = 0.0) -> int:
        """Deliver what has come, waiting up to ``timeout_s`` for the first message; returns how many
        deliveries were made. Of a topic under :attr:`latest_only` only the newest message that is
        waiting is delivered; the older ones are counted (:attr:`superseded`) and dropped."""
        n = 0
        try:
            item = self._queue.get(timeout=timeout_s) if timeout_s > 0 else self._queue.get_nowait()
        except queue.Empty:
            return 0
        while True:
            batch = [item]
            while True:
                try:
                    batch.append(self._queue.get_nowait())
                except queue.Empty:
                    break
            newest = {topic: i for i, (topic, _, remote) in enumerate(batch)
                      if remote and any(topic_matches(p, topic) for p in self.latest_only)}
            for i, (topic, payload, remote) in enumerate(batch):
                if remote and newest.get(topic, i) != i:
                    self.superseded += 1
                    continue
                n += self._deliver(topic, payload, remote)
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return n

    def _deliver(self, topic: str, payload: Any, remote: bool) -> int:
        handlers = self._handlers(topic)
        if remote:
            self.received += 1
            self.last_received = time.monotonic()
            if not handlers:
                return 0
            encoding, data = payload
            try:
                payload = wire.decode(encoding.partition(";")[2] or self._expected_schema(topic), data)
            except MessageError as exc:
                self._drop(exc)
                return 0
        for handler in handlers:
            handler(topic, payload)
        return len(handlers)

    def _expected_schema(self, topic: str) -> str:
        for pattern, cls in self._expected:
            if topic_matches(pattern, topic):
                return wire.CODECS[cls].proto.DESCRIPTOR.full_name  # type: ignore[no-any-return]
        raise MessageError(f"{topic}: bytes without their type, and no stage here reads the topic as a message")

    def _drop(self, exc: MessageError) -> None:
        self.dropped += 1
        now = time.monotonic()
        if now - self._last_report >= self.params.drop_report_interval_s:
            new = self.dropped - self._dropped_reported
            print(f"{self.name}: dropped {new} undecodable message{'s' * (new != 1)} ({exc})", file=self._err)
            self._dropped_reported, self._last_report = self.dropped, now

    def wait_for(self, done: Callable[[], bool], timeout_s: float, poll_s: float = 0.05) -> bool:
        """Spin until ``done()`` or ``timeout_s`` passed; whether it is done."""
        end = time.monotonic() + timeout_s
        while not done():
            left = end - time.monotonic()
            if left <= 0:
                return False
            self.spin(min(poll_s, left))
        return True

    def close(self) -> None:
        for sub in self._declared.values():
            sub.undeclare()
        for out in self._outlets.values():
            out.close()
        self._declared.clear()
        self._outlets.clear()
        if self._own:
            self.session.close()


def _echo(config: str, prefix: str, ready: Any, done: Any) -> None:
    """The far end of :func:`round_trips` (its own process): every ping back as a pong."""
    import zenoh

    with zenoh.open(zenoh.Config.from_json5(config)) as session:
        pong = session.declare_publisher(f"{prefix}/pong")
        session.declare_subscriber(f"{prefix}/ping", lambda sample: pong.put(sample.payload))
        ready.set()
        done.wait(120.0)


def round_trips(params: RuntimeParams, messages: int, size_bytes: int, session: Any = None) -> list[float]:
    """zenoh alone (no protobuf, no stage): ``messages`` payloads of ``size_bytes`` to a client in
    another process (spawned), which puts each back from its callback; the round trips (ms). The
    pings go from ``session`` (the router's: one link each way, as between the sim node and a node),
    else from a client of the router of ``params`` (which must be open; two links each way)."""
    import json
    import multiprocessing
    import threading

    import zenoh

    prefix = f"cmdragons/{params.field_name}/floor"
    ctx = multiprocessing.get_context("spawn")  # never fork a process that has zenoh open
    ready, done = ctx.Event(), ctx.Event()
    echo = ctx.Process(target=_echo, args=(json.dumps(params.zenoh.session("client")), prefix, ready, done))
    echo.start()
    rtt: list[float] = []
    own = session is None
    pinger = zenoh.open(params.zenoh.config("client")) if own else session
    back = threading.Event()
    pong = pinger.declare_subscriber(f"{prefix}/pong", lambda _s: back.set())
    ping: Any = pinger.declare_publisher(f"{prefix}/ping")  # (the stubs type matching_status wrongly)
    try:
        if not ready.wait(60.0):
            raise TimeoutError("the echo process never came up")
        for _ in range(500):  # its subscriber reaches this session
            if ping.matching_status.matching:
                break
            time.sleep(0.02)
        else:
            raise TimeoutError("the echo's subscriber never reached this session")
        time.sleep(0.2)  # its pong publisher's route reaches this session too
        payload = bytes(size_bytes)
        for _ in range(messages):
            back.clear()
            t0 = time.perf_counter()
            ping.put(payload)
            if back.wait(1.0):
                rtt.append((time.perf_counter() - t0) * 1e3)
            time.sleep(0.002)
    finally:
        done.set()
        echo.join(10)
        pong.undeclare()
        ping.undeclare()
        if own:
            pinger.close()
    return rtt
