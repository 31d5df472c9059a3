"""The proximity ring's collision detection: what the queue and spiral papers count as collision time.

Both papers' "collision time" is the time robots spend in collision avoidance, counted by their
ARGoS controllers, not physical contact. The queue paper's authors' code
(Tameem786/Collision_Free_CPFA and Artglz/Collision_Free_CPFA, ``BaseController.cpp``,
``BaseController::CollisionDetection`` and ``GetCollisionVector``, called from ``Move`` every
control step) sums the foot-bot's 24 proximity readings as vectors (value, sensor angle), and a
tick on which that mean vector is non-zero and points within +-80 deg of the heading increments
``collision_counter``; ``CPFA_loop_functions::PostExperiment`` adds the counters of all robots
and prints them in minutes.

Here the ring's sensors are the scan's rays (the generic robot: 24 rays every 15 deg from -180 deg;
a foot-bot model lays the scan out on the foot-bot's sensor directions, 7.5 + 15 k deg,
`swarm_sim.robots.footbot`): a ray that hits something within `ProximityRingConfig.range` of the
body reads the robot model's `ring_reading` of d, the distance beyond the body (the generic robot:
exp(-d); the foot-bot: ARGoS's ``CFootBotProximityDefaultSensor`` curve), else 0. The world
counts, for every robot, the ticks on which the robots acted on such a reading (`World.step`), so
batch runs and recorded runs (``/world/robot_stats``) report the same number.

The authors' later queue controllers narrow the angle to +-30 deg while a robot follows a queue
path or exits (``CPFA_controller::CollisionDetection``), and a robot waiting at a dock (``Wait``)
skips the check. Both depend on the controller's state, which the world does not know: the rule
here applies in every state, and the state-dependent rules are computed beside it from the states
the robots report (`swarm_sim.analysis.state_rules`), from `vectors`.
"""

from __future__ import annotations

import math

import numpy as np

from swarm_sim.robots import model_of
from swarm_sim.scenario import Scenario
from swarm_sim.world.raycast import scan_angles


class ProximityRing:
    """Per tick, which robots' proximity ring sees something ahead."""

    def __init__(self, scenario: Scenario) -> None:
        sc = scenario.sensors.scan
        ring = scenario.sensors.proximity_ring
        start, inc = scan_angles(sc.rays, sc.fov)
        angles = start + inc * np.arange(sc.rays)
        self._cos = np.cos(angles)
        self._sin = np.sin(angles)
        self._body = scenario.robots.diameter / 2.0
        self._range = ring.range
        self._cos_ahead = math.cos(math.radians(ring.ahead))
        self._reading = model_of(scenario).ring_reading
        self.ahead_deg = ring.ahead
        """The half-angle of `ahead` [deg]."""
        self._last: tuple[np.ndarray, np.ndarray] | None = None
        """(ranges, their readings) of the last call: the world reads the ring of a tick twice."""

    def _values(self, ranges: np.ndarray) -> np.ndarray:
        """(n, rays) each ring sensor's reading (0: nothing within range)."""
        if self._last is not None and self._last[0] is ranges:
            return self._last[1]
        d = np.asarray(ranges, dtype=float) - self._body
        with np.errstate(invalid="ignore"):
            hit = d <= self._range  # NaN and inf compare False
        value = np.zeros_like(d)
        value[hit] = self._reading(d[hit])  # few rays read anything (1000 robots: 110 -> 45 us)
        if isinstance(ranges, np.ndarray) and not ranges.flags.writeable:  # the world's: read-only, kept
            self._last = (ranges, value)
        return value

    def ahead(self, ranges: np.ndarray) -> np.ndarray:
        """(n,) bool: the mean reading vector of each robot's ring points within the ahead angle.

        `ranges`: (n, rays) scan ranges from the robots' centres [m] (inf: nothing hit)."""
        value = self._values(ranges)
        x = value @ self._cos
        y = value @ self._sin
        norm = np.hypot(x, y)
        # angle within +-ahead of the heading <=> cos(angle) >= cos(ahead); a zero vector never.
        return (norm > 0.0) & (x >= self._cos_ahead * norm)

    def vectors(self, ranges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(x, y), each (n,): every robot's summed reading vector [body frame; 0 where nothing is
        within range]. Each row is summed on its own (numpy's pairwise sum along a contiguous row),
        so a row gives the same floats whichever rows it is stacked with: the batch runner's
        whole-swarm array and a bag replay's rows of a few robots agree bit for bit (`ahead`'s
        matrix product may order its sums by the array's shape)."""
        value = self._values(ranges)
        x, y = np.zeros(len(value)), np.zeros(len(value))
        rows = np.flatnonzero(value.any(axis=1))  # most robots read nothing
        if len(rows):
            near = np.ascontiguousarray(value[rows])
            x[rows] = (near * self._cos).sum(axis=1)
            y[rows] = (near * self._sin).sum(axis=1)
        return x, y
