"""The docks on the depot boundary (queue_depot_traffic.md sec. III, Fig. 2) and the ``docks``
delivery kind they make (registered in `swarm_controllers.queue.registration`): resources are
delivered only at a dock, after T_unload there.

ROS-free world facts computed from the scenario's ``depot`` disc and its ``docking`` section
(`depot_manager.config.DockingConfig`); the queue geometry
(`depot_manager.geometry`), the CPFA baseline's carriers (through their drop zones) and the
metrics take their docks from here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from depot_manager.config import DockingConfig
from swarm_sim.scenario.schema import DropZoneConfig, Scenario


@dataclass(frozen=True, eq=False)
class Dock:
    """A dock on the depot boundary (queue paper, green square of Fig. 2)."""

    index: int
    angle: float
    """Bearing from the depot centre [rad, world frame, CCW from +x]."""
    position: np.ndarray
    """Point on the depot boundary [m, world frame]."""
    stop: np.ndarray
    """Where an unloading robot's centre waits, one robot radius outside [m, world frame]."""


def polar(center: np.ndarray, r: np.ndarray | float, phi: np.ndarray | float) -> np.ndarray:
    """Points at distance `r` and bearing `phi` [rad] from `center` [m, world frame]."""
    r_a, phi_a = np.broadcast_arrays(np.asarray(r, float), np.asarray(phi, float))
    pts = np.stack([r_a * np.cos(phi_a), r_a * np.sin(phi_a)], axis=-1)
    return pts + center


def docks(center: tuple[float, float], depot_radius: float, robot_diameter: float, count: int,
          stop_radius: float | None = None) -> tuple[Dock, ...]:
    """`count` docks evenly spaced on the depot boundary, CCW from +x (queue paper Fig. 2); a
    robot unloads with its centre one robot radius outside the boundary, or `stop_radius` [m]
    from the centre when given (``docking.dock_distance``)."""
    c = np.asarray(center, dtype=float)
    if stop_radius is None:
        stop_radius = depot_radius + robot_diameter / 2.0
    out = []
    for k in range(count):
        a = 2 * math.pi * k / count
        out.append(Dock(k, a, polar(c, depot_radius, a), polar(c, stop_radius, a)))
    return tuple(out)


def scenario_docks(scenario: Scenario) -> tuple[Dock, ...]:
    """The scenario's docks (``docking.docks`` on the depot disc)."""
    d, k = scenario.depot, DockingConfig.of(scenario)
    return docks(d.center, d.radius, scenario.robots.diameter, k.docks, k.dock_distance)


def dock_zones(scenario: Scenario) -> tuple[DropZoneConfig, ...]:
    """The ``docks`` delivery kind's zones: one per dock stop, of radius ``docking.dock_radius``,
    where a carrier stays ``docking.unload_time`` before its resource is dropped."""
    k = DockingConfig.of(scenario)
    return tuple(
        DropZoneConfig(f"dock_{d.index}", (float(d.stop[0]), float(d.stop[1])), k.dock_radius, k.unload_time, "dock")
        for d in scenario_docks(scenario)
    )


def check_docks(scenario: Scenario) -> None:
    """A scenario delivering at the docks needs its docks side by side around the depot and its
    perimeter around the depot and inside the arena (ValueError naming the key)."""
    d, k = scenario.depot, DockingConfig.of(scenario)
    diameter = scenario.robots.diameter
    stop = d.radius + diameter / 2 if k.dock_distance is None else k.dock_distance
    if k.docks > 1 and 2 * stop * math.sin(math.pi / k.docks) < diameter:
        raise ValueError(f"docking.docks: {k.docks} docks do not fit side by side {stop} m from the depot centre")
    check_perimeter(scenario)


def check_perimeter(scenario: Scenario) -> None:
    """The perimeter round the depot and inside the arena (ValueError naming the key)."""
    d, k, half = scenario.depot, DockingConfig.of(scenario), scenario.arena.size / 2
    if k.perimeter_radius <= d.radius:
        raise ValueError("docking.perimeter_radius: must exceed depot.radius")
    if not (abs(d.center[0]) + k.perimeter_radius <= half and abs(d.center[1]) + k.perimeter_radius <= half):
        raise ValueError(f"docking.perimeter_radius: a perimeter of {k.perimeter_radius} m does not fit in the arena")
