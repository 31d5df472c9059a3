"""The spiral paper's pictures of a run: MDBSA's regions under the trajectories (Figs. 1, 4, 5)
and the foraging rate per minute (Figs. 7 and 9) as a summary panel."""

from __future__ import annotations

from typing import Any

from swarm_controllers.spiral.geometry import region_side
from swarm_controllers.spiral.metrics import resources_per_robot_per_min
from swarm_controllers.spiral.regions import RegionConfig, region_centers
from swarm_sim.scenario import Scenario


def regions(ax, scenario: Scenario) -> None:
    """The MDBSA regions' squares (`Algorithm.backdrop`)."""
    count, size = RegionConfig.of(scenario).count, scenario.arena.size
    half = region_side(count, size) / 2
    for k, (x, y) in enumerate(region_centers(count, size)):
        ax.plot([x - half, x + half, x + half, x - half, x - half], [y - half, y - half, y + half, y + half, y - half],
                color="tab:olive", lw=0.8, ls="--", zorder=1, label=f"regions ({count})" if k == 0 else None)


def rate_per_minute(trace: Any) -> list[tuple[float, float]]:
    """(start of the minute [s], resources per robot delivered in it): the per-minute series
    as a step line, each value over its own minute."""
    return [(t - 60.0, v) for t, v in resources_per_robot_per_min(trace)]
