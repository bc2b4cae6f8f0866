"""Ctrl-C (SIGINT) and SIGTERM (a closed terminal, a CI timeout, ``kill``) end a run cleanly.

Inside ``with Interrupt() as stop:`` both signals are handled alike. While the run's frame loop
is going (:meth:`Interrupt.soft`), a signal only sets :attr:`Interrupt.signal`; the loop checks
``stop.requested`` once a frame and ends, and the run then closes its MCAP log and videos and
writes its summary, marked interrupted, as after a full run. A second signal during the loop
raises :class:`KeyboardInterrupt`, for a user who insists. While files are being finished
(:meth:`Interrupt.shield`) signals only set the flag, so that nothing is left half-written.
Anywhere else (a compile, a setup) a signal raises :class:`KeyboardInterrupt` at once, so that
every ``finally`` runs.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType, TracebackType
from typing import Any

__all__ = ["Interrupt"]

_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupt:
    """SIGINT and SIGTERM as a clean stop (see the module docstring)."""

    def __init__(self) -> None:
        self.signal: str | None = None  # "SIGINT" or "SIGTERM" once one arrived
        self.exit_code = 0  # 128 + the signal's number once one arrived (the shell's convention)
        self._mode = "raise"  # or "soft" (the first signal only sets the flag) or "shield" (all do)
        self._previous: dict[int, Any] = {}

    @property
    def requested(self) -> bool:
        return self.signal is not None

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        first = self.signal is None
        self.signal = signal.Signals(signum).name
        self.exit_code = 128 + signum
        if self._mode == "raise" or (self._mode == "soft" and not first):
            raise KeyboardInterrupt(self.signal)

    @contextmanager
    def _within(self, mode: str) -> Iterator[None]:
        before, self._mode = self._mode, mode
        try:
            yield
        finally:
            self._mode = before

    def soft(self) -> contextlib.AbstractContextManager[None]:
        """Within: a first signal only sets the flag, a second raises KeyboardInterrupt."""
        return self._within("soft")

    def shield(self) -> contextlib.AbstractContextManager[None]:
        """Within: every signal only sets the flag (for closing files)."""
        return self._within("shield")

    def __enter__(self) -> Interrupt:
        if threading.current_thread() is threading.main_thread():
            for s in _SIGNALS:
                self._previous[s] = signal.signal(s, self._handle)
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        for s, handler in self._previous.items():
            signal.signal(s, handler)
        self._previous.clear()
