"""What a play run's own output says: read back from its MCAP log, checked, and drawn on one page.

:class:`RunCollector` gathers a run's figures from the bus's own messages (topics truth,
world/<ours>, referee, events and report/<ours>) into arrays: as the match runs
(:class:`ReportStage`, a subscriber like the logger) or from ``run.mcap`` afterwards
(:func:`load_run`). :func:`run_warnings` says what looks wrong (a ball or an
own robot vision never or seldom saw, commands the simulator clamped, a match slower than real
time). :func:`write_report` draws the match report PNG with matplotlib: the shot map, possession
and passes over time, the robots' traces, and the stage timings of summary.json.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cmdragons.messages import KickPurpose
from cmdragons.runtime.bus import BaseStage, Publish
from cmdragons.runtime.topics import ANY, Contract, Port

__all__ = ["ReportStage", "RunCollector", "RunData", "load_run", "run_warnings", "write_report"]

SELDOM = 0.5  # an object tracked as visible in fewer than this fraction of the frames is "seldom seen"
_POSSESSION_M = 0.15  # a robot within this of the ball (centre to centre) has it


@dataclass
class RunData:
    """A play run read back from its MCAP log. Times in s, positions field frame in m."""

    ours: str = "blue"
    t: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))  # /truth times
    ball: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))  # true ball per frame
    traces: dict[tuple[str, int], NDArray[np.float64]] = field(default_factory=dict)  # true (n, 3): t, x, y
    possession: list[str | None] = field(default_factory=list)  # per /truth frame: "blue", "yellow" or None
    ball_seen: float = 0.0  # fraction of /world frames with the ball tracked as visible
    ball_tracked: float = 0.0  # ... with the ball tracked at all (seen, or hidden in a robot's mouth)
    robot_seen: dict[int, float] = field(default_factory=dict)  # own robot id -> fraction of /world frames
    kicks: list[dict[str, Any]] = field(default_factory=list)  # /events of type kick, with x, y of the ball
    goals: list[dict[str, Any]] = field(default_factory=list)
    score_t: list[tuple[float, int, int]] = field(default_factory=list)  # (t, blue, yellow) at each change

    @property
    def frames(self) -> int:
        return len(self.t)


class RunCollector:
    """Gathers a :class:`RunData` from the bus's messages as they come: a play's own stage
    (:class:`ReportStage`) or a log read back (:func:`load_run`). ``topics``: what it reads.
    ``positions``: the topic the ball's and robots' positions come from: the simulator's truth, or
    (a simulator of someone else's, which tells us no truth) our tracked world."""

    def __init__(self, ours: str = "blue", positions: str = "truth") -> None:
        self.ours = ours
        self.positions = positions
        self.topics = tuple(dict.fromkeys((positions, "truth", f"world/{ours}", f"report/{ours}", "referee",
                                           "events")))
        self._run = RunData(ours=ours)
        self._times: list[float] = []
        self._balls: list[tuple[float, float]] = []
        self._traces: dict[tuple[str, int], list[tuple[float, float, float]]] = {}
        self._world_frames = 0
        self._ball_visible = 0
        self._ball_tracked = 0
        self._robot_visible: dict[int, int] = {}
        self._actions: dict[int, KickPurpose] = {}  # our robots' actions as the latest report had them

    def take(self, topic: str, message: Any) -> None:
        """One message of ``topic`` (one of :attr:`topics`, without the log's leading slash)."""
        run = self._run
        if topic == self.positions and message.ball is not None:
            t, b = message.t, message.ball
            self._times.append(t)
            self._balls.append((b.x, b.y))
            near, holder = _POSSESSION_M, None
            for r in message.robots:
                self._traces.setdefault((r.team, r.id), []).append((t, r.x, r.y))
                dist = math.hypot(r.x - b.x, r.y - b.y)
                if dist < near:
                    near, holder = dist, r.team
            run.possession.append(holder)
        if topic == f"world/{self.ours}":
            self._world_frames += 1
            if message.ball is not None:
                self._ball_tracked += 1
                self._ball_visible += bool(message.ball.visible)
            for r in message.robots:
                if r.team == self.ours and r.visible:
                    self._robot_visible[r.id] = self._robot_visible.get(r.id, 0) + 1
        elif topic == f"report/{self.ours}":
            self._actions = dict(message.actions)
        elif topic == "referee":
            score = (message.score_blue, message.score_yellow)
            if not run.score_t or run.score_t[-1][1:] != score:
                run.score_t.append((float(message.t), *score))
        elif topic == "events" and message.events:
            for e in message.to_dict()["events"]:
                if e.get("type") == "kick":
                    if e.get("team") == self.ours:
                        e = {**e, "action": self._actions.get(int(e["id"]))}  # what the strategy meant it for
                    if self._balls:
                        e = {**e, "x": self._balls[-1][0], "y": self._balls[-1][1]}
                    run.kicks.append(e)
                elif e.get("type") == "goal":
                    run.goals.append(e)

    def result(self) -> RunData:
        """The run so far."""
        run, frames = self._run, self._world_frames
        run.t = np.array(self._times)
        run.ball = np.array(self._balls).reshape(-1, 2)
        run.traces = {k: np.array(v) for k, v in self._traces.items()}
        run.ball_seen = self._ball_visible / frames if frames else 0.0
        run.ball_tracked = self._ball_tracked / frames if frames else 0.0
        run.robot_seen = {rid: self._robot_visible.get(rid, 0) / frames if frames else 0.0
                          for team, rid in run.traces if team == self.ours}
        return run


class ReportStage(BaseStage):
    """The match report's data gathered as the match runs (a subscriber: what :func:`load_run`
    would read back from the log, without reading it)."""

    def __init__(self, ours: str = "blue", positions: str = "truth") -> None:
        self.collector = RunCollector(ours, positions)
        self.contract = Contract("report", tuple(Port(t, ANY) for t in self.collector.topics))

    def on_message(self, topic: str, message: Any, publish: Publish) -> None:
        self.collector.take(topic, message)


def load_run(path: str | Path, ours: str = "blue") -> RunData:
    """Read ``run.mcap`` (see the module docstring)."""
    from cmdragons.runtime.log import read_log

    collector = RunCollector(ours)
    for topic, _t, message in read_log(path, {"/" + t for t in collector.topics}):
        collector.take(topic[1:], message)
    return collector.result()


def _seen(fraction: float) -> str | None:
    if fraction <= 0.0:
        return "never"
    if fraction < SELDOM:
        return f"seldom ({100 * fraction:.0f} % of the frames)"
    return None


def run_warnings(run: RunData, summary: dict[str, Any]) -> list[str]:
    """What looks wrong in a run, one sentence each (empty when nothing does)."""
    out = []
    if summary.get("perception") != "truth" and run.frames:
        # a ball hidden in a robot's mouth (carried, placed) is tracked though no camera sees it
        how = _seen(run.ball_tracked)
        if how:
            out.append(f"our tracker had the ball {how} (seen in {100 * run.ball_seen:.0f} %): the team could "
                       "hardly play (check the vision colours: cmdragons vision tune)")
        for rid, fraction in sorted(run.robot_seen.items()):
            how = _seen(fraction)
            if how:
                out.append(f"our tracker saw our robot {rid} {how} (check its pattern and the vision colours)")
    clamped = summary.get("command_faults", {}).get("clamped", 0)
    if clamped:
        out.append(f"{clamped} command{'s were' if clamped != 1 else ' was'} clamped by the simulator to the "
                   "robots' limits (the team asked for more than the robots can do)")
    for name in ("non_finite", "timed_out", "unknown_robot"):
        n = summary.get("command_faults", {}).get(name, 0)
        if n:
            out.append(f"{n} command fault{'s' if n != 1 else ''} of kind {name} (see summary.json command_faults)")
    rtf = summary.get("realtime_factor")
    if rtf is not None and rtf < 1.0:
        compiled = ", not counting the first-run compile" if summary.get("compile_seconds", 0) >= 1 else ""
        out.append(f"the match ran slower than real time ({rtf}x{compiled}): the team would fall behind a real game")
    return out


def pyplot() -> Any:
    """matplotlib's pyplot on the Agg backend (files only, no screen), imported on first use."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


# how each pass ended (cmdragons/runtime/pass_record.py), and its colour in the report
PASS_END_COLOURS = {"received": "tab:green", "too_fast": "tab:olive", "intercepted": "tab:red", "out": "tab:gray",
                    "stopped": "0.6", "late": "tab:orange", "missed": "tab:purple", "too_slow": "tab:brown",
                    "reassigned": "tab:pink", "timeout": "tab:cyan"}


def _draw_passes(ax_map: Any, ax_time: Any, run: RunData, passes: dict[str, Any], field_axes: Any) -> None:
    """Each pass from where it was kicked to its target, coloured by how it ended; beside it each
    pass's ball arrival at the target against its receiver's and the closest opponent's predicted
    interception (s after the kick)."""
    records = passes.get("list", [])
    kicks = {round(float(e["t"]), 4): (e["x"], e["y"]) for e in run.kicks if "x" in e}
    ends = passes.get("ends", {})
    field_axes(ax_map, "Our passes, kick to target, by how they ended")
    seen: set[str] = set()
    for r in records:
        start, target, end = kicks.get(round(float(r["t_kick"]), 4)), r.get("target"), r.get("end")
        colour = PASS_END_COLOURS.get(str(end), "black")
        label = None if end in seen else f"{end} ({ends.get(str(end), 0)})"
        seen.add(str(end))
        if start is not None and target is not None:
            ax_map.annotate("", xy=target, xytext=start, arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.5})
            ax_map.scatter([start[0]], [start[1]], color=colour, s=15, label=label)
        elif start is not None:
            ax_map.scatter([start[0]], [start[1]], color=colour, marker="x", s=40, label=label)
    if seen:
        ax_map.legend(loc="upper left", fontsize=8)
    ax_time.set_title("Per pass: ball at target (o), receiver there (^),\nclosest opponent's predicted "
                      "interception (x)", fontsize=10)
    for k, r in enumerate(records):
        colour = PASS_END_COLOURS.get(str(r.get("end")), "black")
        for key, marker in (("ball_s", "o"), ("receiver_s", "^"), ("opponent_s", "x")):
            if r.get(key) is not None:
                ax_time.scatter([r[key]], [k], marker=marker, color=colour, s=40)
        ax_time.text(0.0, k + 0.25, f"{r.get('end')} {r.get('speed_m_s', float('nan')):.1f} m/s", fontsize=7)
    ax_time.set_xlabel("s after the kick")
    ax_time.set_ylabel("pass")
    ax_time.set_ylim(-0.5, max(len(records), 1) - 0.5 + 0.5)


def write_report(run: RunData, summary: dict[str, Any], path: str | Path,
                 half_size_m: tuple[float, float] = (4.5, 3.0)) -> Path:
    """The one-page match report PNG (see the module docstring) of a field of ``half_size_m``
    (half length, half width; m); returns its path."""
    from matplotlib.patches import Rectangle

    plt = pyplot()

    path = Path(path)
    fig = plt.figure(figsize=(14, 14), dpi=100)
    grid = fig.add_gridspec(4, 2, height_ratios=[1.25, 1.25, 0.6, 1.0])
    score = summary.get("score", {})
    fig.suptitle(f"Match report: blue (us) {score.get('blue', 0)} : {score.get('yellow', 0)} yellow (them), "
                 f"{summary.get('seconds', 0):.0f} s against {summary.get('opponent')} "
                 f"({summary.get('perception')}), seed {summary.get('seed')}"
                 + ("  [interrupted]" if summary.get("interrupted") else ""), fontsize=13)
    fl, fw = half_size_m
    hl = max([fl] + [float(abs(tr[:, 1]).max()) for tr in run.traces.values() if len(tr)])
    hw = max([fw] + [float(abs(tr[:, 2]).max()) for tr in run.traces.values() if len(tr)])

    def field_axes(ax: Any, title: str) -> None:
        ax.add_patch(Rectangle((-fl, -fw), 2 * fl, 2 * fw, fill=False, lw=1, color="0.5"))
        ax.axvline(0.0, color="0.7", lw=0.8)
        ax.set_xlim(-hl - 0.3, hl + 0.3)
        ax.set_ylim(-hw - 0.3, hw + 0.3)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=11)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")

    # shot map: where each of our kicks started, by what it was for
    ax = fig.add_subplot(grid[0, 0])
    field_axes(ax, "Our kicks (where the ball was): shots, passes, clears; goals ringed")
    marks = {KickPurpose.SHOT: ("o", "tab:red"), KickPurpose.PASS: ("^", "tab:purple"),
             KickPurpose.CLEAR: ("s", "tab:gray")}
    for kind, (m, c) in marks.items():
        k = [e for e in run.kicks if e.get("team") == run.ours and e.get("action") == kind]
        ax.scatter([e["x"] for e in k], [e["y"] for e in k], marker=m, color=c, s=50,
                   label=f"{kind} ({len(k)})")
    goals = [g for g in run.goals if g.get("scoring_team") == run.ours]
    if goals:
        ax.scatter([g["x"] for g in goals], [g["y"] for g in goals], s=200, facecolors="none", edgecolors="gold",
                   linewidths=2, label=f"our goals ({len(goals)})")
    ax.legend(loc="upper left", fontsize=8)

    # robot traces
    ax = fig.add_subplot(grid[0, 1])
    field_axes(ax, "Robot traces (truth): blue us, yellow them; ball black")
    for (team, _rid), tr in sorted(run.traces.items()):
        ax.plot(tr[:, 1], tr[:, 2], lw=0.8, color="tab:blue" if team == run.ours else "goldenrod",
                alpha=0.9 if team == run.ours else 0.5)
    if len(run.ball):
        ax.plot(run.ball[:, 0], run.ball[:, 1], lw=0.6, color="black", alpha=0.6)

    _draw_passes(fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1]), run, summary.get("passes", {}),
                 field_axes)

    # possession and passes over time
    ax = fig.add_subplot(grid[2, :])
    ax.set_title("Possession over time (robot within 0.15 m of the ball) and our kicks", fontsize=11)
    if run.frames:
        code = np.array([1.0 if p == run.ours else (-1.0 if p is not None else 0.0) for p in run.possession])
        ax.fill_between(run.t, 0, code, where=code > 0, step="mid", color="tab:blue", label="blue (us)")
        ax.fill_between(run.t, 0, code, where=code < 0, step="mid", color="goldenrod", label="yellow")
        ours_share = float(np.mean(code > 0))
        theirs_share = float(np.mean(code < 0))
        ax.text(0.01, 0.92, f"us {100 * ours_share:.0f} %, them {100 * theirs_share:.0f} %, "
                f"loose {100 * (1 - ours_share - theirs_share):.0f} %", transform=ax.transAxes, fontsize=9)
        for kind, (_m, c) in marks.items():
            ts = [e["t"] for e in run.kicks if e.get("team") == run.ours and e.get("action") == kind]
            if ts:
                ax.vlines(ts, -1.0, 1.0, colors=c, lw=1.2, label=kind)
        ax.set_xlim(0, max(float(run.t[-1]), 1e-3))
    passes = summary.get("passes", {})
    ax.set_xlabel(f"time (s); passes {passes.get('completed', 0)}/{passes.get('tried', 0)} completed")
    ax.set_yticks([-1, 0, 1], ["them", "loose", "us"])
    ax.legend(loc="upper right", fontsize=8, ncol=5)

    # timings
    ax = fig.add_subplot(grid[3, :])
    cycle = summary.get("cycle_ms", {})
    names = [n for n in ("render", "vision", "tracker", "brain", "strategy", "planning_control", "safety",
                         "physics_and_opponent", "frame") if n in cycle]
    y = np.arange(len(names))
    ax.barh(y - 0.2, [cycle[n]["median"] for n in names], height=0.4, color="tab:green", label="median")
    ax.barh(y + 0.2, [cycle[n]["p95"] for n in names], height=0.4, color="tab:olive", label="95th percentile")
    ax.set_yticks(y, names)
    ax.invert_yaxis()
    ax.set_xlabel("ms per frame")
    rtf = summary.get("realtime_factor")
    compile_s = summary.get("compile_seconds", 0)
    compiled = f", not counting {compile_s:.0f} s of first-run compile" if compile_s >= 1 else ""
    ax.set_title(f"Stage timings per camera frame (brain and vision are ours); {rtf}x real time{compiled}",
                 fontsize=11)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(path)
    plt.close(fig)
    return path
