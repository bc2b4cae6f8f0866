"""Latency compensation: where each robot will be when the command sent now starts to act.

Field frame, metres, seconds. A command sent at time s acts from s + latency until the next one
acts. The robots' observed state is therefore a latency behind what the next command meets; the
commands still in flight decide what happens in between, so the controller and the safety search
start from the state predicted through them (the motor model of :func:`_kernels.predict_motion`).
"""

from __future__ import annotations

from collections import deque

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cmdragons.control import _kernels as K
from cmdragons.control.motion import MotionParams

__all__ = ["LatencyCompensator"]

FloatArray = NDArray[np.float64]


class LatencyCompensator:
    """Remembers the velocity commands sent during the last latency and predicts the robots' states
    through them. One per team; robots are named by id."""

    def __init__(self, params: MotionParams) -> None:
        self.params = params
        self._sent: deque[tuple[float, dict[int, tuple[float, float, float]]]] = deque()

    def reset(self) -> None:
        self._sent.clear()

    def record(self, t_s: float, ids: ArrayLike, commands: ArrayLike) -> None:
        """Commands (n, 3: vx, vy in the field frame, m/s; omega, rad/s) sent at ``t_s`` to robots
        ``ids``."""
        c = np.asarray(commands, dtype=np.float64).reshape(-1, 3)
        sent = {int(i): (float(a), float(b), float(w)) for i, (a, b, w) in zip(np.ravel(ids), c, strict=True)}
        self._sent.append((float(t_s), sent))
        # keep the command in force at the oldest moment still asked about, drop older ones
        horizon = float(t_s) - self.params.latency_s - 1e-9
        while len(self._sent) > 1 and self._sent[1][0] <= horizon:
            self._sent.popleft()

    def predict(self, t_s: float, ids: ArrayLike, states: ArrayLike) -> FloatArray:
        """States (n, 6: x, y, theta, vx, vy, omega) observed at ``t_s``, advanced by the latency
        through the commands in flight. Robots with no command on record are assumed commanded to
        rest."""
        s = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, 6)
        lat = self.params.latency_s
        if lat <= 0.0 or len(s) == 0:
            return s.copy()
        t, ids_list = float(t_s), [int(i) for i in np.ravel(ids)]
        # each sent command acts from sent + latency; cut [t, t + lat] at those moments
        start = [(max(sent + lat, t), cmds) for sent, cmds in self._sent if sent + lat < t + lat - 1e-9]
        if not start or start[0][0] > t:
            start.insert(0, (t, {}))
        bounds = [b for b, _ in start] + [t + lat]
        durations = np.diff(np.array(bounds))
        commands = np.zeros((len(s), len(start), 3))
        for k, (_, cmds) in enumerate(start):
            for i, rid in enumerate(ids_list):
                commands[i, k] = cmds.get(rid, (0.0, 0.0, 0.0))
        m = self.params
        out = K.predict_motion(s, commands, np.maximum(durations, 0.0), m.max_accel_m_s2, m.max_brake_m_s2,
                               m.max_alpha_rad_s2)  # fmt: skip
        return np.asarray(out)
