"""A run's trace and the metric functions over it.

A `RunTrace` is built either by the batch runner (straight from the world core) or by
`swarm_sim.analysis.load_run` (from a recorded bag). Every metric is a pure function of the
trace, so a metric is defined once and means the same thing for both kinds of run.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from swarm_msgs_py.types import NS_PER_S, BehaviourStatus, DropEvent, NodeDownEvent, PickupEvent, RobotId, RobotStats
from swarm_sim import registry
from swarm_sim.scenario import Scenario


@dataclass
class RunTrace:
    scenario: str
    seed: int
    robots: tuple[RobotId, ...]
    sim_seconds: float
    """Sim time the run covered [s]."""
    wall_seconds: float
    total_resources: int
    mode: str
    """`batch`, `lockstep` or `realtime`."""
    pickups: list[PickupEvent] = field(default_factory=list)
    drops: list[DropEvent] = field(default_factory=list)
    stats: dict[RobotId, RobotStats] = field(default_factory=dict)
    """World counters at the end of the run."""
    status: dict[RobotId, BehaviourStatus] = field(default_factory=dict)
    """Each behaviour's last published status."""
    config: Scenario | None = None
    """The scenario the run used (world facts the metrics need: its world sections)."""
    probes: dict[str, Any] = field(default_factory=dict)
    """What each probe of the run's task observed (`swarm_sim.registry.Probe`), by name."""
    server_stale: dict[str, int] = field(default_factory=dict)
    """Lockstep ticks each server (by channel) did not acknowledge in time (graph runs)."""
    commands: dict[str, dict] = field(default_factory=dict)
    """Graph runs: per robot, what the network did to its commands (`swarm_sim.nodes.command_watch`)."""
    malformed: dict[str, int] = field(default_factory=dict)
    """Recorded messages that did not decode, by topic (skipped by the analysis)."""
    rejected: dict[str, dict[tuple[str, str], int]] = field(default_factory=dict)
    """Per node, the messages it dropped by (topic or message class, reason): its last
    ``/diagnostics`` counts (`swarm_sim.inbound`)."""
    down: list[NodeDownEvent] = field(default_factory=list)
    """Nodes the world declared dead, in order."""
    ended: str = "complete"
    """How the run ended: ``complete``, ``interrupted``, ``server <channel> died``, or ``cut off``
    (the world node died: the bag ends where its last flushed data does)."""
    series: dict[str, list[tuple[float, Any]]] = field(default_factory=dict)
    """Servers' time series by name, (t [s], value) whenever it changed: e.g. the depot
    manager's ``queue_lengths`` (robots queued on each entry line); and the world task's state,
    (t [s], value) every tick (the transport task's ``object`` position)."""
    messages: list[Any] = field(default_factory=list)
    """The robots' peer messages, in delivery order, for algorithms that ask
    (`swarm_sim.registry.Algorithm.trace_peers`; the caging paper's types 0-4)."""
    lost: list[str] = field(default_factory=list)
    """What the bag lost, one line per damaged file (`swarm_sim.recording.BagInfo.lost`); a run
    whose bag lost data is never ``complete``."""
    foreign: list[str] = field(default_factory=list)
    """Publishers seen on the run's topics that were none of its nodes (`swarm_sim.nodes.taint`):
    the run is tainted, its results may hold what they sent."""
    rule_collision_s: dict[RobotId, float] | None = None
    """Per robot, collision time [s] by the algorithm's state-dependent rule
    (`swarm_sim.registry.Algorithm.collision_rule`; None without one)."""
    status_log: dict[RobotId, list[BehaviourStatus]] = field(default_factory=dict)
    """Per robot, every status it published, in order (`swarm_sim.registry.Algorithm.trace_status`)."""


def resources_delivered(trace: RunTrace) -> int:
    return len(trace.drops)


def delivered_series(trace: RunTrace) -> list[tuple[float, int]]:
    """(t [s], deliveries so far) from 0 and at every drop: the summary figure's step line."""
    times = sorted(d.stamp_ns / NS_PER_S for d in trace.drops)
    return [(0.0, 0), *((t, k + 1) for k, t in enumerate(times))]


def collision_time_by_robot(trace: RunTrace) -> dict[RobotId, float]:
    """The papers' collision time [s]: time each robot's proximity ring saw something ahead,
    i.e. spent in collision avoidance (`swarm_sim.world.proximity`)."""
    return {r: trace.stats[r].avoidance_time_s if r in trace.stats else 0.0 for r in trace.robots}


def contact_time_by_robot(trace: RunTrace) -> dict[RobotId, float]:
    """Time each robot's body touched another robot's [s] (pybullet contacts)."""
    return {r: trace.stats[r].collision_time_s if r in trace.stats else 0.0 for r in trace.robots}


def oae_by_robot(trace: RunTrace) -> dict[RobotId, int]:
    return {
        r: trace.status[r].obstacle_avoidance_events if r in trace.status else 0
        for r in trace.robots
    }


def trips_by_robot(trace: RunTrace) -> dict[RobotId, int]:
    """Completed foraging trips: deliveries per robot."""
    trips = {r: 0 for r in trace.robots}
    for d in trace.drops:
        trips[d.robot] = trips.get(d.robot, 0) + 1
    return trips


def rejected_messages(trace: RunTrace) -> dict[str, dict[str, int]]:
    """Messages dropped by every node, summed: {topic or message class: {reason: count}}."""
    out: dict[str, dict[str, int]] = {}
    for counts in trace.rejected.values():
        for (where, reason), n in counts.items():
            by_reason = out.setdefault(where, {})
            by_reason[reason] = by_reason.get(reason, 0) + n
    return {w: dict(sorted(r.items())) for w, r in sorted(out.items())}


def _mean(values: dict[RobotId, float] | dict[RobotId, int]) -> float:
    return float(np.mean(list(values.values()))) if values else 0.0


def summarize(trace: RunTrace) -> dict[str, Any]:
    """The JSON result of one run: the core's fields, then its task's, its probes' and its
    algorithm's (`_registered_metrics`); a field another paper reports is absent, not None
    (schema: docs/command_line.md)."""
    collision = collision_time_by_robot(trace)
    contact = contact_time_by_robot(trace)
    oae = oae_by_robot(trace)
    trips = trips_by_robot(trace)
    return {
        "scenario": trace.scenario,
        "seed": trace.seed,
        "robots": len(trace.robots),
        "mode": trace.mode,
        "sim_seconds": round(trace.sim_seconds, 6),
        "wall_seconds": round(trace.wall_seconds, 3),
        "real_time_factor": round(trace.sim_seconds / trace.wall_seconds, 2) if trace.wall_seconds else None,
        "total_resources": trace.total_resources,
        "resources_delivered": resources_delivered(trace),
        "collision_time_per_robot_s": round(_mean(collision), 6),
        "collision_time_total_min": round(sum(collision.values()) / 60.0, 6),
        "contact_time_per_robot_s": round(_mean(contact), 6),
        "oae_per_robot": round(_mean(oae), 6),
        "trips_per_robot": round(_mean(trips), 6),
        "collision_time_s_by_robot": {r: round(v, 6) for r, v in collision.items()},
        "contact_time_s_by_robot": {r: round(v, 6) for r, v in contact.items()},
        "oae_by_robot": oae,
        "trips_by_robot": trips,
        "stale_ticks": sum(s.stale_ticks for s in trace.stats.values()),
        "clamped_commands": sum(s.clamped_commands for s in trace.stats.values()),
        "server_stale_ticks": sum(trace.server_stale.values()),
        "commands_by_robot": trace.commands,
        "malformed_messages": sum(trace.malformed.values()),
        "rejected_messages": rejected_messages(trace),
        "dead_nodes": [e.node for e in trace.down],
        "run_ended": trace.ended,
        "bag_lost": list(trace.lost),
        "foreign_publishers": list(trace.foreign),
        **_registered_metrics(trace),
    }


def foraging_metrics(trace: RunTrace) -> dict[str, Any]:
    """The foraging task's per-run metrics: the share of the resources collected, resources per
    robot and the foraging rate."""
    delivered = resources_delivered(trace)
    minutes = trace.sim_seconds / 60.0
    return {
        "resources_collected_pct": round(100.0 * delivered / trace.total_resources, 6)
        if trace.total_resources else 0.0,
        "resources_per_robot": round(delivered / len(trace.robots), 6) if trace.robots else 0.0,
        "foraging_rate_per_min": round(delivered / minutes, 6) if minutes > 0 else 0.0,
    }


def _registered_metrics(trace: RunTrace) -> dict[str, Any]:
    """The world task's metrics, those of the probes the run asked for, then its algorithm's own:
    a row carries the fields of what ran and nothing of the other papers'."""
    ours = registry.of(trace.config) if trace.config is not None else None
    task = registry.task(ours.task if ours is not None else "foraging")
    out = registry.resolve(task.metrics)(trace) if task.metrics else {}
    for probe in registry.probes(trace.config) if trace.config is not None else ():
        out.update(registry.resolve(probe.metrics)(trace))
    for m in ours.metrics if ours is not None else ():
        if m.name not in out:
            out[m.name] = registry.resolve(m.function)(trace)
    return out
