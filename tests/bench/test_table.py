"""Bench tables fit 100 columns, cut no name and keep text as written."""

from __future__ import annotations

import pytest

from cmdragons.bench import TABLE_WIDTH, header, print_table

HEADERS = [("median_ms", "median\nms"), ("max_speed_m_s", "max speed\nm/s"), ("success_rate", "success rate"),
           ("ns_per_query", "ns per query")]


@pytest.mark.parametrize(("metric", "shown"), HEADERS)
def test_header_puts_the_unit_under_the_name(metric: str, shown: str) -> None:
    assert header(metric) == shown


def test_wide_table_fits_and_cuts_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    long = "moving_errt_cached_waypoints_scene_dense"
    metrics = {f"metric_{k}_ms": 1000.0 + k for k in range(14)}
    rows = [{"name": long, **metrics}, {"name": "static", **metrics},
            {"name": "ompl_baselines", "note": "skipped: pip install 'cmdragons[bench]'"}]
    print_table("planning", rows)
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert max(len(line) for line in lines) <= TABLE_WIDTH
    assert "…" not in out
    text = " ".join(line.strip("│┃ ") for line in lines)
    for word in long.split("_"):
        assert word in text
    for k in range(14):
        assert f"metric {k}" in out and f"{1000 + k}" in out
    assert "pip install 'cmdragons[bench]'" in out


def test_play_options_are_refused_for_another_suite(capsys: pytest.CaptureFixture[str]) -> None:
    from cmdragons.cli import main

    assert main(["bench", "sim", "--matches", "2"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "cmdragons bench: --matches is for the play suite, not sim"
