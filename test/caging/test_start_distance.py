"""The robots' starts p_i^0 (Alg. 2) and ``transport.swarm_distance``: every start at least that far
from the object's centre, the default drawing exactly what it drew before the key existed, a
distance the rectangle cannot hold refused in one line naming the key, and the factor's value
recomputed from Table 2."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_controllers.caging.claims import PAPER_TABLE2
from swarm_controllers.caging.factors import SWARM_DISTANCE
from swarm_controllers.caging.plan import grid_path_length
from swarm_controllers.caging.task import START_GAP, starts
from swarm_controllers.caging.world_config import TransportConfig
from swarm_sim.registry import task_factory
from swarm_sim.scenario import ScenarioError, load_scenario
from swarm_sim.world import World

HALF = np.array([4.0, 3.5])
"""The shipped landmark rectangle's half-sides [m]."""
WIDTH = 0.13
CLEAR = 0.3 + WIDTH / 2 + 0.2
"""The shipped object's sensor reach [m]: r + w/2 + proximity range."""
ROBOTS = tuple(f"robot_{i}" for i in range(8))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 8), distance=st.floats(0.0, 3.0),
       cx=st.floats(-4.0, 4.0), cy=st.floats(-3.5, 3.5))
def test_every_start_is_in_the_rectangle_apart_and_at_least_the_distance_from_the_object(seed, count, distance,
                                                                                          cx, cy):
    center = np.array([cx, cy])
    poses = starts(np.random.default_rng(seed), HALF, center, ROBOTS[:count], WIDTH, CLEAR, distance)
    xy = np.array([(q.x, q.y) for q in poses.values()])
    assert list(poses) == list(ROBOTS[:count])
    assert (np.abs(xy) <= HALF).all()
    away = np.hypot(*(xy - center).T)
    assert (away >= distance).all() and (away > CLEAR).all()
    gaps = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))[np.triu_indices(count, 1)]
    assert (gaps >= WIDTH + START_GAP).all()
    assert all(-math.pi <= q.yaw <= math.pi for q in poses.values())


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), distance=st.floats(0.0, CLEAR))
def test_a_distance_within_the_sensor_reach_changes_no_draw(seed, distance):
    center = np.array([0.5, -1.0])
    placed = [starts(np.random.default_rng(seed), HALF, center, ROBOTS, WIDTH, CLEAR, d) for d in (0.0, distance)]
    assert placed[0] == placed[1]


def test_the_default_places_what_it_placed_before_the_key_existed():
    """Seed 0 of the shipped scenario, as the transport task placed it at f282862 (before
    ``transport.swarm_distance``): the same object, the same starts, bit for bit."""
    scenario = load_scenario("caging", seed=0)
    assert TransportConfig.of(scenario).swarm_distance == 0.0
    with World(scenario, task_factory(scenario)) as world:
        assert (world.task.object_pose.x, world.task.object_pose.y) == (3.543500423063035, -1.2856399333015132)
        assert world.positions[0].tolist() == [1.778740709198603, -2.620778401971147]
        assert world.positions[-1].tolist() == [-0.23530519867821287, -1.9461596513286017]
        assert world.headings[0] == -0.4839537873514669


@pytest.mark.parametrize("seed", [0, 1])
def test_the_scenario_key_keeps_the_whole_swarm_away_from_the_object(seed):
    scenario = load_scenario("caging", [f"transport.swarm_distance={SWARM_DISTANCE}"], seed=seed)
    with World(scenario, task_factory(scenario)) as world:
        obj = np.array([world.task.object_pose.x, world.task.object_pose.y])
        assert (np.hypot(*(world.positions - obj).T) >= SWARM_DISTANCE).all()


def test_a_distance_the_rectangle_cannot_hold_is_refused_in_one_line_naming_the_key():
    # 5.3 m from the centre leaves four slivers ~3 cm across at the corners (5.32 m away): room for
    # at most one robot each, never eight
    with pytest.raises(ScenarioError) as info:
        starts(np.random.default_rng(3), HALF, np.zeros(2), ROBOTS, WIDTH, CLEAR, 5.3)
    message = str(info.value)
    assert message.startswith("transport.swarm_distance: 8 robots do not fit apart in the 8 x 7 m landmark "
                              "rectangle at least 5.3 m from the object at (0.00, 0.00)") and "\n" not in message
    # without the key, a crowd that does not fit still names robots.count
    with pytest.raises(ScenarioError, match=r"^robots.count: 8 robots do not fit apart in the 0.2 x 0.2 m"):
        starts(np.random.default_rng(3), np.array([0.1, 0.1]), np.array([1.0, 1.0]), ROBOTS, WIDTH, 0.0, 0.0)


def test_the_factor_value_follows_from_table_2():
    """Each Table 2 length is one shortest 8-connected path of 7 steps of 0.5 m: 7 cells along one
    axis, 2, 4 or 6 along the other. The least straight-line span (3.64 m) less the detection
    landmark's distance to the object's centre (r + w/2 + proximity range + half a step, cell 0's
    object) is the factor's value, to 0.1 m."""
    scenario = load_scenario("caging")
    step = TransportConfig.of(scenario).landmarks.step
    spans = {}
    for cell, (length, _, _) in PAPER_TABLE2.items():
        fits = [(a, b) for a in range(20) for b in range(a + 1) if abs(grid_path_length(step, a, b) - length) < 5e-4]
        assert len(fits) == 1 and fits[0][0] == 7, (cell, fits)
        spans[cell] = step * math.hypot(*fits[0])
    assert min(spans.values()) == pytest.approx(math.hypot(3.5, 1.0))
    gap = TransportConfig.of(scenario).object.radius + scenario.robots.diameter / 2 \
        + scenario.sensors.proximity.range + step / 2
    assert round(min(spans.values()) - gap, 1) == SWARM_DISTANCE
