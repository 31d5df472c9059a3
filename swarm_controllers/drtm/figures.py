"""The DRTM paper's panels of a run's summary figure (Figs. 5-6): the nest's food F(t) with the
desired level F_d the paper draws, and the robots foraging, N_r - N_W."""

from __future__ import annotations

from typing import Any

from swarm_controllers.drtm.config import NestConfig


def desired_food(trace: Any) -> list[tuple[float, str]]:
    """F_d [tokens], the reference line of the food panel."""
    return [(NestConfig.of(trace.config).desired_food, "F_d (desired)")] if trace.config is not None else []


def foraging_robots(trace: Any) -> list[tuple[float, int]]:
    """(t [s], N_r - N_W): the robots out of the nest as the nest's ledger counts them."""
    robots = len(trace.robots)
    return [(t, robots - int(waiting)) for t, waiting in trace.series.get("nest_waiting", [])]
