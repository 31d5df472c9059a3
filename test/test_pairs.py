"""The scan's robot pairs: found from scratch or kept from tick to tick (Verlet list), the same set."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import swarm_sim.world.pairs as pairs
from swarm_sim.world.pairs import RobotPairs, pairs_in_reach
from swarm_sim.world.raycast import StaticScene, cast_scan

R = 0.085


def _sorted(found):
    """The pairs (i, j, dx, dy, d2) in (i, j) order, as one array per field."""
    i, j, *rest = found
    order = np.lexsort((j, i))
    return [np.asarray(a)[order] for a in (i, j, *rest)]


def _same(a, b) -> bool:
    return all(x.tobytes() == y.tobytes() for x, y in zip(_sorted(a), _sorted(b)))


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(0, 60),
    reach=st.sampled_from([0.3, 1.0, 3.585]),
    skin=st.sampled_from([0.05, 0.4, 2.0]),
    tree=st.booleans(),
    step=st.sampled_from([0.005, 0.02, 0.1]),
)
def test_kept_pairs_are_the_pairs_in_reach_at_every_tick(seed, n, reach, skin, tree, step):
    """Robots random-walking (now and then one jumps far, as a teleport does): every tick the
    kept list gives exactly the pairs found from scratch, with the same (dx, dy, d2) bits."""
    rng = np.random.default_rng(seed)
    origins = rng.uniform(-4.0, 4.0, (n, 2))
    kept = RobotPairs(reach, skin)
    with pytest.MonkeyPatch.context() as m:
        m.setattr(pairs, "KD_TREE_FROM", 2 if tree else 10**9)
        for tick in range(40):
            if n and tick % 13 == 12:
                origins[rng.integers(n)] = rng.uniform(-4.0, 4.0, 2)
            origins = origins + rng.normal(0.0, step, (n, 2))
            assert _same(kept(origins), pairs_in_reach(origins, reach)), tick
    if n and step * 40 > skin:
        assert kept.builds > 1  # the list was really rebuilt along the way


def test_the_list_is_kept_while_robots_stay_within_half_the_skin():
    origins = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 0.0]])
    kept = RobotPairs(1.5, skin=0.4)
    kept(origins)
    moved = origins + [[0.19, 0.0], [-0.19, 0.0], [0.0, 0.19]]
    assert _same(kept(moved), pairs_in_reach(moved, 1.5)) and kept.builds == 1
    moved[2] = [3.0, 0.21]
    kept(moved)
    assert kept.builds == 2


def test_scan_with_kept_pairs_equals_the_scan_without():
    rng = np.random.default_rng(3)
    scene = StaticScene(6.0, np.zeros((0, 3)), np.zeros((0, 5)))
    origins = rng.uniform(-5.0, 5.0, (80, 2))
    kept = RobotPairs(3.5 + R)
    for _ in range(10):
        headings = rng.uniform(-math.pi, math.pi, 80)
        origins = origins + rng.normal(0.0, 0.05, origins.shape)
        with_pairs = cast_scan(origins, headings, R, scene, 24, 2 * math.pi, 3.5, pairs=kept)
        assert with_pairs.tobytes() == cast_scan(origins, headings, R, scene, 24, 2 * math.pi, 3.5).tobytes()
    with pytest.raises(ValueError, match="reach"):
        cast_scan(origins, headings, R, scene, 24, 2 * math.pi, 3.0, pairs=kept)
