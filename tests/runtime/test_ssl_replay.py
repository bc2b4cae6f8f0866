"""`cmdragons replay` of a league log: a match's log written as an SSL log file, read back and
replayed into our tracker and brain gives the same world states and commands as the match; a log
like a real match's (four cameras with counters of their own, Unix times, robots driven by someone
else) is tracked to its truth; a log cut off mid-record replays up to its last whole record; the
zenoh-only options are refused in one line."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from cmdragons import messages as msg
from cmdragons.cli import main
from cmdragons.runtime.log import read_log
from cmdragons.runtime.proto import ssl_wrapper_pb2 as wrap_pb
from cmdragons.runtime.settings import load_settings
from cmdragons.runtime.ssl.clock import UnixEpoch
from cmdragons.runtime.ssl.logfile import LogRecord, MessageType, write_log
from cmdragons.runtime.ssl.referee import referee_packet
from cmdragons.runtime.ssl.replay import replay_league_log
from cmdragons.runtime.ssl.vision import decode_wrapper, detection_packet, geometry_packet, settings_on_geometry
from cmdragons.runtime.stages import Tap


@pytest.fixture(scope="module")
def match(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A 1 s match on our vision (seed 1) and its league log."""
    d = tmp_path_factory.mktemp("league")
    assert main(["play", "--seconds", "1", "--seed", "1", "--no-progress", "--out", str(d / "run")]) == 0
    assert main(["log", "convert", str(d / "run" / "run.mcap"), str(d / "match.log")]) == 0
    return d / "run" / "run.mcap", d / "match.log"


def _topic(path: Path, topic: str) -> list[object]:
    return [m for t, _, m in read_log(path) if t == topic]


@pytest.mark.slow
def test_a_league_log_of_a_match_replays_to_the_same_tracks(match: tuple[Path, Path], tmp_path: Path) -> None:
    mcap, league = match
    gz = tmp_path / "match.log.gz"
    assert main(["log", "convert", str(mcap), str(gz)]) == 0
    for log in (league, gz):
        out = tmp_path / log.name.replace(".", "_")
        assert main(["replay", str(log), "--own", "--out", str(out), "--no-progress"]) == 0
        ours, theirs = _topic(mcap, "/world/blue"), _topic(out / "run.mcap", "/world/blue")
        assert len(ours) == 60 and theirs == ours  # to the bit
        assert _topic(out / "run.mcap", "/commands/blue") == _topic(mcap, "/commands/blue")
        assert (out / "summary.json").exists()


def test_a_league_log_cut_mid_record_replays_to_its_last_whole_record(
        match: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    mcap, league = match
    cut = tmp_path / "cut.log"
    data = league.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    assert main(["replay", str(cut), "--own", "--out", str(tmp_path / "cut"), "--no-progress"]) == 0
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "cut short in record" in err
    theirs = _topic(tmp_path / "cut" / "run.mcap", "/world/blue")
    ours = _topic(mcap, "/world/blue")
    assert 20 < len(theirs) < 40 and theirs == ours[: len(theirs)]


def test_a_league_replay_refuses_the_zenoh_options_in_one_line(
        match: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _, league = match
    assert main(["replay", str(league), "--speed", "2", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--speed" in err
    garbage = tmp_path / "garbage.log"
    garbage.write_bytes(b"NOT A LOG FILE AT ALL")
    assert main(["replay", str(garbage), "--out", str(tmp_path / "y"), "--no-progress"]) == 2
    assert "not an SSL log file" in capsys.readouterr().err
    shutil.rmtree(tmp_path / "y", ignore_errors=True)


@pytest.mark.slow
def test_a_real_matchs_log_is_tracked_to_its_truth(tmp_path: Path) -> None:
    t0 = UnixEpoch(1_700_000_000)  # Unix time, as SSL-Vision and the game controller stamp their packets
    counters = {0: 1000, 1: 52000, 2: 7, 3: 999_999}  # each camera counts its own frames
    records = []
    for k in range(240):  # 4 s: a blue robot crossing at 0.5 m/s, seen by four cameras in turn
        for cam in range(4):
            counters[cam] += 1
            t = 0.2 + k / 60 + cam * 0.002
            robot = msg.RobotDetection("blue", 2, -1.0 + 0.5 * t, 0.3, 0.0, 0.9, (0.0, 0.0))
            det = msg.DetectionFrame(cam, counters[cam], t, t + 0.004, (msg.BallDetection(1.0, 0.0, 0.9, (0.0, 0.0)),),
                                     (robot,))
            packet = wrap_pb.SSL_WrapperPacket.FromString(detection_packet(det, t0))
            packet.detection.ClearField("t_capture_camera")  # SSL-Vision's cameras have clocks of their own
            records.append(LogRecord(t0.to_unix_ns(t + 0.005), MessageType.VISION_2014, packet.SerializeToString()))
        if k % 6 == 0:
            game = referee_packet(msg.GameState(0.2 + k / 60, "stop"), epoch=t0)
            records.append(LogRecord(t0.to_unix_ns(0.2 + k / 60), MessageType.REFBOX_2013, game))
    write_log(tmp_path / "real.log", records)
    worlds: list[msg.WorldState] = []
    games: list[msg.GameState] = []
    taps = (Tap("w", ("world/blue",), lambda _t, w: worlds.append(w)),
            Tap("g", ("referee/gc",), lambda _t, g: games.append(g)))
    result = replay_league_log(tmp_path / "real.log", load_settings(), extra=taps)
    assert result.cameras == [0, 1, 2, 3] and result.records == {"VISION_2014": 960, "REFBOX_2013": 40}
    assert result.figures["ssl/vision_in"]["dropped"] == {} and len(worlds) >= 950
    assert len(games) == 40 and all(g.command == msg.RefereeCommand.STOP for g in games)
    w = worlds[-1]
    r = next(r for r in w.robots if r.team == "blue" and r.id == 2)
    # the truth at the world state's time (the tracker predicts ahead by its latency): 5 mm, 0.01 m/s;
    # the log's times are match time from its first second
    assert (r.x, r.y) == pytest.approx((-1.0 + 0.5 * w.t, 0.3), abs=0.005) and 3.5 < w.t < 4.5
    assert games[0].t == pytest.approx(0.2, abs=1e-6)
    assert (r.vx, r.vy) == pytest.approx((0.5, 0.0), abs=0.01)


def test_a_league_replay_is_a_table_of_declared_stages_checked_when_built(tmp_path: Path) -> None:
    from cmdragons.runtime.bus import BaseStage
    from cmdragons.runtime.match import CLOCK
    from cmdragons.runtime.ssl.replay import league_replay_wiring
    from cmdragons.runtime.ssl.udp import DatagramQueue
    from cmdragons.runtime.topics import Contract, Port, WiringError, check_wiring

    settings = load_settings()
    for own in (False, True):
        table = league_replay_wiring(settings, "blue", [0, 1], own, DatagramQueue(), DatagramQueue())
        assert [e.contract.name for e in table] == ["ssl/vision_in", "ssl/referee_in", "tracker/blue", "team/blue"]
        tracker = table[2].contract
        assert ("commands/blue" in tracker.inputs) == own  # the brain's commands as control input: our own match's log
        check_wiring([e.contract for e in table], CLOCK)

    class Viewer(BaseStage):  # a viewer of the other team's world, which nobody in a replay tracks
        contract = Contract("viewer", (Port("world/yellow", msg.WorldState),))

    det = msg.DetectionFrame(0, 1, 1.0, 1.004, (), ())
    write_log(tmp_path / "one.log", [LogRecord(1_000_000_000, MessageType.VISION_2014, detection_packet(det))])
    with pytest.raises(WiringError, match=r"'viewer' reads topic 'world/yellow'"):
        replay_league_log(tmp_path / "one.log", settings, extra=(Viewer(),))
    assert replay_league_log(tmp_path / "one.log", settings).records == {"VISION_2014": 1}


def test_a_replay_plays_on_the_logs_geometry(tmp_path: Path) -> None:
    """A league log whose geometry packets say 12 x 9 m (Division A) replays on that field though
    our config is Division B (9 x 6 m); a log without geometry plays on the config's field."""
    division_a = load_settings(None, ["field.division=A"])
    epoch = UnixEpoch(1_764_000_000)
    geometry = geometry_packet(division_a.field_geometry(), division_a.camera_models())
    records = [LogRecord(epoch.to_unix_ns(0.0), MessageType.VISION_2014, geometry)]
    for k in range(30):  # a robot standing at x = 5.5 m: inside the 12 m field, past the 9 m field's boundary
        det = msg.DetectionFrame(0, k, k / 60, k / 60, (), (msg.RobotDetection("blue", 1, 5.5, 0.0, 0.0, 0.9,
                                                                                (0.0, 0.0)),))
        records.append(LogRecord(epoch.to_unix_ns(k / 60), MessageType.VISION_2014, detection_packet(det, epoch)))
    write_log(tmp_path / "a.log", records)
    write_log(tmp_path / "none.log", records[1:])
    worlds: list[msg.WorldState] = []
    config = load_settings()
    assert (config.field.dims.length_m, config.field.dims.width_m) == (9.0, 6.0)
    result = replay_league_log(tmp_path / "a.log", config, extra=(Tap("w", ("world/blue",), lambda _t, w:
                                                                       worlds.append(w)),))
    assert (result.field_m, result.field_from) == ((12.0, 9.0), "log")
    assert worlds and worlds[-1].robots[0].x == pytest.approx(5.5, abs=0.01)
    plain = replay_league_log(tmp_path / "none.log", config)
    assert (plain.field_m, plain.field_from) == ((9.0, 6.0), "config")
    dims = settings_on_geometry(config, decode_wrapper(geometry)[1]).field.dims  # type: ignore[arg-type]
    a = division_a.field.dims
    assert (dims.length_m, dims.width_m, dims.goal_width_m, dims.defense_width_m, dims.defense_depth_m) == \
        (a.length_m, a.width_m, a.goal_width_m, a.defense_width_m, a.defense_depth_m)
