"""Sites: where the scenario's world facts put things (docks, region centres, drop zones).

The lowest layer: it reads the scenario and imports no algorithm. The depot manager's queue
geometry, the spiral planners, the world's foraging task and the metrics all take their docks,
region centres and drop zones from here, so each is computed in one place.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from swarm_sim.scenario import DropZoneConfig, Scenario


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
    from the centre when given (``depot.dock_distance``)."""
    c = np.asarray(center, dtype=float)
    if stop_radius is None:
        stop_radius = depot_radius + robot_diameter / 2.0
    out = []
    for k in range(count):
        a = 2 * math.pi * k / count
        out.append(Dock(k, a, polar(c, depot_radius, a), polar(c, stop_radius, a)))
    return tuple(out)


def scenario_docks(scenario: Scenario) -> tuple[Dock, ...]:
    """The scenario's docks (``depot.docks`` on the depot disc)."""
    d = scenario.depot
    return docks(d.center, d.radius, scenario.robots.diameter, d.docks, d.dock_distance)


def region_centers(n_regions: int, arena_size: float) -> np.ndarray:
    """(N_R, 2) centers [m, world frame] of the N_R = 4^k equal square regions, eq. (3) of the
    MDBSA paper.

    (x_i, y_j) = (L/2 (1 - (2i+1)/sqrt(N_R)), L/2 (1 - (2j+1)/sqrt(N_R))), i the row, j the column,
    arena centered at (0, 0). Row index = region_id // sqrt(N_R), column = region_id % sqrt(N_R);
    region 0 is therefore the (+x, +y) corner region. The paper assigns regions "by robot id"
    without fixing an order; this row-major order of eq. (3)'s (i, j) is our choice.
    """
    n = int(round(np.sqrt(n_regions)))
    k = int(round(np.log(n_regions) / np.log(4))) if n_regions >= 1 else -1
    if n_regions < 1 or 4**k != n_regions:
        raise ValueError(f"the number of regions must be 4^k, got {n_regions}")
    idx = np.arange(n)
    coord = arena_size / 2.0 * (1.0 - (2 * idx + 1) / n)
    ii, jj = np.meshgrid(idx, idx, indexing="ij")
    return np.stack([coord[ii.ravel()], coord[jj.ravel()]], axis=1)


def drop_zones(scenario: Scenario) -> tuple[DropZoneConfig, ...]:
    """Every zone the world drops resources in: the ones ``depot.delivery`` implies (the depot
    disc, the docks with their unload dwell, or the region centres) plus ``drop_zones``."""
    from swarm_sim.scenario import DropZoneConfig

    d = scenario.depot
    if d.delivery == "docks":
        implied = tuple(
            DropZoneConfig(f"dock_{k.index}", (float(k.stop[0]), float(k.stop[1])),
                           d.dock_radius, d.unload_time, "dock")
            for k in scenario_docks(scenario)
        )
    elif d.delivery == "region_centers":
        r = scenario.regions
        implied = tuple(
            DropZoneConfig(f"region_{i}", (float(x), float(y)), r.center_radius, 0.0, "region_center")
            for i, (x, y) in enumerate(region_centers(r.count, scenario.arena.size))
        )
    else:
        implied = (DropZoneConfig("depot", d.center, d.radius, 0.0, "depot"),)
    return (*implied, *scenario.drop_zones)
