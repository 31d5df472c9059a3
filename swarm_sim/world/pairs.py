"""Which robots are within reach of each other: the scan's robot pairs, for the whole swarm.

`pairs_in_reach` finds them from scratch: all N (N - 1) / 2 pairs for small swarms, a k-d tree
(scipy) for large ones. `RobotPairs` keeps them from tick to tick as a Verlet list: it finds the
pairs within reach + skin, and as long as no robot has moved skin / 2 from where it was then,
every pair now within reach is among them, so a tick only filters that list. Robots drive at
most a few cm per tick, so the list lasts many ticks (1000 robots on 38 x 38 m, ~80,000 pairs
in reach: rebuilt every ~12 ticks, scan 3.1 -> 2.5 ms a tick; 112 robots on 12 x 12 m: 0.26 ->
0.25 ms).

Every way gives the same set of pairs, because the candidates are always filtered with the same
exact ``d2 < reach^2`` test on the same (dx, dy) = origin j - origin i, i < j; only their order
differs, and the scan keeps the nearest hit per ray (a minimum), which does not depend on the
order, so its ranges are bit for bit the same either way.
"""

from __future__ import annotations

import numpy as np

from swarm_sim.world.jit import kernel

KD_TREE_FROM = 200
"""Swarms of at least this many robots find their pairs within reach with a k-d tree; smaller
ones test all N (N - 1) / 2 pairs (cheaper than building a tree at ~100 robots; at 1000 robots
all pairs cost ~8 ms, the tree 1-2 ms)."""
SKIN = 0.4
"""`RobotPairs` keeps the pairs within reach + SKIN [m]. Robots drive <= 0.016 m a tick; at 1000
robots 0.2 m (rebuilt every 7 ticks) to 1 m (every 29, a longer list) cost within 0.15 ms a tick of
each other, 0.4 m least."""

_UPPER_PAIRS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _upper_pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(i, j) for all i < j < n, cached per swarm size."""
    if n not in _UPPER_PAIRS:
        _UPPER_PAIRS[n] = np.triu_indices(n, 1)
    return _UPPER_PAIRS[n]


def _candidates(origins: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(i, j), i < j: every pair closer than `reach` [m], maybe some more."""
    n = len(origins)
    if n < KD_TREE_FROM:
        i, j, *_ = _within(origins, *_upper_pairs(n), reach)
        return i, j
    from scipy.spatial import cKDTree

    pairs = cKDTree(origins).query_pairs(reach * (1 + 1e-9), output_type="ndarray")
    return pairs[:, 0].copy(), pairs[:, 1].copy()  # scipy gives i < j


def _within(
    origins: np.ndarray, i: np.ndarray, j: np.ndarray, reach: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The candidate pairs (i, j) strictly closer than `reach`, with (dx, dy, d2)."""
    return _filter(origins[:, 0].copy(), origins[:, 1].copy(), i, j, reach * reach)


@kernel
def _filter(
    ox: np.ndarray, oy: np.ndarray, i: np.ndarray, j: np.ndarray, reach2: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """`_within` compiled (fastmath off: the same IEEE operations as numpy's dx * dx + dy * dy).

    Every candidate is written at the next free place and kept by advancing that place only if
    it is near: no branch on a test whose outcome the CPU cannot predict. (1000 robots, ~103,000
    candidates, ~85,000 of them near: 0.55 -> 0.21 ms, against numpy's eight passes.)"""
    n = len(i)
    near_i, near_j = np.empty(n, np.intp), np.empty(n, np.intp)
    near_dx, near_dy, near_d2 = np.empty(n), np.empty(n), np.empty(n)
    count = 0
    for p in range(n):
        a, b = i[p], j[p]
        dx = ox[b] - ox[a]
        dy = oy[b] - oy[a]
        d2 = dx * dx + dy * dy
        near_i[count], near_j[count] = a, b
        near_dx[count], near_dy[count], near_d2[count] = dx, dy, d2
        count += d2 < reach2
    return near_i[:count], near_j[:count], near_dx[:count], near_dy[:count], near_d2[:count]


def pairs_in_reach(origins: np.ndarray, reach: float) -> tuple[np.ndarray, ...]:
    """(i, j, dx, dy, d2) of the robot pairs i < j strictly closer than `reach` [m], with
    (dx, dy) = origin j - origin i [m] and d2 its squared length."""
    return _within(origins, *_candidates(origins, reach), reach)


class RobotPairs:
    """`pairs_in_reach` for one swarm, tick after tick: a Verlet list of the pairs within
    reach + `skin`, rebuilt when some robot has moved skin / 2 (less a rounding margin) from
    where it was at the last build, whatever moved it."""

    def __init__(self, reach: float, skin: float = SKIN) -> None:
        self.reach = reach
        self._skin = skin
        self._anchor: np.ndarray | None = None
        self._i = self._j = np.zeros(0, dtype=np.intp)
        self.builds = 0
        """How many times the list was built (for benchmarks and tests)."""

    def __call__(self, origins: np.ndarray) -> tuple[np.ndarray, ...]:
        """`pairs_in_reach(origins, reach)` (the same set, maybe in another order)."""
        anchor = self._anchor
        if anchor is None or anchor.shape != origins.shape or self._moved(origins, anchor):
            self._i, self._j = _candidates(origins, self.reach + self._skin)
            self._anchor = origins.copy()
            self.builds += 1
        return _within(origins, self._i, self._j, self.reach)

    def _moved(self, origins: np.ndarray, anchor: np.ndarray) -> bool:
        d = origins - anchor
        limit = 0.5 * self._skin * (1 - 1e-9)
        return not np.max(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1], initial=0.0) < limit * limit
