"""``python -m cmdragons.estimation [lander|steer|localise|slam|particle ...]``: run the worked examples
of docs/estimation.md on their simulated runs and print how each filter did."""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence

import numpy as np

from cmdragons.estimation import filters
from cmdragons.estimation.filters import EKFLocalisation, EKFSlam, ParticleLocalisation
from cmdragons.estimation.simulate import simulate_run, simulate_steered_run

EXAMPLES = ("lander", "steer", "localise", "slam", "particle")
WHEELBASE_M = 0.5  # the steered example's vehicle


def _lander() -> str:
    run = filters.simulate_lander(filters.Lander(), seed=1)
    late = slice(len(run["t"]) // 4, None)
    radar = float(np.sqrt(np.mean((run["radar"][late] - run["altitude"][late]) ** 2)))
    est = float(np.sqrt(np.mean((run["est_altitude"][late] - run["altitude"][late]) ** 2)))
    return (
        f"lander: landed after {run['t'][-1]:.0f} s at {abs(run['speed'][-1]):.1f} m/s; altitude RMS error "
        f"{est:.2f} m filtered, {radar:.2f} m radar alone"
    )


def _pose_filters(name: str) -> str:
    steered = name == "steer"
    run = simulate_steered_run(seed=0, steps=600, wheelbase_m=WHEELBASE_M) if steered else simulate_run(seed=0)
    p0 = np.diag([0.01, 0.01, 0.001])
    x0 = run.truth[0]
    if steered:
        f: EKFLocalisation | EKFSlam | ParticleLocalisation = filters.EKFSteered(run.landmarks, x0, p0, run.sensor_cov,
                                                                         run.dt_s, WHEELBASE_M)
    elif name == "localise":
        f = EKFLocalisation(run.landmarks, x0, p0, run.sensor_cov)
    elif name == "slam":
        f = EKFSlam(len(run.landmarks), x0, p0, run.sensor_cov)
    else:
        f = ParticleLocalisation(run.landmarks, x0, p0, run.sensor_cov, n=500, seed=0)
    err, nees = [], []
    for k in range(len(run.odometry)):
        f.predict(run.odometry[k], run.odometry_cov)
        f.update(run.sightings[k])
        err.append(math.dist(f.pose[:2], run.truth[k + 1][:2]))
        nees.append(f.nees(run.truth[k + 1]))
    extra = ""
    if isinstance(f, EKFSlam):
        seen = np.flatnonzero(f.known)
        lm = np.median([math.dist(f.landmark(int(i)), run.landmarks[i]) for i in seen])
        extra = f", {len(seen)} landmarks mapped (median error {lm:.3f} m)"
    return (
        f"{name}: {len(run.odometry)} steps, position error median {np.median(err):.3f} m, max {max(err):.3f} m; "
        f"mean NEES {np.mean(nees):.2f} (3 for a consistent filter){extra}"
    )


def main(argv: Sequence[str] | None = None) -> int:
    names = list(sys.argv[1:] if argv is None else argv) or list(EXAMPLES)
    bad = [n for n in names if n not in EXAMPLES]
    if bad:
        print(f"estimation: unknown example {bad[0]!r}; examples: {', '.join(EXAMPLES)}", file=sys.stderr)
        return 2
    for name in names:
        print(_lander() if name == "lander" else _pose_filters(name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
