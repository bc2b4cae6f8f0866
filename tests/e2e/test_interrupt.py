"""A run stopped by SIGINT or SIGTERM loses nothing: the MCAP log is closed (the standard reader
reads it to its summary), every video is complete, summary.json says interrupted, and the last
line names the output folder. Real signals to a child process running the CLI as a user does."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import av
import pytest
from mcap.reader import make_reader

ROOT = Path(__file__).resolve().parents[2]


def start(args: list[str]) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "cmdragons.cli", *args], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def wait_for_frames(path: Path, child: subprocess.Popen[str]) -> None:
    """Until the run has written a few frames' worth into ``path`` (its compile and setup are done)."""
    for _ in range(3000):  # polls 0.2 s apart: a cold first run compiles for a minute or two
        if path.exists() and path.stat().st_size > 50_000:
            return
        assert child.poll() is None, child.communicate()
        time.sleep(0.2)
    child.kill()
    pytest.fail("the run never started writing")


def video_frames(path: Path) -> int:
    with av.open(str(path)) as c:
        return sum(1 for _ in c.decode(video=0))


def mcap_messages(path: Path) -> int:
    with open(path, "rb") as f:
        reader = make_reader(f)
        assert reader.get_summary() is not None  # the footer and summary section were written
        return sum(1 for _ in reader.iter_messages())


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_play_interrupted_keeps_everything(tmp_path: Path, sig: signal.Signals) -> None:
    out = tmp_path / "run"
    child = start(["play", "--seconds", "600", "--perception", "truth", "--video", "--no-progress", "--out",
                   str(out)])
    wait_for_frames(out / "run.mcap", child)
    child.send_signal(sig)
    stdout, stderr = child.communicate(timeout=300)
    assert child.returncode == 128 + sig, stderr
    assert "Traceback" not in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True
    assert 0 < summary["seconds"] < 600
    frames = round(summary["seconds"] * 60)
    assert mcap_messages(out / "run.mcap") > frames
    assert abs(video_frames(out / "match.mp4") - frames) <= 1
    assert (out / "report.png").stat().st_size > 10_000
    lines = stdout.strip().splitlines()
    assert any(sig.name in line and "interrupted" in line for line in lines)
    assert lines[-1].endswith(str(out))


@pytest.mark.slow
def test_sim_record_interrupted_keeps_the_camera_videos(tmp_path: Path) -> None:
    out = tmp_path / "rec"
    child = start(["sim", "--seconds", "600", "--record", "--no-progress", "--out", str(out)])
    wait_for_frames(out / "camera_0.mp4", child)
    child.send_signal(signal.SIGTERM)
    stdout, stderr = child.communicate(timeout=300)
    assert child.returncode == 128 + signal.SIGTERM, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True
    for cam in (0, 1):
        assert abs(video_frames(out / f"camera_{cam}.mp4") - summary["frames"]) <= 1
    assert mcap_messages(out / "run.mcap") > summary["frames"]
    assert stdout.strip().splitlines()[-1].endswith(str(out))


@pytest.mark.slow
def test_the_served_simulator_runs_until_interrupted_and_keeps_everything(tmp_path: Path) -> None:
    from tests.runtime.conftest import free_udp_ports

    out = tmp_path / "served"
    vision, referee, control, blue, yellow = free_udp_ports(5)
    child = start(["sim", "--serve", "--no-progress", "--out", str(out),
                   "--set", f"protocols.simulation.vision_port={vision}", "--set", f"protocols.referee.port={referee}",
                   "--set", f"protocols.simulation.control_port={control}",
                   "--set", f"protocols.simulation.blue_port={blue}",
                   "--set", f"protocols.simulation.yellow_port={yellow}"])
    wait_for_frames(out / "run.mcap", child)
    child.send_signal(signal.SIGINT)
    stdout, stderr = child.communicate(timeout=300)
    assert child.returncode == 128 + signal.SIGINT, stderr
    assert "Traceback" not in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["seconds"] > 0
    assert summary["frames"] == round(summary["seconds"] * 60)
    assert mcap_messages(out / "run.mcap") > 0
    last = stdout.strip().splitlines()[-1]
    assert "score blue 0:0 yellow" in last and "interrupted by SIGINT" in last and str(out) in last
