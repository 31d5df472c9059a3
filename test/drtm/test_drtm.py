"""The DRTM paper's rules (eqs. (2)-(7), ARTM) and the response-threshold foragers' state machine."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from swarm_controllers.drtm.behaviour import ArtmBehaviour, DrtmBehaviour, ForagerState
from swarm_controllers.drtm.config import ThresholdConfig
from swarm_controllers.drtm.protocol import NestEvent, NestReport, NestState
from swarm_controllers.drtm.response_threshold import (
    ArtmThreshold,
    drtm_threshold,
    foraging_probability,
    mean_avoidance,
    stimulus,
    traffic_flow_density,
)
from swarm_controllers.drtm.task import NestSense
from swarm_msgs_py.types import Observation, Pose2D
from swarm_sim.scenario import ScenarioError, load_scenario

# ------------------------------------------------------------------ eqs. (2)-(7) by hand


@pytest.mark.parametrize(("s", "theta", "n", "expected"), [
    (15.0, 3.3, 2, 225.0 / (225.0 + 10.89)),  # the paper's start: S = 15, theta = 3.3
    (5.0, 5.0, 9, 0.5),  # theta = S: one half, whatever n (Fig. 2)
    (2.0, 4.0, 3, 8.0 / (8.0 + 64.0)),
    (4.0, 2.0, 3, 64.0 / (64.0 + 8.0)),
    (1.0, 0.0, 5, 1.0),  # a zero threshold: any positive stimulus
    (0.0, 3.3, 2, 0.0),  # S <= 0: the robots stop going foraging
    (-3.0, 3.3, 2, 0.0),
    (-3.0, 0.0, 2, 0.0),
    (1e-300, 10.0, 9, 0.0),  # no overflow for a vanishing stimulus
    (1e300, 1.0, 9, 1.0),
])
def test_foraging_probability_of_eq_7(s, theta, n, expected):
    assert foraging_probability(s, theta, n) == pytest.approx(expected, rel=1e-12, abs=1e-300)


def test_steeper_with_larger_n_as_fig_2():
    below = [foraging_probability(3.0, 5.0, n) for n in range(2, 10)]
    above = [foraging_probability(7.0, 5.0, n) for n in range(2, 10)]
    assert below == sorted(below, reverse=True) and above == sorted(above)


def test_stimulus_density_and_threshold_by_hand():
    assert stimulus(20.0, 5.0) == 15.0 and stimulus(20.0, 23.5) == -3.5
    assert traffic_flow_density(20, 5, 4.0) == 15 / 16  # eq. (4)
    assert traffic_flow_density(20, 20, 3.0) == 0.0
    assert mean_avoidance(30, 20) == 1.5  # eq. (5)
    assert drtm_threshold(15 / 16, 1.5, 3.0, 2.0) == pytest.approx(3 * 15 / 16 + 2 * 1.5)  # eq. (6)


def test_artm_threshold_moves_against_the_stimulus_within_its_bounds():
    artm = ArtmThreshold(3.3, 1.0, 10.0, 1.0)
    values = [artm.update(s) for s in (15.0, 14.0, 10.0, 2.0, 3.0, 20.0)]
    # first stimulus only remembered; -1 -> +1; -4 -> +4; -8 -> clipped at 10; +1 -> 9; +17 -> 1
    assert values == pytest.approx([3.3, 4.3, 8.3, 10.0, 9.0, 1.0])


# ------------------------------------------------------------------ the foragers


def _scenario(*extra: str):
    return load_scenario("drtm", ["robots.count=2", *extra])


def _obs(stamp_k: int, *, carrying=False, resources=(), light=(0.5, 0.0), messages=(), x=0.0, y=0.0,
         ranges=None) -> Observation:
    return Observation("robot_0", stamp_k * 100_000_000, Pose2D(x, y, 0.0), 0.0, 0.0,
                       np.full(24, np.inf, dtype=np.float32) if ranges is None else ranges,
                       NestSense(tuple(resources), carrying, light), tuple(messages))


def _state(stamp_k: int, food: float, waiting: int = 2, recent: int = 0) -> NestState:
    return NestState(stamp_k * 100_000_000, food, waiting, recent, 0)


def _events(command) -> list[NestEvent]:
    return [m.event for m in command.messages if isinstance(m, NestReport)]


def test_waits_t1_ticks_then_leaves_searches_returns_and_deposits():
    scenario = _scenario("controller.threshold.min_wait_steps=5")
    robot = DrtmBehaviour(scenario, "robot_0", np.random.default_rng(1))
    assert robot.state is ForagerState.WAITING and 2 <= robot.exponent <= 9
    hungry = _state(0, food=0.0)  # S = 20, theta = 0: P_s = 1
    for k in range(5):  # t_1 = 0..4 < T_1: standing still
        c = robot.step(_obs(k, messages=(hungry,) if k == 1 else ()))
        assert (c.linear, c.angular) == (0.0, 0.0) and not c.messages
    c = robot.step(_obs(5))
    assert robot.state is ForagerState.SEARCHING and _events(c) == [NestEvent.LEFT] and c.linear > 0
    c = robot.step(_obs(6, resources=[(1.0, 0.0)]))  # A(t) = 1: straight at the token ahead
    assert c.linear > 0 and c.angular == 0.0
    c = robot.step(_obs(7, carrying=True, light=(0.0, 0.3)))  # light on the left
    assert robot.state is ForagerState.RETURNING and _events(c) == [NestEvent.FOUND] and c.angular > 0
    c = robot.step(_obs(8, carrying=False, x=0.7))
    assert robot.state is ForagerState.WAITING and _events(c) == [NestEvent.DEPOSITED]
    assert robot.trips == 1 and c.linear > 0  # settling into the nest, towards the light
    status = robot.status()
    assert (status.state, status.trips, status.obstacle_avoidance_events) == ("waiting", 1, 0)


def test_never_leaves_without_news_from_the_nest_or_when_the_nest_is_full():
    scenario = _scenario("controller.threshold.min_wait_steps=0", "controller.threshold.draw_period=1")
    robot = DrtmBehaviour(scenario, "robot_0", np.random.default_rng(2))
    for k in range(20):
        robot.step(_obs(k))
    assert robot.state is ForagerState.WAITING  # heard nothing
    for k in range(20, 200):
        robot.step(_obs(k, messages=(_state(k - 1, food=20.0),)))  # S = 0: P_s = 0
    assert robot.state is ForagerState.WAITING


def test_a_robot_that_stays_draws_again_after_t1_by_default():
    scenario = _scenario("controller.threshold.min_wait_steps=10")
    robot = DrtmBehaviour(scenario, "robot_0", np.random.default_rng(3))
    draws = []
    robot._draw = lambda: draws.append(robot._waited) or False  # stays every time
    for k in range(60):
        robot.step(_obs(k, messages=(_state(k, 19.0),)))
    assert draws == [10, 20, 30, 40, 50]
    every_tick = DrtmBehaviour(_scenario("controller.threshold.min_wait_steps=10",
                                         "controller.threshold.draw_period=1"), "robot_0", np.random.default_rng(3))
    draws.clear()
    every_tick._draw = lambda: draws.append(every_tick._waited) or False
    for k in range(15):
        every_tick.step(_obs(k, messages=(_state(k, 19.0),)))
    assert draws == [10, 11, 12, 13, 14]


def test_drtm_threshold_comes_from_the_nest_state_and_artm_from_food_changes():
    scenario = _scenario()
    drtm = DrtmBehaviour(scenario, "robot_0", np.random.default_rng(4))
    # 2 robots, L = 4: k = (2 - 1) / 16; M_A = 3 / 2
    assert drtm.threshold(_state(0, 10.0, waiting=1, recent=3)) == pytest.approx(3 / 16 + 2 * 1.5)
    bounded = DrtmBehaviour(_scenario("controller.threshold.drtm_bounded=true"), "robot_0",
                            np.random.default_rng(4))
    assert bounded.threshold(_state(0, 10.0)) == 1.0  # eq. (6) gives 0, the bounds say 1
    artm = ArtmBehaviour(scenario, "robot_0", np.random.default_rng(4))
    assert artm.threshold(_state(0, 10.0)) == 3.3
    for k, food in enumerate((5.0, 7.0, 6.5)):
        artm.step(_obs(k, messages=(_state(k, food),)))
    assert artm.threshold(_state(3, 0.0)) == pytest.approx(3.3 + 2.0 - 0.5)


def test_every_avoidance_episode_is_reported_once():
    scenario = _scenario()
    robot = DrtmBehaviour(scenario, "robot_0", np.random.default_rng(5))
    robot._state = ForagerState.SEARCHING
    blocked = np.full(24, np.inf, dtype=np.float32)
    blocked[12] = 0.06  # ray 12 points straight ahead
    events = [_events(robot.step(_obs(k, ranges=blocked))) for k in range(3)]
    assert events == [[NestEvent.AVOIDED], [], []]
    robot.step(_obs(3))
    assert _events(robot.step(_obs(4, ranges=blocked))) == [NestEvent.AVOIDED]
    assert robot.status().obstacle_avoidance_events == 2


def test_the_sections_are_checked_naming_the_key():
    with pytest.raises(ScenarioError, match="controller.threshold.exponent_min"):
        _scenario("controller.threshold.exponent_min=0")
    with pytest.raises(ScenarioError, match="controller.nest.token_energy"):
        _scenario("controller.nest.token_energy=0")
    with pytest.raises(ScenarioError, match="resources.respawn"):
        _scenario("resources.respawn=false")
    with pytest.raises(ScenarioError, match="controller.threshold.draw_period"):
        _scenario("controller.threshold.draw_period=0")
    assert ThresholdConfig.of(_scenario()).period() == 50


def test_reports_are_protocol_messages():
    robot = DrtmBehaviour(_scenario("controller.threshold.min_wait_steps=0", "controller.threshold.draw_period=1"),
                          "robot_0", np.random.default_rng(6))
    c = robot.step(_obs(0, messages=(_state(0, 0.0),)))
    assert c.messages == (NestReport(0, "robot_0", NestEvent.LEFT),)
    assert replace(c.messages[0], robot="robot_1").CHANNEL == "nest"
