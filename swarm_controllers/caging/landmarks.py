"""The caging paper's landmarks L and their neighbourhoods eta (Alg. 2, lines 1-6).

A world fact computed from the scenario (``transport.landmarks``), the same for the world task
(which draws them) and every robot (which searches along them and names them in messages).
Alg. 2 says "generate randomly lambda_i in the arena"; the paper's results (sec. 5) speak of
discretisation steps of 0.5 and 1 m and report 255 and 72 landmarks, so landmarks are the nodes
of a square grid of that step. eta(lambda) is the grid's 8-neighbourhood: the paper's planned
path lengths (Table 2: 3.9142 = 5 x 0.5 + 2 x 0.5 sqrt 2, ...) contain diagonal steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np

from swarm_controllers.caging.world_config import LandmarkConfig, TransportConfig
from swarm_sim.scenario import Scenario


@dataclass(frozen=True, eq=False)
class Landmarks:
    points: np.ndarray
    """(Lambda, 2) landmark positions [m, world frame], row by row from the bottom left."""
    neighbours: tuple[tuple[int, ...], ...]
    """eta(lambda_i): the indices of the up to eight grid neighbours of landmark i."""
    step: float
    """Grid step [m]."""
    columns: int
    """Landmarks along x: landmark i sits in column i % columns, row i // columns."""

    def __len__(self) -> int:
        return len(self.points)

    def position(self, i: int) -> tuple[float, float]:
        x, y = self.points[i]
        return float(x), float(y)

    def cell(self, i: int) -> tuple[int, int]:
        """(column, row) of landmark i."""
        return i % self.columns, i // self.columns

    def index(self, column: int, row: int) -> int:
        return row * self.columns + column


def grid_counts(config: LandmarkConfig) -> tuple[int, int]:
    """Landmarks along x and along y: as many steps as fit in the extent, plus one."""
    return tuple(int(math.floor(e / config.step + 1e-9)) + 1 for e in config.extent)  # type: ignore[return-value]


@cache
def _grid(step: float, extent: tuple[float, float]) -> Landmarks:
    config = LandmarkConfig(step=step, extent=extent)
    nx, ny = grid_counts(config)
    xs = (np.arange(nx) - (nx - 1) / 2) * step
    ys = (np.arange(ny) - (ny - 1) / 2) * step
    points = np.array([(x, y) for y in ys for x in xs], dtype=float)
    points.flags.writeable = False
    neighbours = []
    for iy in range(ny):
        for ix in range(nx):
            neighbours.append(tuple(
                jy * nx + jx
                for jy in range(max(iy - 1, 0), min(iy + 2, ny))
                for jx in range(max(ix - 1, 0), min(ix + 2, nx))
                if (jx, jy) != (ix, iy)
            ))
    return Landmarks(points, tuple(neighbours), step, nx)


def landmarks(scenario: Scenario) -> Landmarks:
    """The scenario's landmark grid (built once per step and extent)."""
    c = TransportConfig.of(scenario).landmarks
    return _grid(c.step, tuple(c.extent))
