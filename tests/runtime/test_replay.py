"""Replaying a run's log on the bus: every bus message of the log in order, paced at its log time
over the speed; over zenoh a team node plays against it; bad input is one line and exit code 2."""

from __future__ import annotations

import dataclasses
import threading
from pathlib import Path
from typing import Any

import pytest

from cmdragons.cli import main
from cmdragons.messages import NodeControl
from cmdragons.runtime.bus import InProcessTransport
from cmdragons.runtime.log import RunLog, read_log
from cmdragons.runtime.match import Match
from cmdragons.runtime.replay import replay, replay_topics
from cmdragons.runtime.stages import LoggerStage
from cmdragons.runtime.wire import encode
from tests.runtime.test_zenoh import SETTINGS, loopback_params

SEED = 7
SECONDS = 1.0


@pytest.fixture(scope="module")
def match_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A second of an embedded match on truth perception, logged as ``cmdragons play`` logs it."""
    path = tmp_path_factory.mktemp("replay") / "run.mcap"
    with RunLog(path) as log:
        Match(SETTINGS, "simple", "truth", seed=SEED, extra=[LoggerStage(log)]).run(SECONDS)
    return path


def logged(path: Path, topics: list[str], start_s: float = 0.0) -> list[tuple[str, float, Any]]:
    return [(t.lstrip("/"), tt, m) for t, tt, m in read_log(path, ["/" + t for t in topics], start_s=start_s)]


class Clock:
    """A clock that moves only when slept on (s)."""

    def __init__(self) -> None:
        self.t = 0.0

    def now(self) -> float:
        return self.t

    def sleep(self, dt: float) -> None:
        self.t += dt


@pytest.mark.parametrize(("start_s", "speed"), [(0.0, 1.0), (0.5, 2.5)])
def test_every_message_comes_in_log_order_at_its_time_over_the_speed(match_log: Path, start_s: float,
                                                                     speed: float) -> None:
    transport = InProcessTransport()
    clock = Clock()
    got: list[tuple[str, Any, float]] = []
    transport.subscribe("*", lambda topic, m: got.append((topic, m, clock.now())))
    result = replay(match_log, transport, start_s, speed, now=clock.now, sleep=clock.sleep)
    topics = replay_topics(match_log)
    assert {"truth", "referee", "events", "perception/blue", "commands/blue", "world/blue"} <= set(topics)
    assert not any(t.startswith("summary/") for t in topics)
    t0 = next(iter(read_log(match_log)))[1] + start_s  # messages compare by their bytes (arrays in them)
    expected = logged(match_log, topics, t0)
    assert got[-1] == ("control/clock", NodeControl("clock", "stop"), got[-1][2])
    messages = got[:-1]
    if start_s > 0:  # the game's state before the start comes first
        last_state = [m for t, tt, m in logged(match_log, ["referee"]) if tt < t0][-1]
        assert messages[0][:2] == ("referee", last_state) and messages[0][2] == 0.0
        messages = messages[1:]
    assert [(t, encode(m)) for t, m, _ in messages] == [(t, encode(m)) for t, _, m in expected]
    assert result.messages == len(got) - 1 and not result.interrupted
    for (_, _, at), (_, t, _) in zip(messages, expected, strict=True):
        assert at == pytest.approx((t - t0) / speed, abs=1e-9)


def test_a_team_node_plays_against_a_replay_over_zenoh(match_log: Path) -> None:
    import zenoh

    from cmdragons.runtime.distributed import MatchSpec, run_node
    from cmdragons.runtime.zenoh_transport import ZenohTransport

    params = loopback_params("replay")
    spec = MatchSpec(dataclasses.replace(SETTINGS, runtime=params), "simple", "truth", SEED)
    router = zenoh.open(params.zenoh.config("router"))
    team, watch, source = (ZenohTransport(params, name) for name in ("team", "watch", "replay"))
    got: list[tuple[str, Any]] = []
    watch.subscribe("*", lambda topic, m: got.append((topic, m)))
    ours = ["commands/blue", "world/blue", "report/blue"]  # what the live team node says
    node = threading.Thread(target=run_node, args=("team", spec, team), daemon=True)
    try:
        node.start()
        assert source.wait_for(lambda: source.has_subscribers("truth"), 10.0)  # the watcher is there
        result = replay(match_log, source, speed=4.0, skip=ours, wait_for=["team"])
        node.join(30)
        assert not node.is_alive()  # the replay's end stopped it
        assert watch.wait_for(lambda: ("control/clock", NodeControl("clock", "stop")) in got, 10.0)
    finally:
        for t in (team, watch, source):
            t.close()
        router.close()
    topics = replay_topics(match_log, ours)
    replayed = [(t, m) for t, m in got if t in topics]
    assert [(t, encode(m)) for t, m in replayed] == [(t, encode(m)) for t, _, m in logged(match_log, topics)]
    assert result.messages == len(replayed)
    # the node answers every frame of the log it saw with commands for that frame, and they move robots
    frames = [m.frame_number for t, m in replayed if t == "perception/blue"]
    commands = [m for t, m in got if t == "commands/blue"]
    assert [c.frame_number for c in commands] == frames
    assert any(abs(c.vx) + abs(c.vy) > 0.1 for cs in commands for c in cs.commands)


@pytest.mark.parametrize(("make", "extra", "says"), [
    (lambda p: p / "absent.mcap", [], "no such file"),
    (lambda p: (p / "text.mcap").write_text("hello") and p / "text.mcap", [], "not an MCAP log"),
    (None, ["--from", "99"], "beyond the log's end"),
])
def test_bad_input_is_one_line_and_exit_code_2(match_log: Path, tmp_path: Path, make: Any, extra: list[str],
                                               says: str, capsys: pytest.CaptureFixture[str]) -> None:
    path = match_log if make is None else make(tmp_path)
    assert main(["replay", str(path), *extra, "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert says in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_the_command_replays_a_log_as_its_own_router(match_log: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from tests.runtime.test_zenoh import free_port

    router = f"runtime.zenoh.router=tcp/127.0.0.1:{free_port()}"
    assert main(["replay", str(match_log), "--router", "--set", router, "--speed", "8", "--from", "0.5",
                 "--skip", "commands/*", "--no-progress"]) == 0
    out = capsys.readouterr().out
    start = next(iter(read_log(match_log)))[1] + 0.5
    expected = 1 + len(logged(match_log, replay_topics(match_log, ["commands/*"]), start))  # the state, then on
    assert f"replay: {expected} messages, log time 0.50 .. " in out, out
