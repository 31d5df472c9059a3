"""The MDBSA regions (mdbsa_spiral_search.md eq. (3)): the scenario's ``regions`` section, the
grid of region centres, and the ``region_centers`` delivery kind they make (MDBSA-D: each
region's resources are delivered at its centre), both declared in
`swarm_controllers.spiral.registration`.

World facts, ROS-free: the planners (`swarm_controllers.spiral.geometry` re-exports
`region_centers`), the center, the robots and the world's drop zones take the regions from here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np

from swarm_sim.scenario.schema import DropZoneConfig, Scenario, WorldSection


@dataclass(frozen=True)
class RegionConfig(WorldSection):
    """The arena split into N_R = 4^k equal square regions (MDBSA paper eq. (3)); each region's
    centre is a drop zone when ``depot.delivery`` is `region_centers`."""

    count: int = 16
    """N_R, a power of 4 (the MDBSA paper's experiment 1 default is 16)."""
    center_radius: float = 0.25
    """Radius of each region centre's drop zone [m] (MDBSA-D), within which an idle MDBSA robot
    stops (the authors' ``RegionRadius``)."""
    order: Literal["row_major", "nearest_first"] = "row_major"
    """The order in which the center hands regions out (robot k's first region is the k-th; a
    later walk goes to the longest unwalked region, ties to the earlier in this order):
    ``row_major``, eq. (3)'s (i, j) in row-major order, region 0 the (+x, +y) corner; or
    ``nearest_first``, by distance of the region's centre from the depot's (the nest, the arena's
    centre in the authors' set-up), ties in row-major order, as the MDBSA authors'
    ``DSA_loop_functions::calRegions`` sorts them (MARSLab-UTRGV/Adaptive-Multiple-Distributed-
    Spiral-Search-Algorithm, luki-dev c890aa1, ``Centralized/source/DSA/DSA_loop_functions.cpp``:
    ``sort`` of (squared distance, row-major index) pairs). The paper says only "based on its ID"."""

    SECTION: ClassVar[str] = "regions"

    def check(self) -> None:
        k = round(math.log(self.count, 4)) if self.count >= 1 else -1
        if not (k >= 0 and 4**k == self.count):
            raise ValueError(f"regions.count: {self.count} is not a power of 4")
        if not self.center_radius > 0:
            raise ValueError("regions.center_radius: must be positive")


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


def region_order(scenario: Scenario) -> tuple[int, ...]:
    """The region ids in the order the center hands them out (`RegionConfig.order`)."""
    r = RegionConfig.of(scenario)
    ids = tuple(range(r.count))
    if r.order == "row_major":
        return ids
    centers = region_centers(r.count, scenario.arena.size)
    cx, cy = scenario.depot.center
    # squared distances, as the authors sort them: equal rings compare equal, ties by id
    return tuple(sorted(ids, key=lambda k: ((centers[k, 0] - cx) ** 2 + (centers[k, 1] - cy) ** 2, k)))


def region_center_zones(scenario: Scenario) -> tuple[DropZoneConfig, ...]:
    """The ``region_centers`` delivery kind's zones: a disc of ``regions.center_radius`` at every
    region's centre, no dwell.

    Resources may lie inside them (the kind's record says so): the authors keep food off the
    nest only (``DSA_loop_functions::IsOutOfBounds`` checks ``IsCollidingWithNest``, MARSLab-UTRGV/
    Adaptive-Multiple-Distributed-Spiral-Search-Algorithm, branch luki-dev, Distributed/source/
    DSA/DSA_loop_functions.cpp), so DDSA, MDBSA-C and MDBSA-D get the same layout for a seed,
    and a resource lying in a region centre is delivered as soon as it is picked up, as their
    ``IsInTheRegion`` does. (Keeping 64 such discs clear also left no room for the larger piles.)
    """
    r = RegionConfig.of(scenario)
    return tuple(
        DropZoneConfig(f"region_{i}", (float(x), float(y)), r.center_radius, 0.0, "region_center")
        for i, (x, y) in enumerate(region_centers(r.count, scenario.arena.size))
    )
