"""The summary lines the commands share."""

from __future__ import annotations

from typing import Any

__all__ = ["plural", "rules_line"]


def plural(n: int, word: str, many: str | None = None) -> str:
    """``n`` and the word, in the plural unless ``n`` is 1."""
    return f"{n} {word if n == 1 else (many or word + 's')}"


def rules_line(rules: dict[str, Any], ours: str = "blue") -> str:
    """The referee's calls per team (``ours``: our team's colour): fouls by kind, cards, placements
    tried and succeeded."""
    parts = []
    for team in ("blue", "yellow"):
        who = "us" if team == ours else "them"
        fouls = rules["fouls"][team]
        kinds = ", ".join(f"{k.replace('_', ' ')} {n}" for k, n in fouls.items() if k != "total")
        cards, placed = rules["cards"][team], rules["placements"][team]
        median = f", median {placed['median_s']:.1f} s" if placed["median_s"] is not None else ""
        cut = f", {placed['cut_short']} cut short" if placed.get("cut_short") else ""
        shot = rules.get("shootout", {}).get(team, {})
        shootout = f", shootout {shot['scored']}/{shot['taken']}" if shot.get("taken") else ""
        parts.append(f"{team} ({who}) {plural(fouls['total'], 'foul')}{f' ({kinds})' if kinds else ''}, "
                     f"cards {cards['yellow']} yellow {cards['red']} red, placements {placed['succeeded']}/"
                     f"{placed['tried']}{median}{cut}{shootout}")
    return "rules: " + "; ".join(parts)
