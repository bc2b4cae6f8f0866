"""Every planning kernel against its plain-numpy reference (cmdragons/planning/_reference.py)."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.planning import _kernels as K
from cmdragons.planning import _reference as R
from cmdragons.planning.world import BROAD_PHASES, CollisionParams, CollisionWorld


def random_world(rng: np.random.Generator, n_circles: int, n_boxes: int) -> CollisionWorld:
    circles = np.column_stack(
        [rng.uniform(-4, 4, n_circles), rng.uniform(-3, 3, n_circles), rng.uniform(0.02, 0.3, n_circles)]
    )
    vel = rng.normal(0.0, 1.0, (n_circles, 2))
    lo = np.column_stack([rng.uniform(-4, 4, n_boxes), rng.uniform(-3, 3, n_boxes)])
    boxes = np.hstack([lo, lo + rng.uniform(0.05, 1.0, (n_boxes, 2))])
    return CollisionWorld((-4.8, -3.3, 4.8, 3.3), circles, vel, boxes)


def test_point_segment_distance_agrees() -> None:
    rng = np.random.default_rng(0)
    p, a, b = (rng.uniform(-2, 2, (500, 2)) for _ in range(3))
    b[:20] = a[:20]  # degenerate segments are points
    got = np.sqrt([K.point_segment_dist2(*p[i], *a[i], *b[i]) for i in range(500)])
    np.testing.assert_allclose(got, R.point_segment_dist(p, a, b), atol=1e-12)


@pytest.mark.parametrize("kind", ["segment", "box"])
def test_segment_distances_agree_with_dense_sampling(kind: str) -> None:
    rng = np.random.default_rng(1)
    for _ in range(150):
        a, b, c, d = (rng.uniform(-1, 1, 2) for _ in range(4))
        if kind == "segment":
            got = np.sqrt(K.segment_segment_dist2(*a, *b, *c, *d))
            ref = R.sampled_segment_dist(
                a,
                b,
                lambda q, c=c, d=d: R.point_segment_dist(q, np.broadcast_to(c, q.shape), np.broadcast_to(d, q.shape)),
            )
        else:
            box = np.array([min(c[0], d[0]), min(c[1], d[1]), max(c[0], d[0]), max(c[1], d[1])])
            got = np.sqrt(K.segment_box_dist2(*a, *b, *box))
            ref = R.sampled_segment_dist(
                a, b, lambda q, box=box: R.point_box_dist(q, np.broadcast_to(box, (len(q), 4)))
            )
        # sampling can only overestimate, by at most half a sample spacing
        assert ref - 1e-3 <= got <= ref + 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("broad_phase", sorted(BROAD_PHASES))
@pytest.mark.parametrize(
    ("n_circles", "n_boxes", "window"), [(0, 0, 0.0), (10, 2, 0.0), (21, 8, 0.0), (40, 4, 0.3), (50, 3, 0.1)]
)
def test_swept_segment_query_agrees_with_sampling(
    broad_phase: str, n_circles: int, n_boxes: int, window: float
) -> None:
    rng = np.random.default_rng(n_circles + 100 * n_boxes)
    world = random_world(rng, n_circles, n_boxes)
    cw = world.compile(0.09, 0.0, window, CollisionParams(broad_phase=broad_phase, mask_bins=16))  # type: ignore[arg-type]
    agree = 0
    for _ in range(150):
        a = rng.uniform(-5, 5, 2) * [1, 0.7]
        b = a + rng.normal(0, 1.0, 2)
        clearance = R.segment_clearance(cw.obs, cw.inner, a, b)
        if abs(clearance) < 2e-3:
            continue  # a contact thinner than the sampling step is ambiguous: skip those few
        assert cw.segment_free(a, b) == (clearance > 0), (a, b)
        assert cw.point_free(*a) == R.segment_free(cw.obs, cw.inner, a, a)
        agree += 1
    assert agree > 130


def test_broad_phases_give_identical_answers() -> None:
    rng = np.random.default_rng(7)
    world = random_world(rng, 35, 6)
    seg = np.hstack([rng.uniform(-5, 5, (3000, 2)), rng.uniform(-5, 5, (3000, 2))])
    answers = [
        world.compile(0.09, params=CollisionParams(broad_phase=bp)).segments_free(seg) for bp in sorted(BROAD_PHASES)
    ]  # type: ignore[arg-type]
    assert 0 < answers[0].sum() < len(seg)
    for other in answers[1:]:
        np.testing.assert_array_equal(answers[0], other)


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
    state = np.array([2, 0, 0, 0, 0], dtype=np.int64)
    bridges = np.zeros((4, 3))
    kd = (np.full((cap, 2), -1, dtype=np.int32), np.zeros(cap, dtype=np.int32), np.array([0, 1], dtype=np.int32))
    trees = (nodes, parent, tree, np.zeros(cap), *kd, np.zeros((cap, 2)), state, bridges)
    code = K.errt_grow(cw.cw, *trees, rng.random((300, 3)), np.zeros((0, 2)), p_goal=0.1, p_way=0.0, step=0.3,
                       connect_r=20.0, max_ext=8, bidir=True, max_br=4, extra=20, nn=K.NN_BRUTE, node_limit=cap)
    assert code in (K.GROW_DONE, K.GROW_FULL, K.GROW_RUNNING)
    n = int(state[0])
    assert n > 2
    for i in range(2, n):
        a, b = nodes[parent[i]], nodes[i]
        assert np.hypot(*(b - a)) <= 0.3 + 1e-9
        assert R.segment_free(cw.obs, cw.inner, a, b, samples=201)
    for a0, a1, length in bridges[: int(state[1])]:
        assert tree[int(a0)] == 0 and tree[int(a1)] == 1
        assert R.segment_free(cw.obs, cw.inner, nodes[int(a0)], nodes[int(a1)])
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
