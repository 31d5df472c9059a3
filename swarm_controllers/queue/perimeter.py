"""The queue paper's perimeter measures (sec. III and sec. VII, metric 3): when carriers cross
into the red circle around the depot, the drop-off time from that entry to the dock, the time
delay until they leave again, and deliveries that missed every dock.

Registered as a probe of every foraging run (`swarm_controllers.queue.registration`), the CPFA
baseline's included, since the paper reports these for every strategy; the batch runner feeds
`PerimeterLog` the odometry positions as it steps them, the bag replay as they were recorded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from depot_manager.config import DockingConfig
from swarm_msgs_py.types import NS_PER_S, DropEvent, RobotId
from swarm_sim.registry import delivery_zones
from swarm_sim.scenario import Scenario
from swarm_sim.sites import drop_zones

PROBE = "perimeter"
"""The probe's name: its crossings are ``RunTrace.probes["perimeter"]``."""


@dataclass
class Crossings:
    """Per robot, the sim times [s] it entered and left the perimeter disc."""

    entries: dict[RobotId, list[float]] = field(default_factory=dict)
    exits: dict[RobotId, list[float]] = field(default_factory=dict)


class PerimeterLog:
    """When each robot crossed into the depot perimeter (the drop-off time runs from entering
    the perimeter to the drop)."""

    def __init__(self, scenario: Scenario, robots: tuple[RobotId, ...]) -> None:
        self.robots = robots
        self._center = np.asarray(scenario.depot.center, dtype=float)
        self._r2 = DockingConfig.of(scenario).perimeter_radius ** 2
        self._inside = np.zeros(len(robots), dtype=bool)
        self._crossings = Crossings({r: [] for r in robots}, {r: [] for r in robots})

    def update(self, t: float, xy: np.ndarray) -> None:
        """`xy`: (robots, 2) positions at time `t` [m, world frame], in `robots` order."""
        d = np.asarray(xy, dtype=float) - self._center
        inside = np.einsum("ij,ij->i", d, d) < self._r2
        if np.array_equal(inside, self._inside):  # nobody crossed (almost every tick)
            return
        for i in np.flatnonzero(inside & ~self._inside):
            self._crossings.entries[self.robots[i]].append(t)
        for i in np.flatnonzero(~inside & self._inside):
            self._crossings.exits[self.robots[i]].append(t)
        self._inside = inside

    def result(self) -> Crossings:
        return self._crossings


def _crossings(trace: Any) -> Crossings:
    return trace.probes.get(PROBE) or Crossings()


def dock_arrival_s(trace: Any, drop: DropEvent) -> float:
    """When the carrier reached the zone it dropped in [s]: the drop's time less the zone's
    dwell (T_unload at a dock) rounded up to whole ticks, as the foraging task drops on the
    first tick the carrier has been inside for the dwell (`swarm_sim.world.tasks.foraging`)."""
    t = drop.stamp_ns / NS_PER_S
    if trace.config is None:
        return t
    dwell = {z.name: z.dwell for z in drop_zones(trace.config)}.get(drop.zone, 0.0)
    dt = trace.config.sim.dt
    return t - math.ceil(dwell / dt - 1e-9) * dt if dwell > 0 else t


def dropoff_times(trace: Any) -> list[float]:
    """Per delivery, the time from the carrier's last entry into the perimeter to its arrival at
    the dock, before T_unload (queue paper sec. VII, metric 3: "entering the red circular region"
    to "dropping off a resource at a designated dock"; the authors' controllers stop this clock
    on reaching the nest, before their ``Wait(5)``: ``CPFA_controller::FollowingEntryPath`` in
    Tameem786/Collision_Free_CPFA); deliveries without a recorded entry are skipped [s]."""
    out = []
    for d in trace.drops:
        t = d.stamp_ns / NS_PER_S
        entered = [e for e in _crossings(trace).entries.get(d.robot, ()) if e <= t]
        if entered:
            out.append(dock_arrival_s(trace, d) - entered[-1])
    return out


def perimeter_delays(trace: Any) -> list[float]:
    """Per delivery, the queue paper's *time delay* (sec. III): from the carrier's last entry
    into the perimeter before the drop to its first exit after it [s]; deliveries whose robot
    had not left again by the end of the run are skipped."""
    out = []
    for d in trace.drops:
        t = d.stamp_ns / NS_PER_S
        entered = [e for e in _crossings(trace).entries.get(d.robot, ()) if e <= t]
        left = [e for e in _crossings(trace).exits.get(d.robot, ()) if e >= t]
        if entered and left:
            out.append(left[0] - entered[-1])
    return out


def deliveries_outside_docks(trace: Any) -> int | None:
    """Drops farther than the dock radius from every dock stop (None without a scenario)."""
    if trace.config is None:
        return None
    stops = np.array([z.center for z in delivery_zones(trace.config, "docks")])
    radius = DockingConfig.of(trace.config).dock_radius + 1e-6
    return sum(
        1 for d in trace.drops if np.min(np.hypot(stops[:, 0] - d.x, stops[:, 1] - d.y)) > radius
    )




def perimeter_metrics(trace: Any) -> dict[str, Any]:
    """The run's JSON fields: drop-off time (mean and per delivery), time delay, deliveries
    outside the docks."""
    dropoff = dropoff_times(trace)
    delay = perimeter_delays(trace)
    return {
        "dropoff_time_mean_s": round(float(np.mean(dropoff)), 6) if dropoff else None,
        "dropoff_times_s": [round(v, 3) for v in dropoff],
        "perimeter_delay_mean_s": round(float(np.mean(delay)), 6) if delay else None,
        "deliveries_outside_docks": deliveries_outside_docks(trace),
    }
