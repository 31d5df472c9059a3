"""The transport's planned path under its three readings (`swarm_controllers.caging.plan`): the
shortest grid path is a path of the 8-neighbourhood, as short as a Dijkstra search over the same
graph finds, and Table 2's lengths are such paths of 7 steps; one batch run per landmark-only
reading follows the plan it measures."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_controllers.caging.claims import PAPER_TABLE2
from swarm_controllers.caging.landmarks import landmarks
from swarm_controllers.caging.metrics import caging_report, polyline_length, transport_stage
from swarm_controllers.caging.plan import PLANS, grid_path_length, nearest, planned_path, shortest_grid_path
from swarm_controllers.caging.protocol import Reached, Recruitment
from swarm_sim.batch import run_batch
from swarm_sim.scenario import ScenarioError, load_scenario

MARKS = landmarks(load_scenario("caging"))
"""The shipped grid: 17 x 15 landmarks, 0.5 m apart."""


def _dijkstra(a: int, b: int) -> float:
    """The shortest path's length over the landmarks' neighbourhoods eta (an independent oracle)."""
    best, queue = {a: 0.0}, [(0.0, a)]
    while queue:
        d, i = heapq.heappop(queue)
        if i == b:
            return d
        if d > best[i]:
            continue
        for j in MARKS.neighbours[i]:
            e = d + math.dist(MARKS.position(i), MARKS.position(j))
            if e < best.get(j, math.inf) - 1e-12:
                best[j] = e
                heapq.heappush(queue, (e, j))
    raise AssertionError("unreachable")


def _is_shortest_grid_path(path: list[int], a: int, b: int) -> bool:
    steps_ok = all(j in MARKS.neighbours[i] for i, j in zip(path, path[1:]))
    length = polyline_length(np.array([MARKS.position(i) for i in path]))
    return path[0] == a and path[-1] == b and steps_ok and math.isclose(length, _dijkstra(a, b), abs_tol=1e-9)


def test_table2_lengths_are_shortest_7_step_grid_paths():
    """3.9142, 4.3284, 4.7426 m: 7 cells along one axis and 2, 4, 6 along the other at 0.5 m."""
    lengths = sorted({paper[0] for paper in PAPER_TABLE2.values()})
    assert [round(grid_path_length(0.5, 7, k), 4) for k in (2, 4, 6)] == lengths
    a = MARKS.index(2, 3)
    for k, length in zip((2, 4, 6), lengths):
        path = shortest_grid_path(MARKS, a, MARKS.index(2 + 7, 3 + k))
        assert len(path) == 8  # 7 steps
        assert round(polyline_length(np.array([MARKS.position(i) for i in path])), 4) == length


cells = st.tuples(st.integers(0, 16), st.integers(0, 14))


@settings(max_examples=60, deadline=None)
@given(cells, cells)
def test_shortest_grid_path_is_a_shortest_path_of_the_neighbourhood(a, b):
    i, j = MARKS.index(*a), MARKS.index(*b)
    path = shortest_grid_path(MARKS, i, j)
    assert _is_shortest_grid_path(path, i, j)
    assert math.isclose(_dijkstra(i, j), grid_path_length(MARKS.step, b[0] - a[0], b[1] - a[1]), abs_tol=1e-9)


def test_the_oracle_rejects_a_detour_and_a_jump():
    """The adversarial twins: a walk with one detour, and a path skipping a landmark, fail."""
    a, b = MARKS.index(2, 3), MARKS.index(9, 5)
    path = shortest_grid_path(MARKS, a, b)
    detour = [path[0], MARKS.index(2, 4), *path[1:]]  # up first, then the diagonal: one step longer
    assert all(j in MARKS.neighbours[i] for i, j in zip(detour, detour[1:]))
    assert not _is_shortest_grid_path(detour, a, b)
    assert not _is_shortest_grid_path([path[0], *path[2:]], a, b)


def test_the_readings_share_their_start_and_differ_in_their_end():
    walk = [MARKS.index(2, 3), MARKS.index(3, 3), MARKS.index(3, 4), MARKS.index(2, 4), MARKS.index(3, 5)]
    start = (-3.9, -3.1)
    to_start, search, shortest = (planned_path(MARKS, walk, start, plan) for plan in PLANS)
    assert to_start[0] == search[0] == shortest[0] == MARKS.position(walk[-1])
    assert to_start[-1] == start and to_start[:-1] == search
    assert search[-1] == shortest[-1] == MARKS.position(walk[0])
    assert polyline_length(np.array(shortest)) < polyline_length(np.array(search))
    assert shortest == [MARKS.position(i) for i in shortest_grid_path(MARKS, walk[-1], walk[0])]


def test_an_empty_trajectory_ends_where_the_search_began():
    start = (1.13, -0.62)
    for plan in ("search", "shortest"):
        assert planned_path(MARKS, [], start, plan) == [MARKS.position(nearest(MARKS, start))]
    assert planned_path(MARKS, [], start, "search_to_start") == [start]


def test_an_unknown_plan_is_refused_naming_the_key():
    with pytest.raises(ValueError, match="controller.caging.plan"):
        planned_path(MARKS, [0], (0.0, 0.0), "straight")
    with pytest.raises(ScenarioError, match="controller.caging.plan"):
        load_scenario("caging", ["controller.caging.plan=straight"])


SMALL = ["arena.size=5.0", "transport.landmarks.extent=[2.0, 2.0]", "robots.count=6", "sim.duration=300"]
"""Six robots on a 2 x 2 m grid (test_caging_e2e's set-up): a whole protocol in about three minutes of sim."""
SEED = 11
"""Its recruiter reaches 5 landmarks with a detour: 5 targets under ``search``, 2 under ``shortest``."""


@pytest.mark.parametrize("plan", ["search", "shortest"])
def test_a_run_follows_and_measures_its_plan(plan):
    scenario = load_scenario("caging", [*SMALL, f"controller.caging.plan={plan}"], seed=SEED)
    trace = run_batch(scenario).trace
    first = min((m for m in trace.messages if isinstance(m, Recruitment)), key=lambda m: m.stamp_ns)
    marks = landmarks(scenario)
    readings = {p: planned_path(marks, first.trajectory, (first.start_x, first.start_y), p) for p in PLANS}
    assert len({len(r) for r in readings.values()}) == 3  # the seed tells the three readings apart
    targets = readings[plan]
    assert max(m.leg for m in trace.messages if isinstance(m, Reached)) == len(targets) - 1
    report, transport = caging_report(trace), transport_stage(trace)
    assert report.transport_time_s is not None
    np.testing.assert_allclose(transport.planned[1:], targets)
    assert math.isclose(report.planned_path_m, polyline_length(transport.planned))
