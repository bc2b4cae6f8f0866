"""examples/outside_team.py, a client that knows only zenoh and our schemas, plays yellow in a
distributed lock-step match: it answers every frame, and its robots drive at the ball."""

from __future__ import annotations

import dataclasses
import math
import signal
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

from cmdragons.runtime.distributed import MatchSpec, node_roles, run_clock
from cmdragons.runtime.stages import Tap
from tests.runtime.test_distributed import _nodes, router  # noqa: F401  (the fixture)
from tests.runtime.test_zenoh import SETTINGS

ROOT = Path(__file__).resolve().parents[2]
SECONDS = 1.0


def _ball_distance(truth: Any) -> float:
    """The yellow robots' mean distance to the ball (m)."""
    d = [math.hypot(r.x - truth.ball.x, r.y - truth.ball.y) for r in truth.robots if r.team == "yellow"]
    return sum(d) / len(d)


def test_the_example_client_plays_yellow_over_zenoh(router: Any) -> None:  # noqa: F811
    from cmdragons.runtime.zenoh_transport import ZenohTransport

    client = subprocess.Popen([sys.executable, str(ROOT / "examples" / "outside_team.py"), "--router",
                               router.zenoh.router, "--field", router.field_name], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    spec = MatchSpec(dataclasses.replace(SETTINGS, runtime=router), "outside", "truth", 3)
    roles = node_roles("outside", log=False)
    assert "opponent" not in roles
    stop = threading.Event()
    truth: list[Any] = []
    clock = ZenohTransport(router, "sim")
    threads: list[threading.Thread] = []
    try:
        assert "outside team: yellow" in (client.stdout.readline() if client.stdout else "")
        threads = _nodes(spec, [r for r in roles if r != "sim"], stop)
        summary = run_clock(spec, clock, SECONDS, roles, extra=[Tap("rec", ("truth",), lambda _t, x: truth.append(x))])
    finally:
        stop.set()
        for th in threads:
            th.join(10)
        clock.close()
        client.send_signal(signal.SIGINT)
        _, err = client.communicate(timeout=20)
    assert client.returncode == 0 and "Traceback" not in err, err
    assert summary["frames"] == round(SECONDS * 60) and summary["frames_stepped_without_a_team"] == 0
    assert summary["command_faults"]["timed_out"] == 0  # yellow's commands were never late
    yellow = [r for r in truth[-1].robots if r.team == "yellow"]
    assert yellow and any(math.hypot(r.vx, r.vy) > 0.3 for r in yellow)
    print(_ball_distance(truth[0]), _ball_distance(truth[-1]))
    assert _ball_distance(truth[-1]) < _ball_distance(truth[0]) - 0.3
