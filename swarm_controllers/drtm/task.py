"""The nest task of the DRTM paper (drtm_task_allocation.md Secs. 2.3, 3.1): food, nest, light.

It is the foraging task (`swarm_sim.world.tasks.foraging`) with a light: the food tokens are the
scenario's resources (``distribution: uniform``, ``respawn: true``: "whenever a robot delivers a
food token back to the nest, a new food token is generated randomly in the foraging arena", so
the arena always holds N_f), the nest is the depot disc (a carried token is delivered the tick
its carrier's centre is inside it), and "a light source ... in the middle" stands at the depot
centre. What a robot senses besides `ForagingSense` is the light: its vector in the robot frame,
pointing at the light, of length the intensity, zero when the light is farther than
``sensors.light_range`` ("walk randomly until the light is detected"). The paper gives no sensor
model; the intensity falls off linearly, 1 at the light and 0 at the range (a robot only uses
the direction and whether it sees the light at all).

The nest's energy ledger is not here: it needs the robots' states and obstacle-avoidance events,
which only the robots know, so the nest server (`swarm_controllers.drtm.nest`) keeps it from their
reports; this task owns the world's facts only (tokens, deliveries, the light).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from swarm_sim.world.tasks.foraging import ForagingTask

if TYPE_CHECKING:
    from swarm_sim.world.core import World


class NestSense(NamedTuple):
    """`ForagingSense` plus the light."""

    resources: tuple[tuple[float, float], ...]
    """Food tokens within the detection radius [m, world frame], nearest first."""
    carrying: bool
    """True while the gripper holds a token."""
    light: tuple[float, float]
    """(x, y) [robot frame, x forward]: points at the light, length = intensity in (0, 1];
    (0.0, 0.0) when the light is not detected."""


_new_sense = functools.partial(tuple.__new__, NestSense)


class NestTask(ForagingTask):
    """Food tokens, deliveries into the nest and the light at the nest centre."""

    def __init__(self, world: World, seeds: tuple[np.random.SeedSequence, np.random.SeedSequence]) -> None:
        super().__init__(world, seeds)
        s = world.scenario
        self.light = np.array(s.depot.center, dtype=float)
        """The light's position [m, world frame]."""
        self._light_range = s.sensors.light_range

    def light_vectors(self) -> np.ndarray:
        """(n, 2) each robot's light vector [robot frame] (see `NestSense.light`)."""
        w = self._world
        d = self.light - w.positions
        distance = np.hypot(d[:, 0], d[:, 1])
        intensity = np.clip(1.0 - distance / self._light_range, 0.0, 1.0)
        bearing = np.arctan2(d[:, 1], d[:, 0]) - w.headings
        return np.column_stack([intensity * np.cos(bearing), intensity * np.sin(bearing)])

    def sense(self) -> list[NestSense]:
        detected, carrying = self.sense_fields()
        light = list(map(tuple, self.light_vectors().tolist()))
        return list(map(_new_sense, zip(detected, carrying, light)))

    def placed(self) -> Mapping[str, np.ndarray]:
        return {**super().placed(), "light": self.light[None, :].copy()}
