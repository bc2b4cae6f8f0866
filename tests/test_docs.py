"""The docs site builds with mkdocs, warnings as errors: every page in the navigation, every link
and anchor found, the generated references and results tables in place."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("material") is None,
                    reason="mkdocs and mkdocs-material are not installed (pip install -e '.[docs]')")
def test_the_docs_build_strict(tmp_path: Path) -> None:
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, capture_output=True, text=True, env={"NO_MKDOCS_2_WARNING": "1", "PATH": ""},
                         timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    cli = (tmp_path / "site" / "reference" / "cli" / "index.html").read_text(encoding="utf-8")
    config = (tmp_path / "site" / "reference" / "config" / "index.html").read_text(encoding="utf-8")
    bench = (tmp_path / "site" / "benchmarks" / "index.html").read_text(encoding="utf-8")
    assert "cmdragons play" in cli and "--opponent-set" in cli and "--fit-principal-point" in cli
    assert "max_speed_m_s" in config and "errt.step_m" in config
    assert "frame_to_command_in_process" in bench and "0ab35a7" in bench
    assert (tmp_path / "site" / "img" / "match.png").is_file()
