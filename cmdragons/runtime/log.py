"""Run logs: ``logs/<time>-<command>/`` with an MCAP file of every message and a summary.json.

MCAP channels carry JSON (the ``to_dict`` forms); log times are the simulation's capture times,
so the same config and seed give the same log, byte for byte.
"""

from __future__ import annotations

import datetime as _dt
import json
from pathlib import Path
from typing import Any, BinaryIO

from mcap.writer import CompressionType, Writer

__all__ = ["RunLog", "run_folder"]


def run_folder(command: str, out: str | Path | None = None, logs: str | Path = "logs") -> Path:
    """``out`` if given, else a new ``logs/<YYYYmmdd-HHMMSS>-<command>`` folder."""
    if out is not None:
        folder = Path(out)
    else:
        stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
        folder = Path(logs) / f"{stamp}-{command}"
        n = 1
        while folder.exists():
            n += 1
            folder = Path(logs) / f"{stamp}-{command}-{n}"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


class RunLog:
    """An MCAP recording of JSON messages on named topics."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._file: BinaryIO = open(self.path, "wb")  # noqa: SIM115
        self._writer = Writer(self._file, compression=CompressionType.ZSTD)
        self._writer.start(profile="", library="cmdragons")
        self._channels: dict[str, int] = {}
        self._sequence = 0

    def write(self, topic: str, t: float, message: dict[str, Any]) -> None:
        channel = self._channels.get(topic)
        if channel is None:
            schema = self._writer.register_schema(
                name=topic.strip("/").replace("/", "."), encoding="jsonschema",
                data=json.dumps({"type": "object"}).encode(),
            )  # fmt: skip
            channel = self._writer.register_channel(topic=topic, message_encoding="json", schema_id=schema)
            self._channels[topic] = channel
        ns = max(0, int(round(t * 1e9)))
        self._sequence += 1
        data = json.dumps(message, separators=(",", ":")).encode()
        self._writer.add_message(channel_id=channel, log_time=ns, data=data, publish_time=ns, sequence=self._sequence)

    def close(self) -> None:
        if not self._file.closed:
            self._writer.finish()  # type: ignore[no-untyped-call]
            self._file.close()

    def __enter__(self) -> RunLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
