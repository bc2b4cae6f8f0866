"""The collision kernels against their plain-numpy references (cmdragons/planning/collision_reference.py)."""

from __future__ import annotations

import numpy as np
import pytest

from cmdragons.planning import collision as K
from cmdragons.planning import collision_reference as R
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
