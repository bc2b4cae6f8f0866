"""The import rules of DESIGN.md, kept by scanning the source."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FLOOR = {"cmdragons.config", "cmdragons.geometry", "cmdragons.messages", "cmdragons.camera", "cmdragons.recording",
         "cmdragons.videoio", "cmdragons._kernels"}
PROJECT = ("cmdragons", "vision", "strategy", "sim")


def imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.add(node.module)
    return out


def sources(package: str) -> list[Path]:
    return sorted((ROOT / package.replace(".", "/")).rglob("*.py"))


def project_imports(path: Path) -> set[str]:
    return {m for m in imports(path) if m.split(".")[0] in PROJECT}


@pytest.mark.parametrize("module", sorted(FLOOR))
def test_floor_imports_only_the_floor(module: str) -> None:
    path = ROOT / (module.replace(".", "/") + ".py")
    assert project_imports(path) <= FLOOR, path


@pytest.mark.parametrize("path", sources("sim"), ids=lambda p: p.name)
def test_sim_never_imports_vision_strategy_or_the_brain(path: Path) -> None:
    bad = {m for m in project_imports(path) if not (m in FLOOR or m.split(".")[0] == "sim")}
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize(
    "path",
    [p for pkg in ("vision", "strategy", "cmdragons") for p in sources(pkg)
     if "runtime" not in p.parts and "bench" not in p.parts and p.name != "cli.py"],
    ids=lambda p: str(p.relative_to(ROOT)),
)  # fmt: skip
def test_algorithms_import_no_middleware_physics_or_plotting(path: Path) -> None:
    bad = {m for m in imports(path) if m.split(".")[0] in {"zenoh", "pymunk", "matplotlib"}}
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize(
    "path", [p for pkg in PROJECT for p in sources(pkg) if p != ROOT / "cmdragons" / "videoio.py"],
    ids=lambda p: str(p.relative_to(ROOT)),
)  # fmt: skip
def test_only_videoio_imports_pyav(path: Path) -> None:
    assert "av" not in {m.split(".")[0] for m in imports(path)}, f"{path} imports PyAV: go through cmdragons.videoio"
