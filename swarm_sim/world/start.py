"""Where the robots stand at tick 0 (``robots.start_layout``) [m, world frame].

Only the `depot_random` layout draws from the generator it is given (after the start headings,
so a `grid` run draws exactly what it always did). `swarm_sim.scenario.validation` has already
refused layouts that cannot fit.
"""

from __future__ import annotations

import math

import numpy as np

from swarm_sim.robots import depot_start_room
from swarm_sim.scenario.schema import Scenario, ScenarioError

START_ATTEMPTS = 100_000
"""Candidate positions drawn per robot before a `depot_random` start gives up."""


def start_positions(scenario: Scenario, rng: np.random.Generator) -> np.ndarray:
    """(n, 2) robot centres for the scenario's ``robots.start_layout``."""
    r = scenario.robots
    n = r.count
    cx, cy = scenario.depot.center
    if r.start_layout == "grid":
        side = math.ceil(math.sqrt(n))
        i = np.arange(n)
        return np.column_stack([cx + (i % side - (side - 1) / 2) * r.start_spacing,
                                cy + (i // side - (side - 1) / 2) * r.start_spacing])
    if r.start_layout == "groups":
        return _groups(scenario)
    room = depot_start_room(scenario)
    if r.start_layout == "depot_ring":
        phi = 2 * math.pi * np.arange(n) / n
        return np.column_stack([cx + room * np.cos(phi), cy + room * np.sin(phi)])
    out = np.empty((n, 2))
    for k in range(n):  # random sequential addition, uniform over the disc of centres
        for _ in range(START_ATTEMPTS):
            radius, phi = room * math.sqrt(rng.random()), 2 * math.pi * rng.random()
            x, y = cx + radius * math.cos(phi), cy + radius * math.sin(phi)
            if k == 0 or np.min(np.hypot(out[:k, 0] - x, out[:k, 1] - y)) >= r.start_spacing:
                out[k] = x, y
                break
        else:
            raise ScenarioError(f"robots.count: found no free start for robot {k} in the depot")
    return out


def _groups(scenario: Scenario) -> np.ndarray:
    """`groups` layout: an equal share of the robots per group, each on a grid of
    `start_group_columns` columns centred on its point (the queue paper's authors' experiment
    files: four ``<distribute>`` blocks, ``method="grid"``, ``layout="6, 6, 1"``, ``distances=
    "0.3, 0.3, 0.0"``; robots fill a block row by row, x first, in our reading of ARGoS's grid
    generator)."""
    r = scenario.robots
    groups = len(r.start_groups)
    share, extra = divmod(r.count, groups)
    cols = r.start_group_columns
    out = []
    for g, (gx, gy) in enumerate(r.start_groups):
        k = np.arange(share + (1 if g < extra else 0))
        out.append(np.column_stack([gx + (k % cols - (cols - 1) / 2) * r.start_spacing,
                                    gy + (k // cols - (cols - 1) / 2) * r.start_spacing]))
    return np.concatenate(out)
