"""The README's examples run as written (with short durations), every flag of every command is in
the README, and every config file is in its table."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from cmdragons.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
SECONDS = "0.3"  # simulated seconds each example runs for


def code_lines() -> list[str]:
    """Every `cmdragons ...` line of the README's indented code blocks that is an example (not a
    synopsis with [--options] or a line of output), its comment cut off."""
    lines = []
    for line in README.splitlines():
        if not line.startswith("    "):
            continue
        text = line.strip()
        text = text.rsplit("&& .venv/bin/", 1)[-1] if "&& .venv/bin/cmdragons" in text else text
        if not text.startswith("cmdragons ") or " [--" in text or "(see " in text:
            continue
        lines.append(text.split("  #", 1)[0].strip())
    return lines


EXAMPLES = code_lines()


def test_the_examples_were_found() -> None:
    assert "cmdragons play" in EXAMPLES  # the first command of the README
    assert len(EXAMPLES) >= 8
    assert any(line.startswith("cmdragons vision ") for line in EXAMPLES)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """What the vision examples read: a recording in H.264 video and one in PNG frames."""
    base = tmp_path_factory.mktemp("recordings")
    out = {}
    for key, fmt in (("mp4", "h264"), ("png", "png")):
        assert main(["sim", "--seconds", SECONDS, "--record", "--format", fmt, "--out", str(base / key),
                     "--no-progress"]) == 0  # fmt: skip
        out[key] = base / key
    return out


def runnable(line: str, rec: dict[str, Path], tmp: Path) -> list[str]:
    """The example's arguments with the README's placeholders made real, short, and in ``tmp``."""
    mp4, png = rec["mp4"], rec["png"]
    line = line.replace("logs/<time>-sim", str(mp4)).replace("cam0.mp4", str(mp4 / "camera_0.mp4"))
    line = line.replace("cam1.mp4", str(mp4 / "camera_1.mp4")).replace("frames/", str(png / "camera_0") + "/")
    line = line.replace("'cam1/*.png'", f"'{png}/camera_1/*.png'")
    frame = sorted((png / "camera_0").glob("*.png"))[0]
    line = line.replace("--lines frame.png", f"--lines {frame}")
    argv = shlex.split(line)[1:]
    if argv[:2] in (["vision", "calibrate"], ["vision", "tune"]):  # they write a config: into the test's folder
        overlay = ["--overlay", str(tmp / "o.png")] if "--lines" in argv else []
        return argv + ["--out", str(tmp / "out.yaml")] + overlay
    for i, a in enumerate(argv[:-1]):  # outputs go to the test's folder
        if a in ("--out", "--snapshot", "--json") and not Path(argv[i + 1]).is_absolute():
            argv[i + 1] = str(tmp / argv[i + 1])
    if argv[0] in ("sim", "play"):
        if "--seconds" in argv:
            argv[argv.index("--seconds") + 1] = SECONDS
        else:
            argv += ["--seconds", SECONDS]
    if argv[0] in ("sim", "play", "vision"):
        argv += ["--no-progress"]
        if "--out" not in argv:
            argv += ["--out", str(tmp / "out")]
    return argv


@pytest.mark.parametrize("line", EXAMPLES)
def test_readme_example_runs(line: str, recordings: dict[str, Path], tmp_path: Path,
                             capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    argv = runnable(line, recordings, tmp_path)
    assert main(argv) == 0, (argv, capsys.readouterr())
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    assert out.strip(), argv  # it says what it did


@pytest.mark.parametrize("command", ["sim", "play", "vision", "bench"])
def test_every_flag_is_documented(command: str) -> None:
    parser = build_parser()
    sub = next(a for a in parser._subparsers._actions if a.dest == "command").choices[command]  # type: ignore[union-attr]
    for action in sub._actions:
        for flag in action.option_strings:
            if flag.startswith("--") and flag != "--help":
                assert re.search(rf"{re.escape(flag)}\b", README), f"{command} {flag} is not in the README"


def test_every_config_file_is_in_the_table() -> None:
    for path in sorted((ROOT / "configs").glob("*.yaml")):
        assert f"| `{path.name}` |" in README, path.name
