"""The queue paper's pictures of a run: its queue layout (Figs. 3, 4, 6, 7: the depot manager's
geometry, `depot_manager.draw`) under the robots' recorded trajectories."""

from __future__ import annotations

from depot_manager.config import QueueConfig
from depot_manager.draw import draw_on
from depot_manager.geometry import DepotGeometryConfig, make_layout
from swarm_sim.scenario import Scenario


def layout(ax, scenario: Scenario) -> None:
    """The scenario's queue layout, lighter, each part labelled (`Algorithm.backdrop`)."""
    draw_on(ax, make_layout(QueueConfig.of(scenario).wrapping, DepotGeometryConfig.from_scenario(scenario)),
            detail=False)
