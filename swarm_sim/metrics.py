"""A run's trace and the metric functions over it.

A `RunTrace` is built either by the batch runner (straight from the world core) or by
`swarm_sim.analysis.load_run` (from a recorded bag). Every metric is a pure function of the
trace, so a metric is defined once and means the same thing for both kinds of run.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from swarm_sim.types import NS_PER_S, BehaviourStatus, DropEvent, PickupEvent, RobotId, RobotStats


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


def resources_delivered(trace: RunTrace) -> int:
    return len(trace.drops)


def delivered_over_time(trace: RunTrace, bin_s: float = 10.0) -> tuple[np.ndarray, np.ndarray]:
    """Cumulative deliveries at the end of each `bin_s` bin: (times [s], counts)."""
    edges = np.arange(0.0, trace.sim_seconds + bin_s, bin_s)
    times = np.array([d.stamp_ns / NS_PER_S for d in trace.drops])
    counts = np.searchsorted(np.sort(times), edges, side="right")
    return edges, counts


def collision_time_by_robot(trace: RunTrace) -> dict[RobotId, float]:
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


def _mean(values: dict[RobotId, float] | dict[RobotId, int]) -> float:
    return float(np.mean(list(values.values()))) if values else 0.0


def summarize(trace: RunTrace) -> dict[str, Any]:
    """The JSON result of one run (schema documented in the README; fields are only ever added)."""
    collision = collision_time_by_robot(trace)
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
        "oae_per_robot": round(_mean(oae), 6),
        "trips_per_robot": round(_mean(trips), 6),
        "collision_time_s_by_robot": {r: round(v, 6) for r, v in collision.items()},
        "oae_by_robot": oae,
        "trips_by_robot": trips,
        "stale_ticks": sum(s.stale_ticks for s in trace.stats.values()),
        "clamped_commands": sum(s.clamped_commands for s in trace.stats.values()),
    }
