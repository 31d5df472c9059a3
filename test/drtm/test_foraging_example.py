"""The ARGoS foraging example's rule (``foraging_example``, the DRTM reference run's): its states
and counters on scripted observations, its probabilities, its reports to the nest's ledger."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_controllers.drtm.foraging_example import ExampleState, ForagingExampleBehaviour
from swarm_controllers.drtm.nest import NestServer
from swarm_controllers.drtm.protocol import NestEvent, NestReport, NestState
from swarm_controllers.drtm.task import NestSense
from swarm_msgs_py.types import Observation, Pose2D
from swarm_sim import registry
from swarm_sim.scenario import ScenarioError, load_scenario

DT_NS = 100_000_000
OUT = (1.5, 0.0, 0.0)
"""A pose outside the nest (depot radius 0.75 at the origin)."""
IN = (0.0, 0.0, 0.0)


def _scenario(*extra: str):
    return load_scenario("drtm_example", ["robots.count=2", *extra])


def _robot(*extra: str, seed: int = 1) -> ForagingExampleBehaviour:
    return ForagingExampleBehaviour(_scenario(*extra), "robot_0", np.random.default_rng(seed))


FREE = np.full(24, np.inf, dtype=np.float32)
BLOCKED = FREE.copy()
BLOCKED[12] = 0.1  # ray 12 of the foot-bot's scan is the sensor at +7.5 deg: outside the +-5 deg window


def _obs(k: int, pose=OUT, *, carrying=False, light=(0.5, 0.0), ranges=FREE, messages=()) -> Observation:
    return Observation("robot_0", k * DT_NS, Pose2D(*pose), 0.0, 0.0, ranges, NestSense((), carrying, light),
                       messages)


def _told(k: int, good: int, bad: int) -> NestState:
    """The nest's state at tick k, relaying `good` successful and `bad` unsuccessful tellings."""
    return NestState(k * DT_NS, 5.0, 2, 0, 0, good, bad)


def _events(command) -> list[NestEvent]:
    return [m.event for m in command.messages if isinstance(m, NestReport)]


class _Clock:
    """Feeds a robot its ticks in order."""

    def __init__(self, robot: ForagingExampleBehaviour) -> None:
        self.robot, self.k = robot, 0

    def step(self, pose=OUT, **kw):
        command = self.robot.step(_obs(self.k, pose, **kw))
        self.k += 1
        return command


def test_the_registration_names_its_states_and_authors_robot():
    a = registry.algorithm("foraging_example")
    assert a.states == tuple(s.value for s in ExampleState) and a.authors_robot == "footbot_foraging"
    assert {m.name for m in a.metrics} == {m.name for m in registry.algorithm("drtm").metrics}


@pytest.mark.parametrize("minimum", [0, 3, 50])
def test_a_robot_that_came_back_rests_more_than_the_minimum_resting_time(minimum):
    robot = _robot("controller.example.initial_rest_to_explore_prob=1.0",
                   f"controller.example.minimum_resting_time={minimum}",
                   "controller.example.minimum_search_for_place_in_nest_time=2")
    clock = _Clock(robot)
    # At the start TimeRested is the minimum (the example's SStateData::Reset): one tick, then it leaves.
    assert _events(clock.step(IN)) == [] and robot.state is ExampleState.RESTING
    c = clock.step(IN)
    assert robot.state is ExampleState.EXPLORING and _events(c) == [NestEvent.LEFT]
    assert (c.linear, c.angular) == (0.0, 0.0)  # Rest() sets no wheels on the tick it leaves
    assert _events(clock.step(carrying=True)) == [NestEvent.FOUND] and robot.state is ExampleState.RETURNING
    for _ in range(3):  # in the nest (the world dropped the token as it entered): TimeSearching-
        # ForPlaceInNest 0, 1, 2, not yet more than 2
        clock.step(IN)
        assert robot.state is ExampleState.RETURNING
    c = clock.step(IN)
    assert robot.state is ExampleState.RESTING and _events(c) == [NestEvent.DEPOSITED, NestEvent.TOLD_SUCCESSFUL]
    resting = [clock.step(IN) for _ in range(minimum + 1)]  # TimeRested 0 .. minimum: no draw
    assert robot.state is ExampleState.RESTING
    assert all((c.linear, c.angular, c.messages) == (0.0, 0.0, ()) for c in resting)
    assert _events(clock.step(IN)) == [NestEvent.LEFT]
    assert robot.status().trips == 1


def test_a_pickup_applies_the_food_rule_and_sends_the_robot_home():
    robot = _robot()
    robot._state = ExampleState.EXPLORING
    robot.time_exploring_unsuccessfully = 17
    c = robot.step(_obs(0, carrying=True))
    assert robot.state is ExampleState.RETURNING and _events(c) == [NestEvent.FOUND]
    assert (robot.explore_to_rest, robot.rest_to_explore) == pytest.approx((0.09, 0.11))
    assert robot.time_exploring_unsuccessfully == 0
    c = robot.step(_obs(1, carrying=True, light=(0.0, 0.4)))  # the light on its left
    assert c.angular > 0 and not _events(c)


def test_an_unsuccessful_exploration_gives_up_after_the_minimum_time_and_rests_empty():
    robot = _robot("controller.example.initial_explore_to_rest_prob=0.0",
                   "controller.example.minimum_search_for_place_in_nest_time=0")
    robot._state = ExampleState.EXPLORING
    clock = _Clock(robot)
    for _ in range(601):  # TimeExploringUnsuccessfully 0 .. 600: no draw
        clock.step()
    assert robot.state is ExampleState.EXPLORING and robot.explore_to_rest == 0.0
    for n in range(1, 4):  # each draw that keeps exploring: the food rule the other way
        clock.step()
        assert robot.explore_to_rest == pytest.approx(0.01 * n)
        assert robot.rest_to_explore == pytest.approx(0.1 - 0.01 * n)
    while robot.state is ExampleState.EXPLORING:
        clock.step()
    assert clock.k < 601 + 50  # ExploreToRestProb grows until a draw sends it home
    assert _events(clock.step(IN)) == []  # TimeSearchingForPlaceInNest 0: not more than 0
    c = clock.step(IN)
    assert robot.state is ExampleState.RESTING and _events(c) == [NestEvent.RETURNED_EMPTY, NestEvent.TOLD_UNSUCCESSFUL]
    assert robot.status().trips == 0


def test_every_collision_tick_moves_the_probabilities_and_each_episode_is_one_oae():
    robot = _robot("controller.example.initial_rest_to_explore_prob=0.03")
    robot._state = ExampleState.EXPLORING
    clock = _Clock(robot)
    events = [_events(clock.step(ranges=r)) for r in (BLOCKED, BLOCKED, BLOCKED, FREE, BLOCKED, BLOCKED)]
    assert events == [[NestEvent.AVOIDED], [], [], [], [NestEvent.AVOIDED], []]
    assert robot.explore_to_rest == pytest.approx(0.1 + 5 * 0.01)
    assert robot.rest_to_explore == 0.0  # 0.03 - 5 x 0.01, clipped at 0
    assert robot.status().obstacle_avoidance_events == 2
    robot._state = ExampleState.RETURNING  # a returning robot counts episodes too, but no collision rule
    assert _events(clock.step(ranges=FREE)) == [] and _events(clock.step(ranges=BLOCKED)) == [NestEvent.AVOIDED]
    assert robot.explore_to_rest == pytest.approx(0.15)


def test_an_explorer_in_the_nest_heads_away_from_the_light():
    robot = _robot()
    robot._state = ExampleState.EXPLORING
    outside = robot.step(_obs(0, OUT))
    ahead = robot.step(_obs(1, IN))  # max_speed x ((1, 0) - 0.25 (1, 0)): straight on, slower
    assert (outside.linear, outside.angular) == (0.1, 0.0)
    assert ahead.linear == pytest.approx(0.075) and ahead.angular == 0.0
    left = robot.step(_obs(2, IN, light=(0.0, 0.9)))  # (1, -0.25): 14 deg to the right, a soft turn
    assert left.angular < 0 and left.linear > 0


def test_the_nest_is_where_ground_sensors_2_and_3_both_are():
    """Right on the nest's edge (radius 0.75): facing +y, sensors 2 and 3 (right-hand side, body
    y = -0.0116) lie 0.0116 m further out than the centre; facing -y, further in."""
    robot = _robot()
    robot._state = ExampleState.RETURNING
    clock = _Clock(robot)
    for _ in range(3):
        clock.step((0.74, 0.0, -math.pi / 2))
    assert robot.time_searching_for_place_in_nest == 3
    clock.step((0.74, 0.0, math.pi / 2))  # centre inside, the sensors out: not in the nest
    assert robot.time_searching_for_place_in_nest == 0


def test_a_resting_robot_moves_its_probabilities_once_per_robot_told():
    """The social rule: +-social delta per telling, each state heard once."""
    robot = _robot("controller.example.minimum_resting_time=100")  # it does not leave meanwhile
    robot.step(_obs(0, IN, messages=(_told(0, 2, 1),)))
    assert robot.rest_to_explore == pytest.approx(0.1 + 0.02 - 0.01)
    assert robot.explore_to_rest == pytest.approx(0.1 - 0.02 + 0.01)
    robot.step(_obs(1, IN, messages=(_told(0, 2, 1),)))  # the same state again: nothing new
    robot.step(_obs(2, IN, messages=(_told(1, 0, 3),)))
    assert robot.rest_to_explore == pytest.approx(0.11 - 0.03)
    assert robot.explore_to_rest == pytest.approx(0.09 + 0.03)


def test_robots_not_resting_or_leaving_on_the_tick_do_not_hear():
    robot = _robot("controller.example.initial_rest_to_explore_prob=1.0")
    robot.step(_obs(0, IN, messages=(_told(0, 0, 0),)))
    robot.step(_obs(1, IN, messages=(_told(1, 5, 0),)))  # it leaves on this tick (Rest()'s first branch)
    assert robot.state is ExampleState.EXPLORING and robot.rest_to_explore == 1.0
    assert robot.explore_to_rest == pytest.approx(0.1)
    robot.step(_obs(2, OUT, messages=(_told(2, 0, 5),)))  # exploring: tellings are not for it
    assert robot.explore_to_rest == pytest.approx(0.1) and robot.rest_to_explore == 1.0


def test_a_robot_does_not_count_its_own_telling_and_the_nest_relays_the_others():
    """Two robots through the nest: robot_0 comes back with food and tells; robot_1, resting, hears
    it one tick after the nest applied it; robot_0 itself does not count it."""
    scenario = _scenario("controller.example.minimum_resting_time=1000",
                         "controller.example.minimum_search_for_place_in_nest_time=0")
    teller = ForagingExampleBehaviour(scenario, "robot_0", np.random.default_rng(1))
    listener = ForagingExampleBehaviour(scenario, "robot_1", np.random.default_rng(2))
    teller._state = ExampleState.EXPLORING
    nest = NestServer(scenario)
    state = nest.step(0, [])[0]
    sequence = [(OUT, True), (IN, False), (IN, False), (IN, False), (IN, False)]
    for k, (pose, carrying) in enumerate(sequence, 1):
        a = teller.step(_obs(k, pose, carrying=carrying, messages=(state,)))
        b = listener.step(_obs(k, IN, messages=(state,)))
        state = nest.step((k + 1) * DT_NS, [*a.messages, *b.messages])[0]
        if NestEvent.TOLD_SUCCESSFUL in _events(a):
            assert teller.state is ExampleState.RESTING and (state.told_successful, state.told_unsuccessful) == (1, 0)
    assert listener.rest_to_explore == pytest.approx(0.11) and listener.explore_to_rest == pytest.approx(0.09)
    assert teller.rest_to_explore == pytest.approx(0.11)  # the food rule's 0.01 only, not its own telling
    assert state.told_successful == 0  # the nest relays a telling once


def test_the_section_is_checked_naming_the_key():
    with pytest.raises(ScenarioError, match="controller.example.initial_rest_to_explore_prob"):
        _scenario("controller.example.initial_rest_to_explore_prob=1.5")
    with pytest.raises(ScenarioError, match="controller.example.minimum_resting_time"):
        _scenario("controller.example.minimum_resting_time=-1")
    with pytest.raises(ScenarioError, match="controller.example.collision_rule_explore_to_rest_delta_prob"):
        _scenario("controller.example.collision_rule_explore_to_rest_delta_prob=-0.1")


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.booleans(), st.booleans(), st.integers(1, 12)), min_size=1, max_size=30),
       st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.integers(0, 2**32 - 1))
def test_the_ledger_follows_the_robot_whatever_the_world_does(stretches, r2e, e2r, seed):
    """Any history of pickups and drops (even impossible ones), positions and obstacles, in
    stretches of a few ticks: the probabilities stay in [0, 1], a resting robot stands still and
    avoids nothing, the nest charges the robot exactly while it is not resting, and every drop is
    credited once."""
    steps = [(carrying, inside, blocked) for carrying, inside, blocked, n in stretches for _ in range(n)]
    scenario = _scenario(f"controller.example.initial_rest_to_explore_prob={r2e}",
                         f"controller.example.initial_explore_to_rest_prob={e2r}",
                         "controller.example.minimum_resting_time=2",
                         "controller.example.minimum_unsuccessful_explore_time=5",
                         "controller.example.minimum_search_for_place_in_nest_time=2",
                         "controller.example.collision_rule_explore_to_rest_delta_prob=0.3")
    robot = ForagingExampleBehaviour(scenario, "robot_0", np.random.default_rng(seed))
    nest = NestServer(scenario)
    nest.step(0, [])
    drops, carried = 0, False
    for k, (carrying, inside, blocked) in enumerate(steps):
        was = robot.state
        c = robot.step(_obs(k, IN if inside else OUT, carrying=carrying, ranges=BLOCKED if blocked else FREE))
        drops += carried and not carrying
        carried = carrying
        assert 0.0 <= robot.rest_to_explore <= 1.0 and 0.0 <= robot.explore_to_rest <= 1.0
        if was is ExampleState.RESTING and robot.state is ExampleState.RESTING:
            assert (c.linear, c.angular) == (0.0, 0.0) and NestEvent.AVOIDED not in _events(c)
        nest.step((k + 1) * DT_NS, c.messages)
        assert ("robot_0" in nest.active) == (robot.state is not ExampleState.RESTING)
    assert nest.ledger.deliveries + robot._delivered == drops
    if robot.state is ExampleState.RESTING:
        assert robot._delivered == 0
