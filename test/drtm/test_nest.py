"""The nest: the energy ledger of Sec. 3.1 on scripted histories, N_W and M_T2 from the robots'
reports, the nest task's light, the start layouts, the metrics of Sec. 2.4 and the bag replay."""

from __future__ import annotations

import math

import numpy as np
import pytest
from generic_robot import generic_scenario
from hypothesis import given
from hypothesis import strategies as st

from swarm_controllers.drtm.codec import NEST, NEST_STATE
from swarm_controllers.drtm.metrics import (
    active_robots_series,
    energy_efficiency,
    food_collected,
    food_deviation,
    nest_food_final,
    nest_food_series,
    oae_total,
)
from swarm_controllers.drtm.nest import NestServer
from swarm_controllers.drtm.protocol import NestEvent, NestReport, NestState
from swarm_msgs_py.types import BehaviourStatus, DropEvent
from swarm_sim import registry
from swarm_sim.analysis.metrics import RunTrace
from swarm_sim.outputs import SeriesLog
from swarm_sim.registry import task_factory
from swarm_sim.scenario import ScenarioError
from swarm_sim.world import World

DT_NS = 100_000_000


def _scenario(*extra: str):
    return generic_scenario("drtm", ["robots.count=3", *extra])


def _report(k: int, robot: int, event: NestEvent) -> NestReport:
    return NestReport(k * DT_NS, f"robot_{robot}", event)


def test_the_ledger_step_by_step_on_a_scripted_history():
    """1500 units per token, 1 unit per robot tick in S_S/S_R, E_a = 10, C_rate = 2 tokens/min
    (5 units per 0.1 s tick), F(0) = 5: every tick by hand."""
    nest = NestServer(_scenario())
    script = {  # tick k: reports stamped k - 1, handled at tick k
        1: [_report(0, 0, NestEvent.LEFT), _report(0, 1, NestEvent.LEFT)],
        2: [_report(1, 0, NestEvent.AVOIDED)],
        3: [_report(2, 0, NestEvent.FOUND), _report(2, 1, NestEvent.AVOIDED), _report(2, 1, NestEvent.AVOIDED)],
        5: [_report(4, 0, NestEvent.DEPOSITED)],
    }
    energy = 5 * 1500.0
    expected = [energy]  # tick 0: nothing has happened yet
    moving = 0
    for k in range(1, 7):
        moving += sum(1 if m.event is NestEvent.LEFT else -1 if m.event is NestEvent.DEPOSITED else 0
                      for m in script.get(k, []))
        energy += 1500.0 * sum(m.event is NestEvent.DEPOSITED for m in script.get(k, []))
        energy -= 10.0 * sum(m.event is NestEvent.AVOIDED for m in script.get(k, []))
        energy -= moving * 1.0 + 5.0
        expected.append(energy)
    states = [nest.step(k * DT_NS, script.get(k, []))[0] for k in range(7)]
    assert [s.food * 1500.0 for s in states] == pytest.approx(expected)
    # by hand: tick 1: 7500 - 2 - 5; tick 2: -10 - 2 - 5; tick 3: -20 - 2 - 5; tick 4: -2 - 5;
    # tick 5: +1500 - 1 - 5; tick 6: -1 - 5
    assert expected == [7500.0, 7493.0, 7476.0, 7449.0, 7442.0, 8936.0, 8930.0]
    assert [s.waiting for s in states] == [3, 1, 1, 1, 1, 2, 2]
    assert [s.total_oaes for s in states] == [0, 0, 1, 3, 3, 3, 3]


def test_a_robot_back_empty_stops_being_charged_and_delivers_nothing():
    """The ARGoS foraging example's unsuccessful exploration (RETURNED_EMPTY): charged from LEFT
    to its return like a forager, nothing delivered, waiting again."""
    nest = NestServer(_scenario())
    script = {1: [_report(0, 0, NestEvent.LEFT)], 4: [_report(3, 0, NestEvent.RETURNED_EMPTY)]}
    states = [nest.step(k * DT_NS, script.get(k, []))[0] for k in range(7)]
    # ticks 1-3 charge robot_0 (1 unit each), every tick charges the nest 5 units
    assert [s.food * 1500.0 for s in states] == pytest.approx([7500.0, 7494.0, 7488.0, 7482.0, 7477.0, 7472.0, 7467.0])
    assert [s.waiting for s in states] == [3, 2, 2, 2, 3, 3, 3]
    assert nest.ledger.deliveries == 0 and not nest.active


def test_every_nest_event_crosses_the_graph():
    reports = tuple(NestReport(7 * DT_NS, "robot_1", e) for e in NestEvent)
    (data,) = NEST.encode(7 * DT_NS, reports)
    assert NEST.decode(data) == reports
    assert NestReport(7 * DT_NS, "robot_1", NestEvent.RETURNED_EMPTY) in NEST.decode(data)


def test_recent_oaes_and_waiting_robots_from_a_hand_made_history():
    nest = NestServer(_scenario("controller.nest.oae_window=0.5"))  # T_2 = 5 ticks
    oae_ticks = [0, 1, 1, 4, 9]
    recent = []
    for k in range(12):
        reports = [_report(k - 1, 2, NestEvent.AVOIDED) for t in oae_ticks if t == k - 1]
        recent.append(nest.step(k * DT_NS, reports)[0].recent_oaes)
    # OAEs stamped in (t_k - 0.5 s, t_k]: by hand
    assert recent == [0, 1, 3, 3, 3, 3, 1, 1, 1, 0, 1, 1]
    window = NestServer(_scenario()).__dict__["_window_ns"]
    assert window == 20 * 10**9  # T_2 = L / 2v = 4 / (2 x 0.1) = 20 s


def test_m_t2_counts_only_returning_robots_when_asked_and_the_ledger_charges_every_oae():
    """robot_0 searches, robot_1 found a token (S_R) at tick 0 and deposits at tick 2; robot_2
    found one at tick 1. With ``returning`` M_T2 counts robot_1's OAE (tick 1) and robot_2's
    (tick 3), not robot_0's nor robot_1's after its deposit; the ledger counts all five."""
    history = {0: [(0, NestEvent.LEFT), (1, NestEvent.LEFT), (2, NestEvent.LEFT), (1, NestEvent.FOUND)],
               1: [(0, NestEvent.AVOIDED), (1, NestEvent.AVOIDED), (2, NestEvent.FOUND)],
               2: [(1, NestEvent.DEPOSITED), (0, NestEvent.AVOIDED)],
               3: [(1, NestEvent.AVOIDED), (2, NestEvent.AVOIDED)]}
    for states, expected in (("all", [0, 0, 2, 3, 5]), ("returning", [0, 0, 1, 1, 2])):
        nest = NestServer(_scenario(f"controller.nest.oae_window_states={states}"))
        seen = [nest.step(k * DT_NS, [_report(k - 1, r, e) for r, e in history.get(k - 1, ())])[0] for k in range(5)]
        assert [s.recent_oaes for s in seen] == expected, states
        assert seen[-1].total_oaes == 5


def test_an_unknown_m_t2_reading_is_refused_naming_the_key():
    with pytest.raises(ScenarioError, match="controller.nest.oae_window_states"):
        _scenario("controller.nest.oae_window_states=searching")


def test_reports_from_unknown_or_dead_robots_are_refused_and_counted():
    nest = NestServer(_scenario())
    nest.step(0, [_report(-1, 0, NestEvent.LEFT)])
    nest.robot_lost("robot_0", DT_NS)  # the world declared it dead: it stands still
    state = nest.step(DT_NS, [NestReport(0, "robot_9", NestEvent.DEPOSITED), _report(0, 0, NestEvent.DEPOSITED)])[0]
    assert state.food == 5.0 - 5.0 / 1500.0 and state.waiting == 3  # one tick of C_rate only
    assert dict(nest.rejections.counts) == {("NestReport", "unknown robot"): 1, ("NestReport", "declared dead"): 1}


@given(st.lists(st.tuples(st.integers(0, 2), st.sampled_from(list(NestEvent))), max_size=60),
       st.integers(1, 4))
def test_food_changes_only_by_deliveries_consumption_and_the_nest_rate(events, per_tick):
    nest = NestServer(_scenario())
    c = nest.ledger.config
    previous = nest.step(0, [])[0]
    active: set[str] = set()
    for k in range(1, len(events) // per_tick + 2):
        batch = [_report(k - 1, r, e) for r, e in events[(k - 1) * per_tick:k * per_tick]]
        for m in batch:
            if m.event is NestEvent.LEFT:
                active.add(m.robot)
            elif m.event in (NestEvent.DEPOSITED, NestEvent.RETURNED_EMPTY):
                active.discard(m.robot)
        state = nest.step(k * DT_NS, batch)[0]
        deliveries = sum(m.event is NestEvent.DEPOSITED for m in batch)
        oaes = sum(m.event is NestEvent.AVOIDED for m in batch)
        change = deliveries - (len(active) * c.step_energy + oaes * c.avoidance_energy) / c.token_energy \
            - c.consumption_rate * 0.1 / 60.0
        assert state.food - previous.food == pytest.approx(change, abs=1e-9)
        assert state.waiting == 3 - len(active)
        if not deliveries:
            assert state.food < previous.food
        previous = state


def test_the_light_points_at_the_nest_centre_within_its_range():
    s = _scenario("sensors.light_range=1.0")
    with World(s, task_factory(s)) as world:
        from swarm_msgs_py.types import Pose2D

        world.teleport({"robot_0": Pose2D(0.5, 0.0, math.pi), "robot_1": Pose2D(0.0, -0.9, 0.0),
                        "robot_2": Pose2D(1.5, 1.5, 0.0)})
        light = {r: o.sensed.light for r, o in world.observe().items()}
    assert light["robot_0"] == pytest.approx((0.5, 0.0), abs=1e-9)  # ahead, half the range away
    assert light["robot_1"] == pytest.approx((0.0, 0.1), abs=1e-9)  # to its left, near the edge
    assert light["robot_2"] == (0.0, 0.0)  # out of range


@pytest.mark.parametrize("layout", ["depot_random", "depot_ring"])
def test_start_layouts_put_every_robot_inside_the_nest(layout):
    s = generic_scenario("drtm", [f"robots.start_layout={layout}", "robots.count=30"])
    with World(s, task_factory(s)) as world:
        xy = world.positions.copy()
    room = s.depot.radius - s.robots.diameter / 2
    assert np.all(np.hypot(xy[:, 0], xy[:, 1]) <= room + 1e-9)
    gaps = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1)) + np.eye(len(xy)) * 9
    assert gaps.min() >= s.robots.start_spacing - 1e-9


def test_impossible_start_layouts_are_refused_naming_the_key():
    with pytest.raises(ScenarioError, match="robots.count: 200 robots"):
        generic_scenario("drtm", ["robots.count=200"])
    with pytest.raises(ScenarioError, match="robots.count: 60 robots"):
        generic_scenario("drtm", ["robots.count=60", "robots.start_layout=depot_ring", "depot.radius=0.3"])


def _trace(foods: list[float], drops: int, oaes: tuple[int, ...] = (4, 6)) -> RunTrace:
    s = generic_scenario("drtm", ["robots.count=2"])
    trace = RunTrace("drtm", 0, ("robot_0", "robot_1"), sim_seconds=0.1 * (len(foods) - 1), wall_seconds=1.0,
                     total_resources=20, mode="batch", config=s)
    trace.series["nest_food"] = [(0.1 * k, f) for k, f in enumerate(foods)]
    trace.series["nest_waiting"] = [(0.1 * k, 2 - k % 3) for k in range(len(foods))]
    trace.drops = [DropEvent("robot_0", k, k, "depot", 0.0, 0.0) for k in range(drops)]
    trace.status = {f"robot_{i}": BehaviourStatus(f"robot_{i}", 0, "waiting", n, 0) for i, n in enumerate(oaes)}
    return trace


def test_food_deviation_and_energy_efficiency_on_a_synthetic_trace():
    trace = _trace([5.0, 6.0, 22.0, 18.0], drops=4)  # F_d = 20
    assert food_deviation(trace) == pytest.approx((14 + 2 + 2) / 3)  # eq. (8): t = 1..T, not F(0)
    assert nest_food_final(trace) == 18.0 and food_collected(trace) == 4
    assert energy_efficiency(trace) == pytest.approx(18.0 / 4)  # eq. (9): F(T) / F_t
    assert oae_total(trace) == 10
    assert energy_efficiency(_trace([5.0, 4.0], drops=0)) is None
    assert food_deviation(_trace([5.0], drops=0)) is None


def test_series_are_sampled_every_five_seconds():
    foods = [float(k) for k in range(101)]  # 10 s of ticks
    trace = _trace(foods, drops=1)
    assert nest_food_series(trace) == [[0.0, 0.0], [5.0, 50.0], [10.0, 100.0]]
    assert active_robots_series(trace) == [[0.0, 0], [5.0, 2], [10.0, 1]]


def test_the_recorded_nest_state_replays_as_the_batch_runners_series():
    """The nest's series are read off the states it sends: from the messages in a batch run,
    from their recorded bytes in a bag replay (`swarm_sim.outputs.SeriesLog`)."""
    nest = NestServer(_scenario())
    (spec,) = registry.algorithm("drtm").servers
    live, replayed = SeriesLog([spec], {}), SeriesLog([spec], {})
    sent = []
    for k in range(3):
        sent += nest.step(k * DT_NS, [_report(k - 1, 0, NestEvent.LEFT)] if k == 1 else [])
    live.sent(sent)
    for state in sent:
        for data in NEST.encode(state.stamp_ns, [state]):
            replayed.replay(NEST_STATE, data)
    assert replayed.series == live.series and set(live.series) == {"nest_food", "nest_waiting", "nest_oaes"}
    assert live.series["nest_waiting"] == [(0.0, 3), (0.1, 2), (0.2, 2)]
    assert NEST_STATE in live.topics and "/nest/reports" not in live.topics
    assert isinstance(sent[-1], NestState) and sent[-1].waiting == 2
