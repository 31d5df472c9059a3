"""Metrics counted by the state each robot reports (`swarm_sim.analysis.state_rules`), on
hand-made readings and statuses; the queue paper's and the DRTM paper's rules. Batch and bag give
the same numbers: test/queue/test_queue_e2e.py and test/drtm/test_drtm_e2e.py compare them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from swarm_msgs_py.types import BehaviourStatus
from swarm_sim.analysis.state_rules import RuleLog, StatusLog, events_by_state
from swarm_sim.scenario import load_scenario


def _status(state: str, stamp: int = 0, oae: int = 0, robot: str = "robot_0", **extra: str) -> BehaviourStatus:
    return BehaviourStatus(robot, stamp, state, oae, 0, tuple(extra.items()))


def _at(degrees: float) -> tuple[float, float]:
    return math.cos(math.radians(degrees)) * 0.3, math.sin(math.radians(degrees)) * 0.3


def test_a_tick_counts_when_the_reading_lies_within_its_states_cone():
    rule = {"PATH": 30.0, "DOCK": None}.get
    log = RuleLog(("robot_0",), lambda st: rule(st.state, 80.0), dt=0.1)
    for degrees, state, counted in ((20.0, "PATH", True), (50.0, "PATH", False), (50.0, "WALK", True),
                                    (-79.0, "WALK", True), (100.0, "WALK", False), (0.0, "DOCK", False)):
        before = log.seconds()["robot_0"]
        log.add(0, *_at(degrees), _status(state))
        assert (log.seconds()["robot_0"] > before) is counted, (degrees, state)
    log.add(0, 0.0, 0.0, _status("WALK"))  # nothing read
    log.add(0, *_at(0.0), None)  # no status yet
    assert log.seconds() == {"robot_0": pytest.approx(0.3)}


def test_a_swarm_tick_asks_only_robots_whose_ring_reads_something():
    asked = []
    log = RuleLog(("a", "b", "c"), lambda st: 80.0, dt=0.1)
    log.update(np.array([0.0, 0.2, -0.2]), np.array([0.0, 0.0, 0.0]),
               lambda i: asked.append(i) or _status("WALK"))
    assert asked == [1, 2] and log.seconds() == {"a": 0.0, "b": pytest.approx(0.1), "c": 0.0}


def test_statuses_are_kept_when_they_change_and_read_back_by_time():
    log = StatusLog(("robot_0",))
    log.update([_status("W", 0)])
    log.update([_status("W", 100)])  # unchanged: not published
    log.update([_status("S", 200)])
    assert [s.stamp_ns for s in log.log["robot_0"]] == [0, 200]
    assert log.at("robot_0", 150).state == "W" and log.at("robot_0", 200).state == "S"
    assert log.at("robot_0", -1) is None and log.at("robot_9", 500) is None


def test_events_go_to_the_state_the_robot_was_in_when_it_counted_them():
    log = {"r0": [_status("waiting", 0), _status("searching", 1, oae=2), _status("returning", 2, oae=2),
                  _status("returning", 3, oae=5)],
           "r1": [_status("searching", 0, oae=1)]}
    assert events_by_state(log) == {"returning": 3, "searching": 3}


def test_the_queue_authors_count_on_the_path_within_30_deg_and_never_at_a_dock():
    from depot_manager.admission import DepotAdmission
    from depot_manager.config import QueueConfig
    from depot_manager.geometry import DepotGeometryConfig, make_layout
    from swarm_controllers.queue.authors_count import collision_rule

    scenario = load_scenario("queue_qmt")
    rule = collision_rule(scenario)
    layout = make_layout(QueueConfig.of(scenario).wrapping, DepotGeometryConfig.from_scenario(scenario))
    line, cell = sorted(DepotAdmission(layout).dock_slots())[0]
    assert rule(_status("SEARCHING")) == scenario.sensors.proximity_ring.ahead == 80.0
    assert rule(_status("TO_ENTRY")) == 80.0
    assert rule(_status("QUEUED", line=line, cell=str(cell - 1))) == 30.0
    assert rule(_status("LEAVING", line="", cell="-1")) == 30.0
    assert rule(_status("QUEUED", line=line, cell=str(cell))) is None  # waiting at the dock
    assert rule(_status("QUEUED", line=line, cell="x")) == 30.0  # an unreadable slot is no dock


def test_the_drtm_fields_from_a_status_log():
    from swarm_controllers.drtm import metrics
    from swarm_sim.analysis.metrics import RunTrace

    trace = RunTrace("drtm", 0, ("robot_0",), 1.0, 1.0, 0, "batch")
    assert metrics.oae_by_state(trace) is None and metrics.oae_returning_total(trace) is None
    trace.status_log = {"robot_0": [_status("searching", 0, oae=1), _status("returning", 1, oae=4)]}
    assert metrics.oae_by_state(trace) == {"returning": 3, "searching": 1}
    assert metrics.oae_returning_total(trace) == 3
