"""Every bad input a user may give: one line on stderr naming the problem and the fix, exit code 2,
no traceback, and nothing already done lost (checks that can fail late run before the work)."""

from __future__ import annotations

import json
import socket
from pathlib import Path

import pytest

from cmdragons.cli import main


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


@pytest.fixture
def a_file(tmp_path: Path) -> Path:
    p = tmp_path / "a_file"
    p.write_text("not a folder\n")
    return p


# (argv, words the one line must hold); {file} is a regular file, {tmp} the test's folder
CASES = [
    (["play", "--seed", "-1"], ["--seed", "-1", "0 to 2**63-1"]),
    (["sim", "--seed", "one"], ["--seed", "'one' is not a whole number"]),
    (["play", "--seconds", "0"], ["--seconds", "positive number"]),
    (["sim", "--seconds", "nan"], ["--seconds", "positive number"]),
    (["vision", "x", "--fps", "-5"], ["--fps", "positive number"]),
    (["play", "--bogus"], ["unrecognized arguments: --bogus", "-h"]),
    (["play", "--out", "{file}"], ["--out", "is a file", "new folder"]),
    (["play", "--out", "{file}/sub"], ["cannot create the output folder", "a_file is a file", "--out DIR"]),
    (["sim", "--out", "{file}/sub/deeper"], ["cannot create the output folder", "a_file is a file", "--out DIR"]),
    (["play", "--out", "/proc/no_such_folder"], ["cannot create the output folder", "--out DIR"]),
    (["bench", "sim", "--quick", "--json", "{file}/rows.json"], ["--json", "a_file is a file"]),
    (["bench", "sim", "--quick", "--json", "{tmp}"], ["--json", "is a folder", "file name"]),
    (["bench", "sim", "--quick", "--json", "/proc/rows.json"], ["--json", "/proc/rows.json", "not writable"]),
    (["sim", "--snapshot", "{file}/last.png", "--out", "{tmp}/s"], ["--snapshot", "a_file is a file"]),
    (["sim", "--snapshot", "{tmp}/last.txt", "--out", "{tmp}/s"], ["--snapshot", "ending in .png"]),
    (["sim", "--serve", "--record", "--out", "{tmp}/s"], ["--serve", "--record", "cannot be used"]),
    (["sim", "--serve", "--division", "C"], ["--division", "invalid choice", "'A', 'B'"]),
    (["sim", "--serve", "--set", "protocols.simulation.address=10.1.2.3"], ["simulation.address", "network: true"]),
    (["play", "--set", "sim.physics.substeps=[1"], ["sim.physics.substeps", "not valid YAML", "[1, 2]"]),
    (["play", "--set", "sim.render.noise_sigma=0"], ["render.noise_sigma", "did you mean noise_sigma_grey?"]),
    (["play", "--set", "nosuch.key=1"], ["unknown concern"]),
    (["play", "--config", "{tmp}/no_configs"], ["config folder not found"]),
    (["bench", "nosuch"], ["unknown suite", "planning"]),
    (["play", "--opponent-set", "team.navigator=robox"], ["--opponent-set", "needs --opponent self", "simple"]),
    (["play", "--opponent", "self", "--opponent-set", "field.division=A"],
     ["--opponent-set", "field.division", "brain and tracker", "planner", "--set"]),
    (["play", "--opponent", "self", "--opponent-set", "team.navigator=magic"], ["team.navigator", "'robox'"]),
    (["play", "--opponent", "self", "--opponent-set", "planner.estar.neighbours=6"], ["estar.neighbours", "4, 8"]),
]


@pytest.mark.parametrize(("argv", "words"), CASES, ids=[" ".join(c[0]) for c in CASES])
def test_bad_input_one_line_exit_2(argv: list[str], words: list[str], tmp_path: Path, a_file: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    argv = [a.format(file=a_file, tmp=tmp_path) for a in argv]
    code, out, err = run([*argv, "--no-progress"] if argv[0] in ("play", "sim") else argv, capsys)
    assert code == 2
    line = one_line(err)
    for w in words:
        assert w in line, line
    assert "cmdragons bench" not in out  # no table: the bench never ran


def test_a_served_port_in_use_is_one_line_and_nothing_written(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as held:
        held.bind(("127.0.0.1", 0))
        port = held.getsockname()[1]
        code, _, err = run(["sim", "--serve", "--seconds", "0.1", "--out", str(tmp_path / "s"), "--no-progress",
                            "--set", f"protocols.simulation.control_port={port}"], capsys)
    assert code == 2
    line = one_line(err)
    assert "cannot open its sockets" in line and str(port) in line and "--set protocols.simulation" in line
    assert not (tmp_path / "s").exists()


def test_snapshot_checked_before_the_run(tmp_path: Path, a_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, _ = run(["sim", "--seconds", "0.2", "--snapshot", f"{a_file}/x.png", "--out", str(tmp_path / "s"),
                      "--no-progress"], capsys)
    assert code == 2
    assert not (tmp_path / "s").exists()  # nothing made: the run never started


@pytest.mark.slow
def test_out_refuses_another_run_unless_overwrite(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    argv = ["play", "--seconds", "0.2", "--perception", "truth", "--opponent", "none", "--no-progress", "--out",
            str(out)]
    assert run(argv, capsys)[0] == 0
    (out / "notes.txt").write_text("mine\n")
    first = json.loads((out / "summary.json").read_text())
    code, _, err = run(argv, capsys)
    assert code == 2
    line = one_line(err)
    assert "holds another run" in line and "--overwrite" in line
    assert json.loads((out / "summary.json").read_text()) == first  # the first run is untouched
    code, stdout, _ = run([*argv, "--overwrite", "--seed", "3"], capsys)
    assert code == 0
    assert json.loads((out / "summary.json").read_text())["seed"] == 3
    assert (out / "notes.txt").read_text() == "mine\n"  # a file the runs did not write stays
    assert stdout.strip().splitlines()[-1].endswith(str(out))


def _recording(tmp_path: Path) -> Path:
    rec = tmp_path / "rec"
    assert main(["sim", "--seconds", "0.2", "--record", "--format", "png", "--out", str(rec), "--no-progress"]) == 0
    return rec


@pytest.mark.slow
def test_a_truth_file_cut_mid_line_keeps_the_frames_before(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = _recording(tmp_path)
    truth = rec / "truth.jsonl"
    text = truth.read_text()
    truth.write_text(text[: len(text) - 40])  # the last line cut off
    capsys.readouterr()
    assert main(["vision", str(rec), "--out", str(tmp_path / "v"), "--no-progress"]) == 0
    err = capsys.readouterr().err
    assert "truth.jsonl: line 12 is cut off; the truth of the frames before it is used" in err
    assert "Traceback" not in err
    # a bad line in the middle: one line naming file and line, exit 2
    lines = text.splitlines()
    truth.write_text("\n".join(lines[:3] + ["{not json"] + lines[4:]) + "\n")
    assert main(["vision", str(rec), "--out", str(tmp_path / "w"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "truth.jsonl: line 4 is not a frame's truth" in err[0]


@pytest.mark.slow
def test_more_sources_than_cameras_is_one_line_before_any_work(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    rec = _recording(tmp_path)
    frames = [str(rec / "camera_0"), str(rec / "camera_1"), str(rec / "camera_0")]
    capsys.readouterr()
    assert main(["vision", *frames, "--out", str(tmp_path / "v"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "3 sources but only 2 camera model(s)" in err[0], err
    assert not (tmp_path / "v" / "detections.jsonl").exists() or not (tmp_path / "v" / "detections.jsonl").read_text()


def test_a_distributed_play_on_a_taken_router_port_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        router = f"runtime.zenoh.router=tcp/127.0.0.1:{port}"
        code, _, err = run(["play", "--distributed", "--perception", "truth", "--seconds", "1", "--out",
                            str(tmp_path / "run"), "--set", router], capsys)
    assert code == 2
    assert err.strip().count("\n") == 0
    assert f"cannot listen on tcp/127.0.0.1:{port}" in err and "runtime.zenoh.router" in err


@pytest.mark.parametrize("cut", [False, True], ids=["closed", "cut_short"])
def test_a_run_log_without_a_message_does_not_block_the_folder(tmp_path: Path, cut: bool,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """A run stopped before its first frame (Ctrl-C while compiling) leaves a run.mcap with no message,
    closed or cut short: the same --out is taken again without --overwrite; a log with messages is not."""
    from cmdragons.runtime.log import RunLog

    out = tmp_path / "run"
    out.mkdir()
    RunLog(out / "run.mcap").close()
    if cut:
        data = (out / "run.mcap").read_bytes()
        (out / "run.mcap").write_bytes(data[: len(data) // 2])
    argv = ["play", "--seconds", "0.2", "--perception", "truth", "--opponent", "none", "--no-progress", "--out",
            str(out)]
    code, stdout, err = run(argv, capsys)
    assert code == 0, err
    assert json.loads((out / "summary.json").read_text())["seconds"] > 0
    for name in ("summary.json", "report.png"):
        (out / name).unlink(missing_ok=True)  # only the played log left: it holds a run
    code, _, err = run(argv, capsys)
    assert code == 2 and "holds another run (run.mcap)" in one_line(err)


@pytest.mark.parametrize("content", [b"hello, not a video\n", bytes(range(256)) * 20], ids=["text", "garbage"])
def test_a_file_that_is_no_video_is_one_line_exit_2(tmp_path: Path, content: bytes,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    video = tmp_path / "camera.mp4"
    video.write_bytes(content)
    code, out, err = run(["vision", str(video), "--out", str(tmp_path / "out"), "--no-progress"], capsys)
    assert code == 2 and out == ""
    line = one_line(err)
    assert "camera.mp4" in line and "cannot be opened as a video" in line and "give a video file" in line
    assert "frames before it" not in line  # there were none
    assert not (tmp_path / "out" / "detections.jsonl").exists()


def test_track_ahead_without_track_is_one_line_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(["vision", "no_such_source", "--track-ahead"], capsys)
    assert code == 2 and "--track-ahead" in one_line(err) and "add --track" in err


def test_version_is_the_package_metadata(capsys: pytest.CaptureFixture[str]) -> None:
    from importlib.metadata import version

    code, out, _ = run(["--version"], capsys)
    assert code == 0 and out.strip() == f"cmdragons {version('cmdragons')}"


def test_bench_help_lists_every_suite_on_a_line(capsys: pytest.CaptureFixture[str]) -> None:
    from cmdragons.bench import ABOUT, SUITES

    assert set(ABOUT) == set(SUITES)
    code, out, _ = run(["bench", "-h"], capsys)
    assert code == 0 and "see `cmdragons bench --help`" not in out
    lines = out.splitlines()
    for name, about in ABOUT.items():
        assert sum(1 for line in lines if line.split()[:1] == [name] and line.rstrip().endswith(about)) == 1


def test_each_commands_set_example_is_a_key_it_reads(capsys: pytest.CaptureFixture[str]) -> None:
    """Every command's --set help gives a key of a concern that command uses, and the key loads."""
    import re

    from cmdragons.runtime.settings import load_settings

    fits = {"sim": "sim.", "play": "strategy.", "vision": "vision.", "bench": "planner.", "node": "runtime.",
            "replay": "runtime.", "vision calibrate": "cameras.", "vision tune": "vision."}
    for command, concern in fits.items():
        try:
            code, out, _ = run([*command.split(), "-h"], capsys)
        except SystemExit as exc:  # vision calibrate and tune: their own parser's -h
            code, out = int(exc.code or 0), capsys.readouterr().out
        assert code == 0, command
        example = re.search(r"e\.g\.\s+--set\s+(\S+)", " ".join(out.split()))
        assert example is not None, command
        assert example.group(1).startswith(concern), (command, example.group(1))
        load_settings(None, [example.group(1)])  # a real key with a valid value
