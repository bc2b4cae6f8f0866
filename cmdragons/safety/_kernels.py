"""numba kernels of Dynamics Safety Search (Bruce 2006 ch. 5).

Field frame, metres, seconds. A robot's command is modelled as one control period ``dt`` of
acceleration ``a`` (the velocity command v + a dt, reached as fast as the motors can and then held)
followed by braking at the maximum deceleration ``brake`` along its velocity until it rests (§5.1,
§5.3): the robot model's :func:`~cmdragons.control.acceleration.trajectory`, a short list of parabolic
segments ``(t0, t1, px, py, vx, vy, ax, ay)``.

Two trajectories collide when their centres come closer than ``R`` (two radii plus a margin) at
the same time. On each time interval where both are single parabolas the squared distance minus
``R(t)^2`` is a quartic in time; its minimum over the interval is at an end or at a root of the
cubic derivative, found by bisection inside the monotone pieces between the cubic's turning points.
An opponent is a disc moving at its current velocity whose radius grows by ``accel t^2 / 2``: every
place it can reach by accelerating at most ``accel`` in any direction.

A pair already closer than ``R`` at the start (noise, a push) counts as safe while the distance
does not shrink below its starting value: otherwise no command, not even the stop, could pass and
the pair would freeze in contact.

Plain-numpy references of these kernels live in :mod:`cmdragons.safety._reference`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmdragons.control.acceleration import N_SEG, Limits, clip_accel, feasible, seg_at, stop_accel, trajectory
from cmdragons.safety.static_check import static_hits
from cmdragons.sorting import argsort_stable, sort_small

# the robot model's braking trajectory (N_SEG, trajectory, stop_accel) is the one of
# cmdragons.control.acceleration, shared with the navigators

_BISECT = 40


class DSSConfig(NamedTuple):
    """The search's numbers, by name (metres, seconds): the robot model and the margins of
    configs/safety.yaml ``dss`` turned into the distances the checks compare with."""

    dt: float  # control period: a command holds for this long
    own_radius: float  # kept between two own robots' centres (two radii and own_margin_m)
    pushed_radius: float  # ... instead, while an opponent may push one of them (two radii and pushed_margin_m)
    push_reach: float  # an opponent centre this close to an own robot's centre may push it
    own_growth: float  # m/s: the own distance kept grows by this per second of braking (velocity errors)
    opponent_radius: float  # kept between an own robot's centre and an opponent's (two radii and margin)
    opponent_accel: float  # m/s^2 an opponent may accelerate in any direction
    static_margin: float  # kept from walls and static obstacles
    static_step: float  # sample spacing of the static check

# statuses of a robot after the search
KEPT = 0  # its own command was safe
CHANGED = 1  # the safe sample nearest its command
STOPPED = 2  # nothing else was safe: the stop
STOP_ASKED = 3  # it asked to stop (always accepted)


@njit(cache=True)
def _poly(c: np.ndarray, t: float) -> float:
    return float((((c[4] * t + c[3]) * t + c[2]) * t + c[1]) * t + c[0])


@njit(cache=True)
def _dpoly(c: np.ndarray, t: float) -> float:
    return float(((4.0 * c[4] * t + 3.0 * c[3]) * t + 2.0 * c[2]) * t + c[1])


@njit(cache=True)
def quartic_min(c: np.ndarray, T: float) -> float:
    """Minimum of c0 + c1 t + ... + c4 t^4 over [0, T]."""
    best = min(_poly(c, 0.0), _poly(c, T))
    # turning points of the cubic derivative: roots of 12 c4 t^2 + 6 c3 t + 2 c2
    cuts = np.empty(4)
    cuts[0] = 0.0
    m = 1
    qa, qb, qc = 12.0 * c[4], 6.0 * c[3], 2.0 * c[2]
    if abs(qa) > 1e-15:
        disc = qb * qb - 4.0 * qa * qc
        if disc > 0.0:
            s = math.sqrt(disc)
            r1, r2 = (-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)
            if r1 > r2:
                r1, r2 = r2, r1
            for r in (r1, r2):
                if 0.0 < r < T:
                    cuts[m] = r
                    m += 1
    elif abs(qb) > 1e-15:
        r = -qc / qb
        if 0.0 < r < T:
            cuts[m] = r
            m += 1
    cuts[m] = T
    m += 1
    for i in range(m - 1):
        lo, hi = cuts[i], cuts[i + 1]
        flo, fhi = _dpoly(c, lo), _dpoly(c, hi)
        if flo < 0.0 < fhi:  # the quartic falls then rises: a minimum inside
            for _ in range(_BISECT):
                mid = 0.5 * (lo + hi)
                if _dpoly(c, mid) < 0.0:
                    lo = mid
                else:
                    hi = mid
            best = min(best, _poly(c, 0.5 * (lo + hi)))
    return best


@njit(cache=True)
def _gap_coeffs(
    d0x: float, d0y: float, d1x: float, d1y: float, ex: float, ey: float, r0: float, r1: float, r2: float
) -> np.ndarray:
    # |d0 + d1 t + e t^2|^2 - (r0 + r1 t + r2 t^2)^2 as quartic coefficients
    c = np.empty(5)
    c[0] = d0x * d0x + d0y * d0y - r0 * r0
    c[1] = 2.0 * (d0x * d1x + d0y * d1y) - 2.0 * r0 * r1
    c[2] = d1x * d1x + d1y * d1y + 2.0 * (d0x * ex + d0y * ey) - (r1 * r1 + 2.0 * r0 * r2)
    c[3] = 2.0 * (d1x * ex + d1y * ey) - 2.0 * r1 * r2
    c[4] = ex * ex + ey * ey - r2 * r2
    return c


@njit(cache=True)
def _interval_hits(
    d0x: float, d0y: float, d1x: float, d1y: float, ex: float, ey: float,
    r0: float, r1: float, r2: float, T: float,
) -> bool:
    """Does |d0 + d1 t + e t^2| fall below r0 + r1 t + r2 t^2 (r's >= 0) for some t in [0, T]?"""
    # cheap rejection: the distance cannot shrink faster than its derivative bounds allow
    lower = math.hypot(d0x, d0y) - math.hypot(d1x, d1y) * T - math.hypot(ex, ey) * T * T
    if lower > r0 + r1 * T + r2 * T * T:
        return False
    return quartic_min(_gap_coeffs(d0x, d0y, d1x, d1y, ex, ey, r0, r1, r2), T) < 0.0


@njit(cache=True)
def _reach(tr: np.ndarray) -> float:
    # a bound on how far the trajectory strays from its start: the path length of its segments
    total = 0.0
    for k in range(N_SEG - 1):
        h = tr[k, 1] - tr[k, 0]
        total += math.hypot(tr[k, 4], tr[k, 5]) * h + 0.5 * math.hypot(tr[k, 6], tr[k, 7]) * h * h
    return total


@njit(cache=True)
def pair_hits(ta: np.ndarray, tb: np.ndarray, radius: float, growth: float) -> bool:
    """Do two trajectories bring their centres closer than ``radius + growth t`` at the same time t?

    ``growth`` (m/s) covers errors in the two velocities the trajectories start from: braking at
    the same deceleration, a velocity off by dv puts the robot dv t away from its model until it
    rests. The kept distance never exceeds the starting one (a pair that starts closer than the
    grown distance only fails when it gets closer still, as a pair already closer than
    ``radius`` does)."""
    dx0, dy0 = ta[0, 2] - tb[0, 2], ta[0, 3] - tb[0, 3]
    d0 = math.hypot(dx0, dy0)
    t_end = max(ta[N_SEG - 1, 0], tb[N_SEG - 1, 0])
    if d0 > _reach(ta) + _reach(tb) + radius + growth * t_end:
        return False
    cap = d0 * (1.0 - 1e-9)
    r = min(radius, cap)
    # until t_cap the kept distance grows; from then on it is the starting distance
    t_cap = (cap - r) / growth if growth > 0.0 else math.inf
    # the breakpoints of both: [0, dt] share one segment each, then the two braking ends, and t_cap
    times = np.empty(N_SEG * 2 + 2)
    n = 0
    for k in range(N_SEG):
        times[n], times[n + 1] = ta[k, 0], tb[k, 0]
        n += 2
    times[n] = t_end
    times[n + 1] = min(t_cap, t_end)
    sort_small(times, n + 2)
    n += 1
    ka, kb = 0, 0
    for i in range(n):
        t0, t1 = times[i], times[i + 1]
        if t1 - t0 <= 1e-12:
            continue
        while ka < N_SEG - 1 and ta[ka, 1] <= t0 + 1e-12:
            ka += 1
        while kb < N_SEG - 1 and tb[kb, 1] <= t0 + 1e-12:
            kb += 1
        ax, ay, avx, avy = seg_at(ta, ka, t0)
        bx, by, bvx, bvy = seg_at(tb, kb, t0)
        ex, ey = 0.5 * (ta[ka, 6] - tb[kb, 6]), 0.5 * (ta[ka, 7] - tb[kb, 7])
        if t0 < t_cap - 1e-12:
            r0, r1 = r + growth * t0, growth
        else:
            r0, r1 = cap, 0.0
        if _interval_hits(ax - bx, ay - by, avx - bvx, avy - bvy, ex, ey, r0, r1, 0.0, t1 - t0):
            return True
    # both at rest after the last breakpoint
    ax, ay = ta[N_SEG - 1, 2], ta[N_SEG - 1, 3]
    bx, by = tb[N_SEG - 1, 2], tb[N_SEG - 1, 3]
    return bool(math.hypot(ax - bx, ay - by) < min(r + growth * t_end, cap))


@njit(cache=True)
def opponent_hits(tr: np.ndarray, ox: float, oy: float, ovx: float, ovy: float, radius: float, accel: float) -> bool:
    """Can an opponent at (ox, oy) moving at (ovx, ovy), accelerating at most ``accel`` in any
    direction, come closer than ``radius`` to the trajectory before it rests?"""
    dx0, dy0 = tr[0, 2] - ox, tr[0, 3] - oy
    d0 = math.hypot(dx0, dy0)
    r = min(radius, d0 * (1.0 - 1e-9))
    t_rest = tr[N_SEG - 1, 0]
    far = _reach(tr) + math.hypot(ovx, ovy) * t_rest + r + 0.5 * accel * t_rest * t_rest
    if d0 > far:
        return False
    for k in range(N_SEG - 1):
        t0, t1 = tr[k, 0], tr[k, 1]
        if t1 - t0 <= 1e-12:
            continue
        qx, qy = ox + ovx * t0, oy + ovy * t0
        # the opponent's reach grows as accel (t0 + h)^2 / 2 = r0 + r1 h + r2 h^2
        g0, g1, g2 = r + 0.5 * accel * t0 * t0, accel * t0, 0.5 * accel
        if _interval_hits(tr[k, 2] - qx, tr[k, 3] - qy, tr[k, 4] - ovx, tr[k, 5] - ovy, 0.5 * tr[k, 6],
                          0.5 * tr[k, 7], g0, g1, g2, t1 - t0):
            return True
    return False


@njit(cache=True)
def exposed(states: np.ndarray, opp: np.ndarray, reach: float) -> np.ndarray:
    """Per own robot: is an opponent's centre within ``reach`` of its centre, near enough to push it
    into a team-mate before anyone can react?"""
    out = np.zeros(states.shape[0], dtype=np.bool_)
    for i in range(states.shape[0]):
        for j in range(opp.shape[0]):
            if math.hypot(states[i, 0] - opp[j, 0], states[i, 1] - opp[j, 1]) < reach:
                out[i] = True
                break
    return out


@njit(cache=True)
def leaves(tr: np.ndarray, stop: np.ndarray, other: np.ndarray, radius: float) -> bool:
    """Does a robot that starts closer than ``radius`` to ``other`` get out of it by ``tr``: at
    rest farther from ``other``'s rest point than its ``stop`` would leave it? (Inside the kept
    distance no trajectory passes :func:`pair_hits` while the velocities' noise points the two at
    each other, and the stop, always accepted, then held two touching robots together for seconds.)"""
    if math.hypot(tr[0, 2] - other[0, 2], tr[0, 3] - other[0, 3]) >= radius:
        return False
    ox, oy = other[N_SEG - 1, 2], other[N_SEG - 1, 3]
    away = math.hypot(tr[N_SEG - 1, 2] - ox, tr[N_SEG - 1, 3] - oy)
    return away > math.hypot(stop[N_SEG - 1, 2] - ox, stop[N_SEG - 1, 3] - oy) + 1e-9


@njit(cache=True)
def _trajectory_hits(
    i: int, tr: np.ndarray, trs: np.ndarray, stops: np.ndarray, pushed: np.ndarray, opp: np.ndarray,
    obs: np.ndarray, inner: np.ndarray, cfg: DSSConfig,
) -> bool:
    # robot i's trajectory tr against the other own robots' trajectories, the opponents and the
    # world; a robot already too near a team-mate may still leave it (``stops``: each one's stop)
    for j in range(trs.shape[0]):
        radius = cfg.pushed_radius if pushed[i] or pushed[j] else cfg.own_radius
        if j != i and pair_hits(tr, trs[j], radius, cfg.own_growth) and not leaves(tr, stops[i], trs[j], radius):
            return True
    for j in range(opp.shape[0]):
        if opponent_hits(tr, opp[j, 0], opp[j, 1], opp[j, 2], opp[j, 3], cfg.opponent_radius, cfg.opponent_accel):
            return True
    return static_hits(tr, obs, inner, cfg.static_margin, cfg.static_step)


@njit(cache=True)
def _store(trs: np.ndarray, i: int, tr: np.ndarray) -> None:
    """``trs[i] = tr``, element by element: numba's array slice assignment brings a shape-mismatch
    message formatter that costs seconds of the first run's compile."""
    for s in range(tr.shape[0]):
        for c in range(tr.shape[1]):
            trs[i, s, c] = tr[s, c]


@njit(cache=True)
def dss(
    states: np.ndarray, desired: np.ndarray, stop_asked: np.ndarray, opp: np.ndarray, obs: np.ndarray,
    inner: np.ndarray, lim: Limits, cfg: DSSConfig, unit_samples: np.ndarray, heuristics: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cooperative Dynamics Safety Search (Bruce 2006 §5.3) over the own robots in turn.

    ``states`` (n, 4) x, y, vx, vy; ``desired`` (n, 2) each robot's commanded acceleration;
    ``stop_asked`` (n,) robots that asked to stop; ``opp`` (m, 4) opponents; ``unit_samples``
    (n, k, 2) random points of the unit disc (mapped into each robot's A(v)); ``heuristics`` (h, 3):
    (scale, rotation rad, 1 = from the A(v) boundary) variants of the desired acceleration.
    ``obs``, ``inner``: the static obstacles as a compiled collision world; ``lim``: the robot's limits.
    Every robot starts on its stop trajectory; in turn, each keeps its command if safe against all
    others' current trajectories, else takes the safe candidate nearest its command, else stops.
    Returns the accelerations (n, 2), each robot's status (KEPT, CHANGED, STOPPED, STOP_ASKED) and
    the braking trajectories checked (n, N_SEG, 8)."""
    n = states.shape[0]
    dt, accel, brake = cfg.dt, lim.accel, lim.brake
    pushed = exposed(states, opp, cfg.push_reach)
    trs = np.empty((n, N_SEG, 8))
    acc = np.empty((n, 2))
    status = np.full(n, STOPPED, dtype=np.int64)
    stops = np.empty((n, N_SEG, 8))
    for i in range(n):
        sx, sy = stop_accel(states[i, 2], states[i, 3], dt)
        acc[i, 0], acc[i, 1] = sx, sy
        _store(stops, i, trajectory(states[i, 0], states[i, 1], states[i, 2], states[i, 3], sx, sy, dt, accel, brake))
        _store(trs, i, stops[i])
    k_rand = unit_samples.shape[1]
    n_h = heuristics.shape[0]
    cand = np.empty((1 + n_h + k_rand + 1, 2))
    cost = np.empty(cand.shape[0])
    for i in range(n):
        if stop_asked[i]:
            status[i] = STOP_ASKED
            continue
        px, py, vx, vy = states[i, 0], states[i, 1], states[i, 2], states[i, 3]
        dx, dy = feasible(vx, vy, desired[i, 0], desired[i, 1], lim, dt)
        tr = trajectory(px, py, vx, vy, dx, dy, dt, accel, brake)
        if not _trajectory_hits(i, tr, trs, stops, pushed, opp, obs, inner, cfg):
            _store(trs, i, tr)
            acc[i, 0], acc[i, 1] = dx, dy
            status[i] = KEPT
            continue
        # candidates: variants of the command, coasting, random points of A(v)
        m = 0
        dn = math.hypot(dx, dy)
        for h in range(n_h):
            c, s = math.cos(heuristics[h, 1]), math.sin(heuristics[h, 1])
            ux, uy = c * dx - s * dy, s * dx + c * dy
            if heuristics[h, 2] > 0.0 and dn > 0.0:
                bx, by = clip_accel(vx, vy, ux * 1e6 / dn, uy * 1e6 / dn, lim.accel, lim.brake)
                ux, uy = bx, by
            cand[m, 0], cand[m, 1] = heuristics[h, 0] * ux, heuristics[h, 0] * uy
            m += 1
        cand[m, 0], cand[m, 1] = 0.0, 0.0
        m += 1
        for r in range(k_rand):
            ux, uy = unit_samples[i, r, 0], unit_samples[i, r, 1]
            un = math.hypot(ux, uy)
            if un > 0.0:
                bx, by = clip_accel(vx, vy, ux * 1e6 / un, uy * 1e6 / un, lim.accel, lim.brake)
                cand[m, 0], cand[m, 1] = bx * un, by * un
            else:
                cand[m, 0], cand[m, 1] = 0.0, 0.0
            m += 1
        for r in range(m):
            fx, fy = feasible(vx, vy, cand[r, 0], cand[r, 1], lim, dt)
            cand[r, 0], cand[r, 1] = fx, fy
            cost[r] = math.hypot(fx - dx, fy - dy)
        order = argsort_stable(cost[:m])
        for r in order:
            tr = trajectory(px, py, vx, vy, cand[r, 0], cand[r, 1], dt, accel, brake)
            if not _trajectory_hits(i, tr, trs, stops, pushed, opp, obs, inner, cfg):
                _store(trs, i, tr)
                acc[i, 0], acc[i, 1] = cand[r, 0], cand[r, 1]
                status[i] = CHANGED
                break
    return acc, status, trs


@njit(cache=True)
def trajectories_clear(
    states: np.ndarray, acc: np.ndarray, opp: np.ndarray, obs: np.ndarray, inner: np.ndarray, lim: Limits,
    cfg: DSSConfig,
) -> np.ndarray:
    """For each robot: is its trajectory under ``acc`` clear of every other's, the opponents and the
    static obstacles? (The check a finished search must pass.)"""
    n = states.shape[0]
    trs = np.empty((n, N_SEG, 8))
    stops = np.empty((n, N_SEG, 8))
    for i in range(n):
        _store(trs, i, trajectory(states[i, 0], states[i, 1], states[i, 2], states[i, 3], acc[i, 0], acc[i, 1],
                                  cfg.dt, lim.accel, lim.brake))
        sx, sy = stop_accel(states[i, 2], states[i, 3], cfg.dt)
        _store(stops, i, trajectory(states[i, 0], states[i, 1], states[i, 2], states[i, 3], sx, sy, cfg.dt,
                                    lim.accel, lim.brake))
    out = np.empty(n, dtype=np.bool_)
    pushed = exposed(states, opp, cfg.push_reach)
    for i in range(n):
        out[i] = not _trajectory_hits(i, trs[i], trs, stops, pushed, opp, obs, inner, cfg)
    return out
