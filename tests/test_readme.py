"""Every command line of the README and the docs runs as written (with short durations, outputs in
the test's folder, and the ports of this test's own), the README's results table is the one the
benches' JSON gives, and the generated references cover every flag and every config file."""

from __future__ import annotations

import shlex
import socket
import sys
from pathlib import Path

import pytest

from cmdragons.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
SECONDS = "0.3"  # simulated seconds each example runs for
sys.path.insert(0, str(ROOT / "docs"))

import reference  # noqa: E402
import results  # noqa: E402


def code_lines(text: str) -> list[str]:
    """Every `cmdragons ...` line of a page's indented code blocks that is an example (not a
    synopsis with [--options] or a line of output), its comment cut off. Lines that start a node
    in one of several terminals (`.venv/bin/cmdragons node ...`) are left to the runtime's tests."""
    lines = []
    for line in text.splitlines():
        if not line.startswith("    "):
            continue
        text = line.strip()
        text = text.rsplit("&& .venv/bin/", 1)[-1] if "&& .venv/bin/cmdragons" in text else text
        if not text.startswith("cmdragons ") or " [--" in text or "(see " in text:
            continue
        lines.append(text.split("  #", 1)[0].strip())
    return lines


def examples() -> list[tuple[str, str]]:
    """(page, line) of every example, each line once (the first page that has it)."""
    seen: dict[str, str] = {}
    for page in PAGES:
        for line in code_lines(page.read_text(encoding="utf-8")):
            seen.setdefault(line, str(page.relative_to(ROOT)))
    return [(page, line) for line, page in seen.items()]


EXAMPLES = examples()


def test_the_examples_were_found() -> None:
    readme = code_lines((ROOT / "README.md").read_text(encoding="utf-8"))
    assert readme[0] == "cmdragons play"  # the first command of the README
    assert any(line.startswith("cmdragons vision ") for line in readme)
    pages = {page for page, _ in EXAMPLES}
    assert "docs/getting-started.md" in pages and "docs/guides/cameras.md" in pages
    assert len(EXAMPLES) >= 15


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """What the vision examples read: a recording in H.264 video and one in PNG frames."""
    base = tmp_path_factory.mktemp("recordings")
    out = {}
    for key, fmt in (("mp4", "h264"), ("png", "png")):
        assert main(["sim", "--seconds", SECONDS, "--record", "--format", fmt, "--out", str(base / key),
                     "--no-progress"]) == 0
        out[key] = base / key
    return out


def _free_port(kind: int) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def own_ports() -> list[str]:
    """--set overrides that give a match ports of its own (free now), so that examples run side by
    side (pytest -n, other checkouts on this machine) never hear each other."""
    udp = [f"protocols.{key}={_free_port(socket.SOCK_DGRAM)}" for key in (
        "vision.port", "tracker.port", "referee.port", "grsim.port", "grsim.vision_port",
        "simulation.control_port", "simulation.blue_port", "simulation.yellow_port")]
    tcp = [f"runtime.zenoh.router=tcp/127.0.0.1:{_free_port(socket.SOCK_STREAM)}"]
    return [arg for setting in udp + tcp for arg in ("--set", setting)]


def runnable(line: str, rec: dict[str, Path], tmp: Path) -> list[str]:
    """The example's arguments with the placeholders made real, short, and in ``tmp``."""
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
        if a in ("--out", "--snapshot", "--json", "--figures") and not Path(argv[i + 1]).is_absolute():
            argv[i + 1] = str(tmp / argv[i + 1])
    if argv[0] in ("sim", "play"):
        if "--seconds" in argv:
            argv[argv.index("--seconds") + 1] = SECONDS
        else:
            argv += ["--seconds", SECONDS]
    if argv[0] == "play":
        argv += own_ports()
    if argv[0] in ("sim", "play", "vision"):
        argv += ["--no-progress"]
        if "--out" not in argv:
            argv += ["--out", str(tmp / "out")]
    return argv


@pytest.mark.slow
@pytest.mark.parametrize(("page", "line"), EXAMPLES, ids=[f"{p}: {line}" for p, line in EXAMPLES])
def test_example_runs(page: str, line: str, recordings: dict[str, Path], tmp_path: Path,
                      capsys: pytest.CaptureFixture[str]) -> None:
    argv = runnable(line, recordings, tmp_path)
    assert main(argv) == 0, (page, argv, capsys.readouterr())
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    assert out.strip(), argv  # it says what it did


def test_the_readme_is_at_most_200_lines() -> None:
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 200


def test_the_readme_results_table_is_the_one_the_json_gives() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert results.replace(text, results.headline_table()) == text, "run: python docs/results.py --write README.md"
    for data in results.load():  # every results file says where it was measured
        assert len(data["commit"]) >= 7 and data["date"][:2] == "20" and data["machine"]


def test_every_flag_of_every_command_is_in_the_command_reference() -> None:
    text = reference.cli_markdown()
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    for name, command in sub.choices.items():  # type: ignore[union-attr]
        assert f"## `cmdragons {name}`" in text
        for action in command._actions:
            for flag in action.option_strings:
                assert flag in text, f"{name} {flag}"
    for tool, flag in (("calibrate", "--lines"), ("tune", "--labels")):
        assert f"## `cmdragons vision {tool}`" in text and flag in text


def test_every_config_key_is_in_the_configuration_reference() -> None:
    from cmdragons.config import load_yaml

    text = reference.config_markdown()
    for path in sorted((ROOT / "configs").glob("*.yaml")):
        assert f"## `{path.name}`" in text, path.name

        def keys(node: object, prefix: str) -> list[str]:
            if not isinstance(node, dict):
                return [prefix]
            return [k for key, value in node.items() for k in keys(value, f"{prefix}{key}.")] or [prefix]

        for key in keys(load_yaml(path), ""):  # every key of the shipped file is listed
            key = key.rstrip(".")
            assert f"`{key}`" in text or f"**`{key}`**" in text, f"{path.name}: {key}"
