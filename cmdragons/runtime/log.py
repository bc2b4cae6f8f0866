"""Run logs: ``logs/<time>-<command>/`` with an MCAP file of every message and a summary.json.

MCAP channels carry JSON (the ``to_dict`` forms); log times are the simulation's capture times,
so the same config and seed give the same log, byte for byte.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import shutil
from pathlib import Path
from typing import Any, BinaryIO

from mcap.writer import CompressionType, Writer

__all__ = ["RUN_FILES", "OutputError", "RunLog", "check_writable_file", "run_folder"]

# what a run writes into its folder (globs): a folder holding one of these holds a run
RUN_FILES = ("run.mcap", "summary.json", "match.mp4", "match_cameras.mp4", "report.png", "detections.jsonl",
             "tracks.jsonl", "truth.jsonl", "cameras.yaml", "camera_*", "annotated_camera_*")  # fmt: skip


class OutputError(Exception):
    """An output path that cannot be used; the message names the path, the problem and the fix."""


def run_folder(command: str, out: str | Path | None = None, logs: str | Path = "logs", overwrite: bool = False) -> Path:
    """``out`` if given, else a new ``logs/<YYYYmmdd-HHMMSS>-<command>`` folder, created.

    An ``out`` folder holding another run's files is refused (:class:`OutputError`) unless
    ``overwrite``, which deletes those files and folders (:data:`RUN_FILES`) and leaves any other
    file alone."""
    if out is not None:
        folder = Path(out)
        if folder.exists() and not folder.is_dir():
            raise OutputError(f"--out {folder}: is a file, not a folder; give a new folder name")
        if folder.is_dir():
            old = sorted({p for pattern in RUN_FILES for p in folder.glob(pattern)})
            if old and not overwrite:
                raise OutputError(f"--out {folder}: holds another run ({old[0].name}); give a new folder, "
                                  "or add --overwrite to replace that run")  # fmt: skip
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
                          "give another folder with --out DIR")  # fmt: skip
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the output folder {folder} ({exc.strerror}); "
                          "give a writable one with --out DIR") from None  # fmt: skip
    _check_folder_writable(folder)
    return folder


def _file_in_the_way(folder: Path) -> Path | None:
    """The nearest of ``folder`` and its parents that exists as something other than a folder."""
    for p in (folder, *folder.parents):
        if p.exists():
            return None if p.is_dir() else p
    return None


def _check_folder_writable(folder: Path) -> None:
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"cannot write into the output folder {folder} (permission denied); "
                          "give a writable one with --out DIR")  # fmt: skip


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
                          "give a writable path") from None  # fmt: skip
    if not os.access(p.parent, os.W_OK | os.X_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise OutputError(f"{option} {p}: not writable (permission denied); give a writable path")
    return p


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
