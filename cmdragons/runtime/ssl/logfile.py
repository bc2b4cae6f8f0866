"""The league's game log files (SSL_LOG_FILE): read and write.

A file is the 12 bytes ``SSL_LOG_FILE``, a big-endian int32 version (1), then records: int64 receive
time (ns since the epoch), int32 message type, int32 payload size, the payload (the packet as it
came: an SSL_WrapperPacket, a Referee message, a TrackerWrapperPacket). A name ending in ``.gz`` is
gzip-compressed. A file may end with an index (the league's game-log description): a last record of
type ``INDEX_2021`` (its time stamp irrelevant; we write 0) whose payload is the int64 offset of every
record before it from the file's start, then the int64 distance from the file's end back to the
index record's start, then the 7 bytes ``INDEXED``, so a reader can find it from the end.

A file cut off mid-record (a recorder that was killed) reads up to its last whole record;
:attr:`LogReader.truncated` then says where and what is missing, in one line.
"""

from __future__ import annotations

import gzip
import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from enum import IntEnum
from pathlib import Path
from typing import IO

__all__ = ["HEADER", "LogFileError", "LogReader", "LogRecord", "MessageType", "write_log"]

HEADER = b"SSL_LOG_FILE"
VERSION = 1
_RECORD = struct.Struct(">qii")  # receive time (ns), message type, payload size
_VERSION = struct.Struct(">i")
_OFFSET = struct.Struct(">q")
INDEX_MARKER = b"INDEXED"


class MessageType(IntEnum):
    BLANK = 0
    UNKNOWN = 1
    VISION_2010 = 2
    REFBOX_2013 = 3
    VISION_2014 = 4
    TRACKER_2020 = 5
    INDEX_2021 = 6


class LogFileError(Exception):
    """Not a league log file (or one of a version we do not read)."""


@dataclass(frozen=True)
class LogRecord:
    receive_time_ns: int
    type: int  # a MessageType (other values are kept as they are)
    payload: bytes


def _open(path: Path, mode: str) -> IO[bytes]:
    if path.suffix == ".gz":
        return gzip.open(path, mode)  # type: ignore[return-value]
    return open(path, mode)  # noqa: SIM115 - the caller closes it


def write_log(path: str | Path, records: Iterable[LogRecord], index: bool = True) -> int:
    """Write ``records`` as a league log file (gzip for a ``.gz`` name), with the trailing index
    unless ``index`` is False; the number of records written."""
    path = Path(path)
    offsets: list[int] = []
    with _open(path, "wb") as f:
        f.write(HEADER + _VERSION.pack(VERSION))
        at = len(HEADER) + _VERSION.size
        for r in records:
            offsets.append(at)
            f.write(_RECORD.pack(r.receive_time_ns, int(r.type), len(r.payload)) + r.payload)
            at += _RECORD.size + len(r.payload)
        if index:
            size = _OFFSET.size * (len(offsets) + 1) + len(INDEX_MARKER)
            back = _RECORD.size + size  # from the file's end to the index record's start
            payload = b"".join(_OFFSET.pack(o) for o in offsets) + _OFFSET.pack(back) + INDEX_MARKER
            f.write(_RECORD.pack(0, MessageType.INDEX_2021, size) + payload)
    return len(offsets)


def _index(payload: bytes) -> list[int] | None:
    """The record offsets of an index record's payload; None when it is not one (no marker)."""
    if not payload.endswith(INDEX_MARKER):
        return None
    n = (len(payload) - len(INDEX_MARKER)) // _OFFSET.size - 1
    return [_OFFSET.unpack_from(payload, i * _OFFSET.size)[0] for i in range(max(n, 0))]


class LogReader:
    """The records of a league log file, in file order (the index is read and checked, not
    yielded). :attr:`truncated`: None, or what was cut short."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.truncated: str | None = None
        self.index: list[int] | None = None
        self.records = 0
        self._gzip_cut = False

    def __iter__(self) -> Iterator[LogRecord]:
        with _open(self.path, "rb") as f:
            head = self._read(f, len(HEADER) + _VERSION.size)
            if head[: len(HEADER)] != HEADER:
                raise LogFileError(f"{self.path}: not an SSL log file (it does not start with SSL_LOG_FILE)")
            if len(head) < len(HEADER) + _VERSION.size:
                raise LogFileError(f"{self.path}: the header is cut short")
            (version,) = _VERSION.unpack(head[len(HEADER):])
            if version != VERSION:
                raise LogFileError(f"{self.path}: log format version {version}; only version {VERSION} is read")
            at = len(head)
            while True:
                raw = self._read(f, _RECORD.size)
                if not raw:
                    if self._gzip_cut:
                        self._cut(at, "the gzip stream ends early")
                    return
                if len(raw) < _RECORD.size:
                    self._cut(at, f"its header has {len(raw)} of {_RECORD.size} bytes")
                    return
                t_ns, kind, size = _RECORD.unpack(raw)
                if size < 0:
                    self._cut(at, f"its size reads {size}")
                    return
                payload = self._read(f, size)
                if len(payload) < size:
                    self._cut(at, f"its payload has {len(payload)} of {size} bytes")
                    return
                if kind == MessageType.INDEX_2021:
                    self.index = _index(payload)
                    return
                self.records += 1
                yield LogRecord(t_ns, kind, payload)
                at += _RECORD.size + size

    def _read(self, f: IO[bytes], n: int) -> bytes:
        try:
            return f.read(n)
        except EOFError:  # a gzip stream cut off: what came before it is whole
            self._gzip_cut = True
            return b""

    def _cut(self, offset: int, what: str) -> None:
        self.truncated = (f"{self.path}: cut short in record {self.records + 1} at byte {offset} ({what}); "
                          f"read up to the {self.records} whole records before it")
