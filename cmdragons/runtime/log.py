"""Run logs: ``logs/<time>-<command>/`` with an MCAP file of every message and a summary.json.

MCAP channels carry protobuf, each with its schema (the bus's wire form,
:mod:`cmdragons.runtime.wire`, and Foxglove's scene messages), so Foxglove opens a log as it is; log
times are the simulation's capture times, so the same config and seed give the same log, byte for
byte. :func:`read_log` reads one back as our messages.
"""

from __future__ import annotations

import datetime as _dt
import os
import shutil
import struct
from collections.abc import Collection, Iterator
from pathlib import Path
from typing import Any, BinaryIO

from mcap.writer import CompressionType, Writer

__all__ = ["RUN_FILES", "LogError", "OutputError", "RunLog", "check_writable_file", "log_channels", "log_info",
           "log_span", "read_log", "run_folder"]

# what a run writes into its folder (globs): a folder holding one of these holds a run
RUN_FILES = ("run.mcap", "summary.json", "match.mp4", "match_cameras.mp4", "report.png", "detections.jsonl",
             "tracks.jsonl", "truth.jsonl", "cameras.yaml", "camera_*", "annotated_camera_*")


class OutputError(Exception):
    """An output path that cannot be used; the message names the path, the problem and the fix."""


def run_folder(command: str, out: str | Path | None = None, logs: str | Path = "logs", overwrite: bool = False) -> Path:
    """``out`` if given, else a new ``logs/<YYYYmmdd-HHMMSS>-<command>`` folder, created.

    An ``out`` folder holding another run's files is refused (:class:`OutputError`) unless
    ``overwrite``, which deletes those files and folders (:data:`RUN_FILES`) and leaves any other
    file alone. A run log without a message (a run stopped before its first frame: nothing was
    played) is not a run: it is replaced without ``overwrite``."""
    if out is not None:
        folder = Path(out)
        if folder.exists() and not folder.is_dir():
            raise OutputError(f"--out {folder}: is a file, not a folder; give a new folder name")
        if folder.is_dir():
            old = sorted({p for pattern in RUN_FILES for p in folder.glob(pattern)})
            if old and not overwrite and any(p.name != "run.mcap" or holds_messages(p) for p in old):
                raise OutputError(f"--out {folder}: holds another run ({old[0].name}); give a new folder, "
                                  "or add --overwrite to replace that run")
            for p in old:
                if p.is_dir():
                    shutil.rmtree(p)
                else:
                    p.unlink()
            _check_folder_writable(folder)
            return folder
    else:
        stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
        folder = Path(logs) / f"{stamp}-{command}"
        n = 1
        while folder.exists():
            n += 1
            folder = Path(logs) / f"{stamp}-{command}-{n}"
    blocking = _file_in_the_way(folder.parent)
    if blocking is not None:
        raise OutputError(f"cannot create the output folder {folder}: {blocking} is a file, not a folder; "
                          "give another folder with --out DIR")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the output folder {folder} ({exc.strerror}); "
                          "give a writable one with --out DIR") from None
    _check_folder_writable(folder)
    return folder


def holds_messages(path: Path) -> bool:
    """Whether the MCAP file at ``path`` holds a message, read from its start (so a file cut
    short, without its summary, counts what it has); a file that is not MCAP holds none."""
    from mcap.exceptions import McapError
    from mcap.reader import NonSeekingReader

    with open(path, "rb") as f:
        try:
            for _ in NonSeekingReader(f).iter_messages():
                return True
        except (McapError, EOFError, ValueError, struct.error):
            pass
    return False


def _file_in_the_way(folder: Path) -> Path | None:
    """The nearest of ``folder`` and its parents that exists as something other than a folder."""
    for p in (folder, *folder.parents):
        if p.exists():
            return None if p.is_dir() else p
    return None


def _check_folder_writable(folder: Path) -> None:
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"cannot write into the output folder {folder} (permission denied); "
                          "give a writable one with --out DIR")


def check_writable_file(path: str | Path, option: str) -> Path:
    """``path`` as a file that can be written (its folder is created); else :class:`OutputError`
    naming ``option``. Called before a long run, so that its result is not lost at the end."""
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"{option} {p}: is a folder; give a file name in it, e.g. {p / 'out'}")
    blocking = _file_in_the_way(p.parent)
    if blocking is not None:
        raise OutputError(f"{option} {p}: {blocking} is a file, not a folder; give another path")
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{option} {p}: cannot create its folder {p.parent} ({exc.strerror}); "
                          "give a writable path") from None
    existed = p.exists()
    try:  # a real open, not os.access: root passes every permission check but still cannot write in /proc
        with open(p, "a" if existed else "x"):
            pass
    except OSError as exc:
        raise OutputError(f"{option} {p}: not writable ({exc.strerror}); give a writable path") from None
    if not existed:
        p.unlink()
    return p


class LogError(Exception):
    """A log that cannot be read (not MCAP, truncated, or a message without a known schema)."""


class RunLog:
    """An MCAP recording of protobuf messages on named topics, each channel with its schema."""

    def __init__(self, path: str | Path) -> None:
        from cmdragons.runtime import wire

        self._wire = wire
        self.path = Path(path)
        self._file: BinaryIO = open(self.path, "wb")  # noqa: SIM115
        self._writer = Writer(self._file, compression=CompressionType.ZSTD)
        self._writer.start(profile="", library="cmdragons")
        self._channels: dict[str, int] = {}
        self._schemas: dict[str, int] = {}
        self._sequence = 0

    def write(self, topic: str, t: float, message: Any) -> None:
        """One of the bus's messages at time ``t`` (s)."""
        self.write_proto(topic, t, self._wire.to_proto(message))

    def write_proto(self, topic: str, t: float, proto: Any) -> None:
        """A protobuf message at time ``t`` (s) (a channel's first message fixes its schema)."""
        channel = self._channels.get(topic)
        if channel is None:
            channel = self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding="protobuf", schema_id=self._schema(proto))
        ns = max(0, int(round(t * 1e9)))
        self._sequence += 1
        self._writer.add_message(channel_id=channel, log_time=ns, data=proto.SerializeToString(deterministic=True),
                                 publish_time=ns, sequence=self._sequence)

    def _schema(self, proto: Any) -> int:
        from mcap_protobuf.schema import register_schema

        name = proto.DESCRIPTOR.full_name
        if name not in self._schemas:
            self._schemas[name] = register_schema(self._writer, type(proto))
        return self._schemas[name]

    def close(self) -> None:
        if not self._file.closed:
            self._writer.finish()  # type: ignore[no-untyped-call]
            self._file.close()

    def __enter__(self) -> RunLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_log(path: str | Path, topics: Collection[str] | None = None,
             start_s: float | None = None) -> Iterator[tuple[str, float, Any]]:
    """``(topic, t, message)`` for every message of an MCAP log in log-time order, ``t`` in s: our
    messages for the bus's schemas, the protobuf objects for the rest (Foxglove's scene); only
    ``topics`` if given, only from ``start_s`` on if given. :class:`LogError` for a file that is not
    a readable log."""
    from google.protobuf import message_factory
    from google.protobuf.descriptor_pb2 import FileDescriptorSet
    from google.protobuf.descriptor_pool import DescriptorPool
    from google.protobuf.message import DecodeError
    from mcap.exceptions import McapError
    from mcap.reader import make_reader

    from cmdragons.messages import MessageError
    from cmdragons.runtime import wire

    known = {c.proto.DESCRIPTOR.full_name: c for c in wire.CODECS.values()}
    classes: dict[int, Any] = {}

    def message_class(schema: Any) -> Any:
        """Our generated class for the bus's schemas, else one built from the log's own schema."""
        if schema.id not in classes:
            if schema.encoding != "protobuf":
                raise LogError(f"{path}: schema {schema.name} is {schema.encoding}, not protobuf (an older log?)")
            if schema.name in known:
                classes[schema.id] = known[schema.name].proto
            else:
                pool = DescriptorPool()
                for fd in FileDescriptorSet.FromString(schema.data).file:
                    pool.Add(fd)
                classes[schema.id] = message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))
        return classes[schema.id]

    start_ns = None if start_s is None else int(round(start_s * 1e9))
    try:
        with open(path, "rb") as f:
            reader = make_reader(f)
            for schema, channel, m in reader.iter_messages(topics=None if topics is None else list(topics),
                                                           starting_at=start_ns, log_time_order=True):
                if schema is None:
                    raise LogError(f"{path}: topic {channel.topic} has no schema")
                proto = message_class(schema).FromString(m.data)
                message = wire.from_proto(proto) if schema.name in known else proto
                yield channel.topic, m.log_time / 1e9, message
    except (McapError, DecodeError, MessageError, OSError, struct.error, ValueError) as exc:
        raise LogError(f"{path}: not a readable log ({exc})") from None


def _summary(path: str | Path) -> Any:
    """The summary section of a finished MCAP log (with its statistics); :class:`LogError` else."""
    from mcap.exceptions import McapError
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as f:
            summary = make_reader(f).get_summary()
    except (McapError, OSError, struct.error, ValueError) as exc:
        raise LogError(f"{path}: not an MCAP log ({exc})") from None
    if summary is None or summary.statistics is None:
        raise LogError(f"{path}: the log has no summary (an unfinished run?)")
    return summary


def log_span(path: str | Path) -> tuple[float, float]:
    """The log times (s) of a log's first and last message; :class:`LogError` for a file that is
    not a finished MCAP log, or one without messages."""
    st = _summary(path).statistics
    if st.message_count == 0:
        raise LogError(f"{path}: the log holds no messages")
    return st.message_start_time / 1e9, st.message_end_time / 1e9


def log_channels(path: str | Path) -> dict[str, str]:
    """A finished MCAP log's topics, each with the name of its schema ("" for none);
    :class:`LogError` for a file that is not one."""
    summary = _summary(path)
    return {ch.topic: (s.name if (s := summary.schemas.get(ch.schema_id)) else "") for ch in summary.channels.values()}


def log_info(path: str | Path) -> list[str]:
    """Lines about an MCAP log: message count and duration, then per topic its count and schema.
    :class:`LogError` for a file that is not a finished MCAP log."""
    summary = _summary(path)
    st = summary.statistics
    lines = [f"{path}: {st.message_count} messages, {(st.message_end_time - st.message_start_time) / 1e9:.2f} s"]
    for cid, ch in sorted(summary.channels.items(), key=lambda kv: kv[1].topic):
        schema = summary.schemas.get(ch.schema_id)
        lines.append(f"  {ch.topic:28s} {st.channel_message_counts.get(cid, 0):7d}  {schema.name if schema else '-'}")
    return lines
