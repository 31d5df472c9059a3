"""The proximity ring as a robot's controller reads it: from its own scan, one robot at a time.

The same sensor model as the world's (`swarm_sim.world.proximity.ProximityRing`, which counts
collision time for the whole swarm at once): the scan's rays are the ring's sensors, a ray that
hits something within ``sensors.proximity_ring.range`` of the body reads the robot model's
`ring_reading` of the distance beyond the body, else 0; ARGoS controllers sum the readings as
vectors (value, sensor angle).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from swarm_controllers.avoidance import ray_angles
from swarm_sim.robots import model_of
from swarm_sim.scenario import Scenario


class RingSensor:
    """One robot's proximity ring, read from its scan."""

    __slots__ = ("_body", "_cos", "_range", "_reach", "_sin", "_value", "rays")

    def __init__(self, scenario: Scenario) -> None:
        angles = ray_angles(scenario.sensors.scan)
        self.rays = len(angles)
        self._cos = [math.cos(a) for a in angles]
        self._sin = [math.sin(a) for a in angles]
        self._body = scenario.robots.diameter / 2.0
        self._range = scenario.sensors.proximity_ring.range
        self._reach = self._body + self._range + 1e-9
        self._value = model_of(scenario).ring_value

    def vector(self, ranges: np.ndarray | Sequence[float]) -> tuple[float, float]:
        """The sum of the readings as vectors [body frame, x ahead]; (0, 0) when nothing is within
        range. `ranges`: the scan [m from the centre]; NaN and inf read nothing."""
        values = ranges.tolist() if isinstance(ranges, np.ndarray) else list(ranges)
        reach, body, rng = self._reach, self._body, self._range
        if min(values, default=math.inf) > reach:  # nothing near (min skips a NaN unless it is first,
            return 0.0, 0.0                        # and a NaN min goes on to the full check below)
        reading, cos, sin = self._value, self._cos, self._sin
        x = y = 0.0
        for i, v in enumerate(values):
            if v <= reach and v - body <= rng:
                value = reading(v - body)
                x += value * cos[i]
                y += value * sin[i]
        return x, y

    def blocks(self, ranges: np.ndarray | Sequence[float], cone: float) -> bool:
        """The readings' vector is non-zero and within `cone` [deg] of the heading: the queue
        authors' path stop (``CPFA_controller::CollisionDetection``, ``GoStraightAngleRangeInDegreesInRegion``)."""
        x, y = self.vector(ranges)
        norm = math.hypot(x, y)
        return norm > 0.0 and x >= math.cos(math.radians(cone)) * norm
