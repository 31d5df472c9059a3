"""The dummy's world task: one beacon, placed at random; every robot senses its range and bearing."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np


class BeaconSense(NamedTuple):
    beacon: tuple[float, float]
    """(range [m], bearing [rad, robot frame]) of the beacon."""


class BeaconTask:
    def __init__(self, world, seeds) -> None:
        self._world = world
        rng = np.random.default_rng(seeds[0])
        half = world.scenario.arena.size / 2 - 0.5
        self.beacon = rng.uniform(-half, half, size=2)

    def post_step(self, stamp_ns: int) -> None:
        pass

    def sense(self) -> list[BeaconSense]:
        pos, yaw = self._world.positions, self._world.headings
        d = self.beacon - pos
        ranges = np.hypot(d[:, 0], d[:, 1]).tolist()
        bearings = (np.arctan2(d[:, 1], d[:, 0]) - yaw).tolist()
        return [BeaconSense((r, math.remainder(b, 2 * math.pi))) for r, b in zip(ranges, bearings)]

    def moved(self) -> None:
        pass

    def drain_events(self) -> list:
        return []

    def placed(self) -> Mapping[str, np.ndarray]:
        return {"beacon": self.beacon[None, :].copy()}

    def progress(self) -> str:
        return f"beacon=({self.beacon[0]:.1f}, {self.beacon[1]:.1f})"
