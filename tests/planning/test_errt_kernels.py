"""The ERRT kernels against their plain-numpy references (cmdragons/planning/_errt_reference.py)."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.planning import _errt_kernels as K
from cmdragons.planning import _errt_reference as R
from cmdragons.planning import collision_reference as CR
from tests.planning.test_collision import random_world


def test_nearest_neighbour_kernels_agree() -> None:
    rng = np.random.default_rng(3)
    n = 800
    nodes = rng.uniform(-4, 4, (n, 2))
    tree = np.zeros(n, dtype=np.int8)
    kdc = np.full((n, 2), -1, dtype=np.int32)
    kdd = np.zeros(n, dtype=np.int32)
    for i in range(1, n):
        K.kd_insert(nodes, kdc, kdd, 0, i)
    stack = np.zeros((n, 2))
    for q in rng.uniform(-5, 5, (300, 2)):
        ref = R.nearest(nodes, q)
        assert K.nearest_brute(nodes, tree, n, 0, *q) == ref
        assert K.kd_nearest(nodes, kdc, kdd, 0, q[0], q[1], stack) == ref


def test_errt_tree_edges_are_collision_free() -> None:
    rng = np.random.default_rng(4)
    world = random_world(rng, 21, 4)
    cw = world.compile(0.09)
    start, goal = np.array([-4.0, 0.0]), np.array([4.0, 0.0])
    cap = 400
    nodes = np.zeros((cap, 2))
    nodes[0], nodes[1] = start, goal
    parent = np.full(cap, -1, dtype=np.int32)
    tree = np.zeros(cap, dtype=np.int8)
    tree[1] = 1
    counts = np.zeros(K.N_COUNTS, dtype=np.int64)
    counts[K.N_NODES] = 2
    bridges = np.zeros((4, 3))
    kd = (np.full((cap, 2), -1, dtype=np.int32), np.zeros(cap, dtype=np.int32), np.array([0, 1], dtype=np.int32))
    trees = K.Trees(nodes, parent, tree, np.zeros(cap), *kd, np.zeros((cap, 2)), counts, bridges)
    cfg = K.GrowConfig(p_goal=0.1, p_waypoint=0.0, step_m=0.3, connect_radius_m=20.0, max_extensions=8,
                       bidirectional=True, max_bridges=4, extra_iterations=20, nearest=K.NN_BRUTE)
    code = K.errt_grow(cw.cw, trees, rng.random((300, 3)), np.zeros((0, 2)), cfg, node_limit=cap)
    assert code in (K.GROW_DONE, K.GROW_FULL, K.GROW_RUNNING)
    n = int(counts[K.N_NODES])
    assert n > 2
    for i in range(2, n):
        a, b = nodes[parent[i]], nodes[i]
        assert np.hypot(*(b - a)) <= 0.3 + 1e-9
        assert CR.segment_free(cw.obs, cw.inner, a, b, samples=201)
    for a0, a1, length in bridges[: int(counts[K.N_BRIDGES])]:
        assert tree[int(a0)] == 0 and tree[int(a1)] == 1
        assert CR.segment_free(cw.obs, cw.inner, nodes[int(a0)], nodes[int(a1)])
        assert length > 0


@pytest.mark.parametrize("fifo", [False, True])
@pytest.mark.parametrize(("size", "batches"), [(5, [3, 4, 9]), (64, [20, 20, 20, 20, 1]), (1, [2, 1])])
def test_waypoint_cache_add_agrees(fifo: bool, size: int, batches: list[int]) -> None:
    rng = np.random.default_rng(size)
    got, ref = np.zeros((size, 2)), np.zeros((size, 2))
    meta, count, nxt = np.zeros(2, dtype=np.int64), 0, 0
    for k in batches:
        pts, u = rng.uniform(-4, 4, (k, 2)), rng.random(k)
        replaced = 0 if fifo else max(0, min(k, size) - (size - count))  # one uniform per random victim
        assert K.cache_add(got, meta, pts, u, fifo) == replaced
        count, nxt = R.cache_add(ref, count, nxt, pts, u, fifo)
        assert (int(meta[0]), int(meta[1])) == (count, nxt)
        np.testing.assert_array_equal(got, ref)
