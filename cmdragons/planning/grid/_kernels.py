"""numba kernels of the grid planners: an indexed binary heap, NF1 wavefronts, 8-connected Dijkstra
and A*, and E*'s event-driven propagation (Philippsen 2004, ch. 4 and appendices A.2, B.1).

Grids are row-major: cell ``i`` is row ``i // w``, column ``i % w``. A cost grid holds each cell's
traversal cost per cell length (>= 1 for free cells, ``inf`` for obstacles); distances come out in
cell lengths. The heap orders cells by a float key and supports changing the key of a queued cell,
which E*'s repair needs (a raised cell's key may go up or down).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

SQRT2 = math.sqrt(2.0)
INF = np.inf

# --- indexed binary heap -----------------------------------------------------------------------
# heap = (keys float64[n], items int64[n], pos int64[n_cells], size int64[1]); pos[i] = -1: not queued


def new_heap(n_cells: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    return (np.empty(n_cells, np.float64), np.empty(n_cells, np.int64), np.full(n_cells, -1, np.int64),
            np.zeros(1, np.int64))


@njit(cache=True, inline="always")
def _swap(keys: np.ndarray, items: np.ndarray, pos: np.ndarray, a: int, b: int) -> None:
    keys[a], keys[b] = keys[b], keys[a]
    items[a], items[b] = items[b], items[a]
    pos[items[a]] = a
    pos[items[b]] = b


@njit(cache=True, inline="always")
def _less(keys: np.ndarray, items: np.ndarray, a: int, b: int) -> bool:
    # ties broken by cell index: the same order on every run
    return bool(keys[a] < keys[b] or (keys[a] == keys[b] and items[a] < items[b]))


@njit(cache=True, inline="always")
def _sift_up(keys: np.ndarray, items: np.ndarray, pos: np.ndarray, k: int) -> None:
    while k > 0:
        parent = (k - 1) >> 1
        if _less(keys, items, k, parent):
            _swap(keys, items, pos, k, parent)
            k = parent
        else:
            return


@njit(cache=True, inline="always")
def _sift_down(keys: np.ndarray, items: np.ndarray, pos: np.ndarray, n: int, k: int) -> None:
    while True:
        left = 2 * k + 1
        if left >= n:
            return
        best = left
        if left + 1 < n and _less(keys, items, left + 1, left):
            best = left + 1
        if _less(keys, items, best, k):
            _swap(keys, items, pos, k, best)
            k = best
        else:
            return


@njit(cache=True)
def heap_set(keys: np.ndarray, items: np.ndarray, pos: np.ndarray, size: np.ndarray, item: int, key: float) -> None:
    """Queue ``item`` with ``key``, or change the key of a queued item."""
    k = pos[item]
    if k < 0:
        k = size[0]
        size[0] += 1
        keys[k], items[k], pos[item] = key, item, k
        _sift_up(keys, items, pos, k)
        return
    old = keys[k]
    keys[k] = key
    if key < old:
        _sift_up(keys, items, pos, k)
    else:
        _sift_down(keys, items, pos, size[0], k)


@njit(cache=True)
def heap_remove(keys: np.ndarray, items: np.ndarray, pos: np.ndarray, size: np.ndarray, item: int) -> None:
    k = pos[item]
    if k < 0:
        return
    last = size[0] - 1
    pos[item] = -1
    size[0] = last
    if k == last:
        return
    keys[k], items[k] = keys[last], items[last]
    pos[items[k]] = k
    _sift_up(keys, items, pos, k)
    _sift_down(keys, items, pos, last, pos[items[k]])


@njit(cache=True)
def heap_pop(keys: np.ndarray, items: np.ndarray, pos: np.ndarray, size: np.ndarray) -> int:
    item = int(items[0])
    heap_remove(keys, items, pos, size, item)
    return item


# --- NF1: breadth-first wavefronts (Latombe's NF1, Philippsen A.2) ------------------------------


@njit(cache=True)
def nf1(free: np.ndarray, h: int, w: int, goal: int, eight: bool) -> np.ndarray:
    """Steps from every free cell to ``goal`` (-1: unreachable) over 4- or 8-connected moves, each
    move one step."""
    n = h * w
    dist = np.full(n, -1, np.int64)
    if not free[goal]:
        return dist
    queue = np.empty(n, np.int64)
    head, tail = 0, 1
    queue[0] = goal
    dist[goal] = 0
    nbr = 8 if eight else 4
    dr = np.array([-1, 1, 0, 0, -1, -1, 1, 1])
    dc = np.array([0, 0, -1, 1, -1, 1, -1, 1])
    while head < tail:
        i = queue[head]
        head += 1
        r, c = i // w, i % w
        for k in range(nbr):
            rr, cc = r + dr[k], c + dc[k]
            if 0 <= rr < h and 0 <= cc < w:
                j = rr * w + cc
                if free[j] and dist[j] < 0:
                    dist[j] = dist[i] + 1
                    queue[tail] = j
                    tail += 1
    return dist


# --- 8-connected shortest paths: Dijkstra and A* (the Moving AI rules: no cut corners) ----------


@njit(cache=True, inline="always")
def _octile(a: int, b: int, w: int) -> float:
    dx, dy = abs(a % w - b % w), abs(a // w - b // w)
    return (SQRT2 - 1.0) * min(dx, dy) + max(dx, dy)


@njit(cache=True)
def octile_search(cost: np.ndarray, h: int, w: int, start: int, goal: int, heuristic: bool,
                  parent: np.ndarray) -> tuple[float, int]:
    """Shortest 8-connected path from ``start`` to ``goal`` (goal < 0: to every cell): a straight move
    costs the mean of the two cells' costs, a diagonal one sqrt 2 times that, and a diagonal never
    passes a blocked cell at its corner. ``heuristic``: A* with the octile distance (exact when every
    free cell costs at least 1). Fills ``parent`` (-1: none); returns (length, cells expanded)."""
    n = h * w
    g = np.full(n, INF)
    closed = np.zeros(n, np.bool_)
    keys, items, pos, size = np.empty(n, np.float64), np.empty(n, np.int64), np.full(n, -1, np.int64), np.zeros(
        1, np.int64)
    parent[:] = -1
    g[start] = 0.0
    heap_set(keys, items, pos, size, start, _octile(start, goal, w) if heuristic and goal >= 0 else 0.0)
    dr = np.array([-1, 1, 0, 0, -1, -1, 1, 1])
    dc = np.array([0, 0, -1, 1, -1, 1, -1, 1])
    expanded = 0
    while size[0] > 0:
        i = heap_pop(keys, items, pos, size)
        if closed[i]:
            continue
        closed[i] = True
        expanded += 1
        if i == goal:
            return g[i], expanded
        r, c = i // w, i % w
        for k in range(8):
            rr, cc = r + dr[k], c + dc[k]
            if not (0 <= rr < h and 0 <= cc < w):
                continue
            j = rr * w + cc
            if closed[j] or not math.isfinite(cost[j]):
                continue
            step = 0.5 * (cost[i] + cost[j])
            if k >= 4:
                if not (math.isfinite(cost[r * w + cc]) and math.isfinite(cost[rr * w + c])):
                    continue  # a blocked corner
                step *= SQRT2
            ng = g[i] + step
            if ng < g[j]:
                g[j] = ng
                parent[j] = i
                heap_set(keys, items, pos, size, j, ng + (_octile(j, goal, w) if heuristic and goal >= 0 else 0.0))
    return (g[goal] if goal >= 0 else 0.0), expanded


# --- E*: the interpolated navigation function with event-driven repair -------------------------
# state: v (the navigation function), rhs (its one-step look-ahead), cost, the heap; a cell is
# consistent when v == rhs; inconsistent cells are queued with key min(v, rhs) (Philippsen §4.5.2).
# E*'s grids carry a border of obstacle cells one cell wide (the caller pads them), so every inner
# cell has all eight neighbours and no kernel checks the grid's bounds.


@njit(cache=True, inline="always")
def _upwind(a: float, b: float, c: float) -> float:
    """The fast-marching update from the smaller neighbour values ``a`` and ``b`` along two
    orthogonal axes at spacing ``c`` (cost times spacing): ``a + c`` where the wave comes along one
    axis, else the root of ``(x - a)^2 + (x - b)^2 = c^2`` (Huygens' principle, Philippsen §4.6.2)."""
    if b < a:
        a, b = b, a
    if a == INF:
        return INF
    if b - a >= c:
        return a + c
    d = a - b
    # never above the one-axis value (equal to it at b - a = c; rounding could put it an ulp above,
    # and the kernel must not rise as more neighbours become known)
    return min(0.5 * (a + b + math.sqrt(2.0 * c * c - d * d)), a + c)


@njit(cache=True, inline="always")
def _corners(cost: np.ndarray, w: int, i: int) -> int:
    """The diagonals cell ``i`` may take as bits (north-east, south-west, north-west, south-east):
    a corner whose two cells beside it are free."""
    fn, fs, fw, fe = cost[i - w] < INF, cost[i + w] < INF, cost[i - 1] < INF, cost[i + 1] < INF
    return int((fn and fe) | ((fs and fw) << 1) | ((fn and fw) << 2) | ((fs and fe) << 3))


@njit(cache=True, inline="always")
def _diagonal(v: np.ndarray, ci: float, w: int, i: int, corners: int) -> float:
    """The upwind update along the diagonals (spacing sqrt 2) over the open ``corners``
    (:func:`_corners`)."""
    a = v[i - w + 1] if corners & 1 else INF
    if corners & 2 and v[i + w - 1] < a:
        a = v[i + w - 1]
    b = v[i - w - 1] if corners & 4 else INF
    if corners & 8 and v[i + w + 1] < b:
        b = v[i + w + 1]
    return _upwind(a, b, SQRT2 * ci)


@njit(cache=True, inline="always")
def estar_kernel(v: np.ndarray, cost: np.ndarray, w: int, i: int, eight: bool) -> float:
    """The value of inner cell ``i`` from its neighbours: the upwind update on the 4-neighbourhood,
    and with ``eight`` the smaller of it and the same update on the diagonal neighbours (spacing
    sqrt 2; a diagonal neighbour counts only where both cells beside the corner are free, so the wave
    never slips through a blocked corner)."""
    ci = cost[i]
    if ci == INF:
        return INF
    x = _upwind(min(v[i - 1], v[i + 1]), min(v[i - w], v[i + w]), ci)
    if not eight:
        return x
    return min(x, _diagonal(v, ci, w, i, _corners(cost, w, i)))


@njit(cache=True, inline="always")
def _offsets(w: int, eight: bool) -> np.ndarray:
    if eight:
        return np.array([-w, w, -1, 1, -w - 1, -w + 1, w - 1, w + 1])
    return np.array([-w, w, -1, 1])


@njit(cache=True, inline="always")
def estar_update(v: np.ndarray, rhs: np.ndarray, cost: np.ndarray, w: int, goal: np.ndarray, keys: np.ndarray,
                 items: np.ndarray, pos: np.ndarray, size: np.ndarray, i: int, eight: bool) -> None:
    """Recompute the look-ahead of cell ``i`` and queue it if inconsistent."""
    if not goal[i]:
        rhs[i] = estar_kernel(v, cost, w, i, eight)
    if v[i] != rhs[i]:
        heap_set(keys, items, pos, size, i, min(v[i], rhs[i]))
    else:
        heap_remove(keys, items, pos, size, i)


@njit(cache=True, inline="always")
def _update_neighbours(v: np.ndarray, rhs: np.ndarray, cost: np.ndarray, w: int, goal: np.ndarray,
                       keys: np.ndarray, items: np.ndarray, pos: np.ndarray, size: np.ndarray, i: int,
                       offsets: np.ndarray, eight: bool, below: float) -> None:
    """New look-aheads for the neighbours of ``i`` whose value may depend on it. A consistent
    neighbour whose value is at most ``below`` (the cell's new value when it was lowered, its old
    one when raised) is skipped: the kernel's result depends only on neighbour values smaller than
    itself, so such a neighbour never used, and never will use, cell ``i``."""
    for o in offsets:
        j = i + o
        if cost[j] == INF or (v[j] == rhs[j] and v[j] <= below):
            continue
        estar_update(v, rhs, cost, w, goal, keys, items, pos, size, j, eight)


@njit(cache=True)
def estar_propagate(v: np.ndarray, rhs: np.ndarray, cost: np.ndarray, w: int, goal: np.ndarray,
                    keys: np.ndarray, items: np.ndarray, pos: np.ndarray, size: np.ndarray,
                    stop_cell: int, max_pops: int, eight: bool) -> tuple[int, bool]:
    """Process queued cells in key order until none is left, or (``stop_cell`` >= 0) until that cell
    is consistent and below every queued key, or ``max_pops`` cells were processed (< 0: no limit).
    A lowered cell takes its look-ahead and updates its neighbours; a raised one is reset to
    infinity first (D*'s raise event, §4.3). Returns (cells processed, whether it finished)."""
    offsets = _offsets(w, eight)
    pops = 0
    while size[0] > 0:
        if stop_cell >= 0 and v[stop_cell] == rhs[stop_cell] and keys[0] >= v[stop_cell]:
            return pops, True
        if 0 <= max_pops <= pops:
            return pops, False
        i = heap_pop(keys, items, pos, size)
        pops += 1
        if v[i] > rhs[i]:
            v[i] = rhs[i]
            _update_neighbours(v, rhs, cost, w, goal, keys, items, pos, size, i, offsets, eight, v[i])
        else:
            old = v[i]
            v[i] = INF
            estar_update(v, rhs, cost, w, goal, keys, items, pos, size, i, eight)
            _update_neighbours(v, rhs, cost, w, goal, keys, items, pos, size, i, offsets, eight, old)
    return pops, True


@njit(cache=True)
def estar_set_costs(v: np.ndarray, rhs: np.ndarray, cost: np.ndarray, w: int, goal: np.ndarray,
                    keys: np.ndarray, items: np.ndarray, pos: np.ndarray, size: np.ndarray,
                    cells: np.ndarray, values: np.ndarray, eight: bool) -> int:
    """Change the cost of (inner) ``cells``; each changed cell and its neighbours get new
    look-aheads and are queued where they became inconsistent (the repair then runs in
    :func:`estar_propagate`). Returns how many cells changed."""
    offsets = _offsets(w, eight)
    changed = 0
    for k in range(len(cells)):
        i = cells[k]
        if cost[i] == values[k]:
            continue
        cost[i] = values[k]
        changed += 1
        estar_update(v, rhs, cost, w, goal, keys, items, pos, size, i, eight)
        # every neighbour: the corner rule may have opened or closed a neighbour's diagonal
        for o in offsets:
            j = i + o
            if cost[j] < INF:
                estar_update(v, rhs, cost, w, goal, keys, items, pos, size, j, eight)
    return changed


@njit(cache=True)
def estar_full(v: np.ndarray, rhs: np.ndarray, cost: np.ndarray, w: int, goal: np.ndarray, seeds: np.ndarray,
               seed_values: np.ndarray, eight: bool) -> int:
    """The whole navigation function from scratch (every ``v`` infinite): fast marching with the
    E* kernel in one pass, a cell final when it leaves the heap (a heap with stale entries, cheaper
    than the indexed heap repairs need). The same values as :func:`estar_propagate` (the same
    kernel on the same final neighbours, monotone as neighbours become known); leaves every cell
    consistent (``rhs == v``), so repairs start from here. Returns the cells finalised."""
    n = len(v)
    offsets = _offsets(w, eight)
    # closed: final, an obstacle or a goal cell (its value is given), never updated again; corners:
    # the diagonals each free cell may take (the kernel's corner rule, read once per cell here)
    closed = np.empty(n, np.bool_)
    corners = np.zeros(n, np.uint8)
    for i in range(n):
        closed[i] = cost[i] == INF or goal[i] or v[i] < INF
    if eight:
        for i in range(w, n - w):
            if cost[i] < INF:
                corners[i] = _corners(cost, w, i)
    heap = np.empty((len(offsets) * n + len(seeds) + 1, 2), np.float64)
    m = 0
    for s in range(len(seeds)):
        rhs[seeds[s]] = seed_values[s]
        m = _lazy_push(heap, m, seed_values[s], seeds[s])
    done = 0
    while m > 0:
        key, i = heap[0, 0], int(heap[0, 1])
        m = _lazy_pop(heap, m)
        if v[i] < INF or key != rhs[i]:
            continue  # final already, or a stale entry
        v[i] = key
        closed[i] = True
        done += 1
        # a neighbour's look-ahead is the smaller of its axis and its diagonal update, and only the
        # one with cell i among its inputs has changed: rhs already holds the other
        for q in range(len(offsets)):
            j = i + offsets[q]
            if closed[j]:
                continue
            if q < 4:
                x = _upwind(min(v[j - 1], v[j + 1]), min(v[j - w], v[j + w]), cost[j])
            else:
                x = _diagonal(v, cost[j], w, j, corners[j])
            if x < rhs[j]:
                rhs[j] = x
                m = _lazy_push(heap, m, x, j)
    return done


# a 4-ary min-heap of (key, item) rows, item stored as a float (exact below 2**53): key and item
# in one cache line, fewer levels than a binary heap; ties in any order (equal keys are equal values)


@njit(cache=True, inline="always")
def _lazy_push(heap: np.ndarray, m: int, key: float, item: int) -> int:
    """Push onto the heap of size ``m``; returns the new size."""
    k = m
    while k > 0:
        p = (k - 1) >> 2
        if key < heap[p, 0]:
            heap[k, 0], heap[k, 1] = heap[p, 0], heap[p, 1]
            k = p
        else:
            break
    heap[k, 0], heap[k, 1] = key, item
    return m + 1


@njit(cache=True, inline="always")
def _lazy_pop(heap: np.ndarray, m: int) -> int:
    """Drop the top of the heap of size ``m`` (read it first); returns the new size."""
    m -= 1
    key, item = heap[m, 0], heap[m, 1]
    k = 0
    while True:
        first = 4 * k + 1
        if first >= m:
            break
        b, bk = first, heap[first, 0]
        for c in range(first + 1, min(first + 4, m)):
            if heap[c, 0] < bk:
                b, bk = c, heap[c, 0]
        if bk < key:
            heap[k, 0], heap[k, 1] = bk, heap[b, 1]
            k = b
        else:
            break
    heap[k, 0], heap[k, 1] = key, item
    return m


@njit(cache=True, inline="always")
def estar_gradient(v: np.ndarray, w: int, i: int) -> tuple[float, float]:
    """The descent direction at inner cell ``i`` (Philippsen §4.6.3): per axis the upwind
    difference toward the smaller neighbour, (0, 0) where no neighbour is lower or the cell is
    unknown."""
    vi = v[i]
    if vi == INF:
        return 0.0, 0.0
    gx = 0.0
    left, right = v[i - 1], v[i + 1]
    if left < vi or right < vi:
        gx = -(vi - left) if left <= right else (vi - right)
    gy = 0.0
    up, down = v[i - w], v[i + w]
    if up < vi or down < vi:
        gy = -(vi - up) if up <= down else (vi - down)
    return gx, gy


@njit(cache=True, inline="always")
def _passable(v: np.ndarray, w: int, a: int, b: int) -> bool:
    """Whether a step from cell ``a`` to the neighbouring or same cell ``b`` stays on known cells
    and, going diagonally, does not cut a corner between two blocked or unknown cells."""
    if v[b] == INF:
        return False
    d = b - a
    if d == 0 or d == 1 or d == -1 or d == w or d == -w:
        return True
    dr = -1 if d < -1 else 1
    dc = d - dr * w
    return bool(v[a + dr * w] < INF and v[a + dc] < INF)


@njit(cache=True)
def estar_descend(v: np.ndarray, h: int, w: int, x0: float, y0: float, step: float, max_steps: int,
                  out: np.ndarray) -> int:
    """Follow the navigation function down from (x0, y0) (padded-grid cell units: x along columns,
    y along rows, cell centres at integers) to the lowest cell of a goal: each step ``step`` cells
    along the direction bilinearly interpolated between the four surrounding cells' gradients
    (known cells only); where that would not go down (into an obstacle or an unknown cell, across a
    blocked corner, or to a higher cell), the step goes to the centre of the lowest neighbouring
    cell it may reach instead, as it does after four steps within one cell (a saddle), so the descent
    always ends. Writes the points to ``out``; returns how many (0: no way down)."""
    x, y = x0, y0
    n = 0
    last = INF  # the value of the cell the path was in before
    idle = 0  # steps since the path last reached a lower cell
    while n < max_steps:
        out[n, 0], out[n, 1] = x, y
        n += 1
        here = int(round(y)) * w + int(round(x))
        vh = v[here]
        if vh == INF:
            return 0
        idle = idle + 1 if vh >= last else 0
        last = vh
        lowest = here
        for o in (-w, w, -1, 1, -w - 1, -w + 1, w - 1, w + 1):
            if v[here + o] < v[lowest] and _passable(v, w, here, here + o):
                lowest = here + o
        if lowest == here:
            return n  # the bottom of a goal: no reachable neighbour is lower
        c0, r0 = int(math.floor(x)), int(math.floor(y))
        fx, fy = x - c0, y - r0
        dx = dy = 0.0
        for dr in range(2):
            for dc in range(2):
                j = (r0 + dr) * w + c0 + dc
                wgt = (fx if dc else 1.0 - fx) * (fy if dr else 1.0 - fy)
                if wgt > 0.0 and v[j] < INF:
                    gx, gy = estar_gradient(v, w, j)
                    norm = math.hypot(gx, gy)
                    if norm > 0.0:
                        dx += wgt * gx / norm
                        dy += wgt * gy / norm
        norm = math.hypot(dx, dy)
        moved = False
        if norm > 1e-12 and idle <= 4:  # circling within a cell (a saddle): take the grid step
            nx, ny = x + step * dx / norm, y + step * dy / norm
            nxt = int(round(ny)) * w + int(round(nx))
            if _passable(v, w, here, nxt) and v[nxt] <= vh:
                x, y = nx, ny
                moved = True
        if not moved:
            x, y = float(lowest % w), float(lowest // w)
    return 0


@njit(cache=True)
def sight(cost: np.ndarray, w: int, ax: float, ay: float, bx: float, by: float) -> bool:
    """Whether the straight line from (ax, ay) to (bx, by) (padded-grid cell units) crosses only
    free cells and never a corner next to a blocked cell (sampled every 1/20 cell)."""
    n = int(math.ceil(20.0 * math.hypot(bx - ax, by - ay))) + 1
    prev = -1
    for k in range(n + 1):
        t = k / n
        cell = int(round(ay + t * (by - ay))) * w + int(round(ax + t * (bx - ax)))
        if cost[cell] == INF:
            return False
        if prev >= 0 and cell != prev:
            d = cell - prev
            if not (d == 1 or d == -1 or d == w or d == -w):
                dr = -1 if d < -1 else 1
                dc = d - dr * w
                if cost[prev + dr * w] == INF or cost[prev + dc] == INF:
                    return False
        prev = cell
    return True


@njit(cache=True)
def pull_taut(cost: np.ndarray, w: int, pts: np.ndarray) -> np.ndarray:
    """The path ``pts`` (k, 2) with every point dropped that the one before it can skip in a straight
    line (greedy, from the start): the descent's zig-zag between cell centres pulled taut."""
    keep = [0]
    i = 0
    n = len(pts)
    while i < n - 1:
        j = n - 1
        while j > i + 1 and not sight(cost, w, pts[i, 0], pts[i, 1], pts[j, 0], pts[j, 1]):
            j -= 1
        keep.append(j)
        i = j
    out = np.empty((len(keep), 2))
    for k in range(len(keep)):
        out[k] = pts[keep[k]]
    return out
