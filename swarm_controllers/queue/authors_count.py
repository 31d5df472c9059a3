"""Collision time as the queue paper's authors count it: by the state the robot is in.

Their controller (Tameem786/Collision_Free_CPFA, branch ``main``, their Q_SE;
``source/CPFA/CPFA_controller.cpp``, ``CPFA_controller::CollisionDetection``) counts a tick of
collision time

- within ``GoStraightAngleRangeInDegreesInRegion`` = +-30 deg of the heading while the robot
  follows the queue path or exits (``GetStatus()`` FOLLOWING_ENTRY_PATH or EXITING; it then
  stops instead of avoiding);
- within the ``BaseController``'s ``GoStraightAngleRangeInDegrees`` (+-80 deg;
  ``sensors.proximity_ring.ahead``) in every other state;
- never while it waits at its dock (``Wait(5)``: ``BaseController::Move`` returns before its
  collision detection).

Our robots report the phase (`swarm_controllers.queue.behaviour.Phase`): QUEUED (slot to slot
along the entry line, the inner queue and the exit line) is following the path, LEAVING (out of
the perimeter from the last exit slot) is exiting, and QUEUED at a dock's slot (the status's
``line`` and ``cell``) is waiting at the dock. The ring's reading is the world's
(`swarm_sim.world.proximity`); the count is `swarm_sim.analysis.state_rules.RuleLog`'s, from
batch runs and bags alike.
"""

from __future__ import annotations

from typing import Any

from depot_manager.admission import DepotAdmission
from depot_manager.config import QueueConfig
from depot_manager.geometry import DepotGeometryConfig, make_layout
from swarm_controllers.queue.behaviour import PATH_CONE, Phase
from swarm_msgs_py.types import BehaviourStatus
from swarm_sim.scenario import Scenario

FOLLOWING = frozenset({Phase.QUEUED.name, Phase.LEAVING.name})
"""The states the authors call FOLLOWING_ENTRY_PATH and EXITING."""


def collision_rule(scenario: Scenario):
    """The authors' rule for `swarm_sim.registry.Algorithm.collision_rule`."""
    wide = scenario.sensors.proximity_ring.ahead
    queue = QueueConfig.of(scenario)
    docks = DepotAdmission(make_layout(queue.wrapping, DepotGeometryConfig.from_scenario(scenario))).dock_slots()

    def rule(status: BehaviourStatus) -> float | None:
        if status.state not in FOLLOWING:
            return wide
        extra = dict(status.extra)
        try:
            slot = (extra.get("line", ""), int(extra.get("cell", "-1")))
        except ValueError:  # a status from a bag is untrusted: an unreadable slot is not a dock
            return PATH_CONE
        return None if slot in docks else PATH_CONE

    rule.widest = max(wide, PATH_CONE)
    return rule


def authors_collision_time_per_robot_s(trace: Any) -> float | None:
    """Mean over robots of the collision time by the authors' rule [s]."""
    by_robot = trace.rule_collision_s
    if not by_robot:
        return None
    return round(sum(by_robot.values()) / len(by_robot), 6)


def authors_collision_time_total_min(trace: Any) -> float | None:
    """The same summed over robots [min] (what their ``PostExperiment`` prints, doubled)."""
    by_robot = trace.rule_collision_s
    return round(sum(by_robot.values()) / 60.0, 6) if by_robot else None
