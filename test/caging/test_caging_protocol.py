"""The caging protocol (Algs. 3-6, message types 0-4) as properties of whole batch runs, the
tie-break between two recruiters, and the timeout for a recruited robot that never answers."""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from swarm_controllers.caging.behaviour import CagingBehaviour, Phase
from swarm_controllers.caging.geometry import cage_position
from swarm_controllers.caging.landmarks import landmarks
from swarm_controllers.caging.protocol import Oriented, Positioned, Reached, Recruitment, Summon
from swarm_controllers.caging.task import CagingSense
from swarm_controllers.caging.world_config import TransportConfig
from swarm_msgs_py.types import NS_PER_S, STOP, BehaviourStatus, Observation, Pose2D, robot_index
from swarm_sim import batch
from swarm_sim.analysis.metrics import summarize
from swarm_sim.behaviour import behaviour_rng
from swarm_sim.scenario import load_scenario

SMALL = ["arena.size=5.0", "transport.landmarks.extent=[2.0, 2.0]", "robots.count=6", "sim.duration=200"]
"""Six robots (the paper's smallest swarm) on a 2 x 2 m grid: the whole protocol in ~3 min of sim."""
EARLY = "sim.stop_when_finished=true"
"""The caging scenario's own setting (the paper's runs end on delivery); `FULL` overrides it."""
FULL = "sim.stop_when_finished=false"
D = 0.05
TICK = 0.1


@cache
def _run(seed: int, *overrides: str):
    return batch.run_batch(load_scenario("caging", [*SMALL, *overrides], seed=seed)).trace


def _at(series: list, t: float):
    """The series value at time t [s] (every tick is recorded)."""
    k = int(round(t / TICK))
    assert math.isclose(series[k][0], t, abs_tol=1e-9)
    return series[k][1]


@settings(max_examples=3, derandomize=True, suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(st.integers(0, 7))
def test_every_run_follows_the_protocol(seed):
    trace = _run(seed, EARLY)
    s = trace.config
    messages = trace.messages
    robots = set(trace.robots)
    objects, positions = trace.series["object"], trace.series["robots"]
    for m in messages:
        assert m.origin in robots and m.destination in robots and m.origin != m.destination

    # one recruiter: the first detection; only it sends type 0 and type 1
    first = min((m for m in messages if isinstance(m, Recruitment)), key=lambda m: (m.stamp_ns, m.origin))
    recruiter = first.origin
    assert {m.origin for m in messages if isinstance(m, Recruitment)} == {recruiter}
    assert {m.destination for m in messages if isinstance(m, Recruitment)} == robots - {recruiter}
    summons = [m for m in messages if isinstance(m, Summon)]
    assert {m.origin for m in summons} == {recruiter}
    assert min(m.stamp_ns for m in summons) > first.stamp_ns

    # the object does not move before the transport starts (no robot touches it before everyone
    # sent its first type 3; a robot that has all of them moves in the tick it sends its own)
    t_go = max(m.stamp_ns for m in messages if isinstance(m, Oriented) and m.leg == 0) / NS_PER_S
    start = objects[0][1]
    assert all(v == start for t, v in objects if t <= t_go)

    # type 1 only after the recruiter is placed, one robot at a time, each once
    r, w, c = TransportConfig.of(s).object.radius, s.robots.diameter, 0.01
    order = [m.destination for m in summons]
    assert len(order) == len(set(order)) == len(robots) - 1
    positioned = {m.origin: m.stamp_ns for m in messages if isinstance(m, Positioned)}
    for k, m in enumerate(summons):
        t = m.stamp_ns / NS_PER_S
        x, y = _at(objects, t)
        place = cage_position((x, y), robot_index(recruiter), len(robots), r, w, c)
        assert math.dist(_at(positions, t)[robot_index(recruiter)], place) <= D + 1e-9
        if k:
            previous = summons[k - 1].destination
            assert positioned[previous] < m.stamp_ns  # the previous robot's type 2 came first

    # type 2 only from a robot that was summoned, after its summons, to every other robot
    for robot, stamp in positioned.items():
        call = next(m for m in summons if m.destination == robot)
        assert call.stamp_ns < stamp
        sent = {m.destination for m in messages if isinstance(m, Positioned) and m.origin == robot}
        assert sent == robots - {robot}

    # transport: per landmark, type 3 from all before anyone moves the object; type 4 at p_i+
    path = [landmarks(s).position(j) for j in reversed(first.trajectory)] + [(first.start_x, first.start_y)]
    cage = robots  # nobody failed in these runs
    for leg, target in enumerate(path):
        oriented = {m.origin: m.stamp_ns for m in messages if isinstance(m, Oriented) and m.leg == leg}
        reached = {m.origin: m.stamp_ns for m in messages if isinstance(m, Reached) and m.leg == leg}
        assert set(oriented) == set(reached) == cage
        still = [v for t, v in objects
                 if min(oriented.values()) / NS_PER_S <= t <= max(oriented.values()) / NS_PER_S]
        assert all(math.dist(xy, still[0]) < 1e-4 for xy in still)  # contacts settle by < 1 um
        assert max(positioned.values()) < min(oriented.values())
        for robot, stamp in reached.items():
            place = cage_position(target, robot_index(robot), len(robots), r, w, c)
            assert math.dist(_at(positions, stamp / NS_PER_S)[robot_index(robot)], place) <= D + 1e-9
            assert oriented[robot] < stamp
        if leg:  # a robot turns to the next landmark only once everyone reached the previous one
            before = {m.origin: m.stamp_ns for m in messages if isinstance(m, Reached) and m.leg == leg - 1}
            assert max(before.values()) < min(oriented.values())
    summary = summarize(trace)
    assert summary["transport_time_s"] is not None and summary["cage_size"] == len(robots)


class _Dead:
    """A robot whose controller died at the start: it never moves and never answers."""

    def __init__(self, robot: str) -> None:
        self.robot = robot

    def step(self, obs: Observation):
        return STOP

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        return BehaviourStatus(self.robot, stamp_ns or 0, "dead", 0, 0)


def test_a_recruited_robot_that_never_answers_is_skipped_after_the_timeout(monkeypatch):
    seed = 1
    recruiter = next(m.origin for m in _run(seed, EARLY).messages if isinstance(m, Recruitment))
    dead = f"robot_{(robot_index(recruiter) + 1) % 6}"  # the first robot mu_r* summons
    real = batch.make_behaviour
    monkeypatch.setattr(batch, "make_behaviour",
                        lambda scenario, robot, rng: _Dead(robot) if robot == dead else real(scenario, robot, rng))
    scenario = load_scenario("caging", [*SMALL, "sim.duration=300", EARLY, "controller.caging.call_timeout=45"],
                             seed=seed)
    trace = batch.run_batch(scenario).trace
    summons = [m for m in trace.messages if isinstance(m, Summon)]
    assert summons[0].destination == dead
    assert summons[1].stamp_ns - summons[0].stamp_ns == 45 * NS_PER_S  # the call_timeout, to the tick
    assert not any(m.origin == dead for m in trace.messages)
    assert trace.status[recruiter].extra[3] == ("skipped", dead)
    summary = summarize(trace)
    assert summary["cage_size"] == 5 and summary["transport_time_s"] is not None
    placed = max(m.stamp_ns for m in trace.messages if isinstance(m, Positioned)) / NS_PER_S
    gave_up = summons[0].stamp_ns / NS_PER_S + 45
    assert summary["search_time_s"] + summary["recruitment_time_s"] == pytest.approx(max(placed, gave_up))


def _obs(robot: str, t: float, messages=(), proximity=("",) * 9, bodies=()) -> Observation:
    return Observation(robot, round(t * NS_PER_S), Pose2D(0.0, 0.0, 0.0), 0.0, 0.0, np.zeros(5, np.float32),
                       CagingSense(tuple(proximity), tuple(bodies)), tuple(messages))


def test_two_robots_detecting_in_the_same_tick_agree_on_the_lower_index():
    s = load_scenario("caging")
    a, b = (CagingBehaviour(s, r, behaviour_rng(0, r)) for r in ("robot_2", "robot_5"))
    sees = {"proximity": ("object",) + ("",) * 8, "bodies": (("object", 0.5, 0.0),)}
    sent = {r: beh.step(_obs(r, 1.0, **sees)).messages for r, beh in (("robot_2", a), ("robot_5", b))}
    assert a.recruiter == "robot_2" and b.recruiter == "robot_5"  # both found it in tick 1.0 s
    inbox = sorted((*sent["robot_2"], *sent["robot_5"]), key=lambda m: (type(m).__name__, repr(m)))
    a.step(_obs("robot_2", 1.1, inbox, **sees))
    b.step(_obs("robot_5", 1.1, inbox, **sees))
    assert a.recruiter == b.recruiter == "robot_2"
    assert a.phase is Phase.TO_CAGE and b.phase is Phase.WAIT_SUMMON  # recruited, already within Delta
    # a third robot hears both and follows the same one
    c = CagingBehaviour(s, "robot_0", behaviour_rng(0, "robot_0"))
    c.step(_obs("robot_0", 1.1, inbox))
    assert c.recruiter == "robot_2"


def test_messages_from_strangers_or_naming_unknown_landmarks_are_ignored_and_counted():
    s = load_scenario("caging")
    beh = CagingBehaviour(s, "robot_1", behaviour_rng(0, "robot_1"))
    bad = (Recruitment(0, "robot_99", "robot_1", 0.0, 0.0, 0.0, 0.0, ()),
           Recruitment(0, "robot_3", "robot_1", 0.0, 0.0, 0.0, 0.0, (10_000,)),
           Summon(0, "robot_3", "robot_1"))  # a summons before any recruiter is known
    beh.step(_obs("robot_1", 0.1, bad))
    assert beh.phase is Phase.SEARCH and beh.recruiter is None
    assert beh.ignored == 2
    assert dict(beh.status().extra)["ignored_messages"] == "2"


@pytest.mark.parametrize("field", ["search_time_s", "recruitment_time_s", "transport_time_s"])
def test_stage_times_add_up_and_come_from_the_messages(field):
    trace = _run(0, EARLY)
    summary = summarize(trace)
    total = summary["search_time_s"] + summary["recruitment_time_s"] + summary["transport_time_s"]
    assert summary["total_time_s"] == pytest.approx(total)
    assert summary[field] > 0
    last = max(m.stamp_ns for m in trace.messages if isinstance(m, Reached)) / NS_PER_S
    assert summary["total_time_s"] == pytest.approx(last)


def test_a_sweep_run_stops_once_every_robot_is_done_with_the_same_measures():
    full, early = summarize(_run(0, FULL)), summarize(_run(0, EARLY))
    assert early["sim_seconds"] < full["sim_seconds"] == 200
    # the last type 4 reaches the others a tick later; they are done once that tick is stepped
    assert early["sim_seconds"] == pytest.approx(early["total_time_s"] + 2 * TICK)
    for key in ("search_time_s", "recruitment_time_s", "transport_time_s", "trajectory_error_m", "cage_held"):
        assert early[key] == full[key]
