"""Reactive obstacle avoidance from the laser scan: the generic robot's (the platform robot models
bring their authors' own, `swarm_controllers.robots`; every behaviour gets its robot's from
`swarm_controllers.motion.Drive.avoidance`).

The scan sees walls, obstacles and other robots alike, so one rule covers all three: when a
ray in the front sector reads closer than `AvoidanceConfig.distance`, the robot stops driving
and turns toward the side with more free space until the front sector is clear again. This is
the role the foot-bot proximity ring plays in the ARGoS CPFA; the behaviour that owns this
object gives it priority over its state machine's motion.

An obstacle-avoidance *event* is one such episode: it is counted on the tick avoidance starts
after at least one clear tick (the state before the first tick counts as clear), not once per
tick spent turning. The turn direction is chosen when the episode starts and kept until it
ends, so a symmetric obstacle (a wall met head on) cannot make the robot dither left and right.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from swarm_msgs_py.geometry import wrap_angle
from swarm_msgs_py.types import Command
from swarm_sim.scenario import AvoidanceConfig, ScanConfig, Scenario

_FULL_CIRCLE_TOLERANCE = 1e-9


def ray_window(rays: Iterable[int]) -> slice | list[int]:
    """Rays `rays` (indices in order) as a slice when they are contiguous, as a sector of a scan
    is in every sane configuration (angles are monotonic around the heading): a scan array's
    sector is then one view. An index list covers anything else."""
    rays = list(rays)
    return slice(rays[0], rays[-1] + 1) if rays and rays == list(range(rays[0], rays[-1] + 1)) else rays


def ray_angles(scan: ScanConfig) -> list[float]:
    """Angle of each ray relative to the heading [rad, counter-clockwise, wrapped to (-pi, pi]].

    Ray i is at ``-fov/2 + i * inc`` with ``inc = fov / rays`` for a full circle (the last ray
    stops one increment short of the first) and ``fov / (rays - 1)`` otherwise (both ends
    included), the convention the world's scan uses.
    """
    n = scan.rays
    if scan.fov >= 2.0 * math.pi - _FULL_CIRCLE_TOLERANCE:
        inc = scan.fov / n
    else:
        inc = scan.fov / (n - 1) if n > 1 else 0.0
    return [wrap_angle(-scan.fov / 2.0 + i * inc) for i in range(n)]


class ObstacleAvoidance:
    """Turns away from whatever the front sector of the scan sees too close; counts episodes."""

    # Slots: every robot owns one (see `swarm_controllers.cpfa.behaviour.CpfaBehaviour`).
    __slots__ = (
        "_active", "_command", "_distance", "_events", "_front", "_front_rays",
        "_keep_right", "_left", "_range_max", "_rays", "_right", "_turn_left",
        "_turn_right", "config", "scan",
    )

    def __init__(
        self, config: AvoidanceConfig, scan: ScanConfig, max_angular: float | None = None,
        *, keep_right: bool = False,
    ) -> None:
        """keep_right: every episode turns right (clockwise) instead of toward the freer side.
        Turning to the freer side makes two robots meeting head on on one straight line mirror
        each other (both turn to the same world side, meet again, push each other along for
        metres); with a fixed turn sense both swerve to their own right and pass, as on a road.
        DDSA/MDBSA searchers use it (carriers and resuming robots share their lanes)."""
        self._keep_right = keep_right
        self.config = config
        self.scan = scan
        self._rays = scan.rays
        self._distance = config.distance
        self._range_max = scan.range_max
        angles = ray_angles(scan)
        half_front = config.front_fov / 2.0 + 1e-12
        self._front_rays = tuple(i for i, a in enumerate(angles) if abs(a) <= half_front)
        self._front = ray_window(self._front_rays)
        # Free space is compared over the forward half-plane only: what lies behind the robot
        # does not matter for where it can turn to and drive.
        self._left = [i for i, a in enumerate(angles) if 0.0 < a <= math.pi / 2 + 1e-12]
        self._right = [i for i, a in enumerate(angles) if -math.pi / 2 - 1e-12 <= a < 0.0]
        turn = config.turn_speed if max_angular is None else min(config.turn_speed, max_angular)
        self._turn_left = Command(0.0, turn)
        self._turn_right = Command(0.0, -turn)
        self._active = False
        self._command: Command = self._turn_left
        self._events = 0

    @property
    def events(self) -> int:
        """Obstacle-avoidance episodes so far."""
        return self._events

    @property
    def active(self) -> bool:
        """True while the last `update` returned a turn."""
        return self._active

    def reset(self) -> None:
        """Forget the current episode (the robot stopped moving): the next blocked tick starts
        a new one."""
        self._active = False

    @property
    def front_rays(self) -> tuple[int, ...]:
        """Indices of the rays watched for obstacles."""
        return self._front_rays

    def update(self, ranges: np.ndarray | Sequence[float]) -> Command | None:
        """A turn-away command if the front sector is blocked, else None.

        `ranges` [m] are the scan's rays in order (float32 array or any float sequence; inf
        where nothing was hit). A NaN ray is ignored.

        Every robot calls this every tick, so only the front sector is read (an array's slice
        as floats) until an episode starts; the whole scan is read then, for the free side.
        """
        if len(ranges) != self._rays:
            raise ValueError(
                f"scan has {len(ranges)} rays, the scenario says sensors.scan.rays={self._rays}"
            )
        is_array = isinstance(ranges, np.ndarray)
        front = ranges[self._front].tolist() if is_array else [ranges[i] for i in self._front_rays]
        if not front:
            self._active = False
            return None
        nearest = min(front)
        if nearest != nearest:  # NaN poisoned min(); look again without NaNs
            nearest = min((v for v in front if v == v), default=math.inf)
        if not nearest < self._distance:
            self._active = False
            return None
        if not self._active:
            self._active = True
            self._events += 1
            values = ranges.tolist() if is_array else list(ranges)
            left = not self._keep_right and self._free_side(values) >= 0.0
            self._command = self._turn_left if left else self._turn_right
        return self._command

    def _free_side(self, values: list[float]) -> float:
        """Mean free range left minus right [m]: positive = more room to the left (ties left)."""
        rmax = self._range_max

        def mean_free(indices: list[int]) -> float:
            if not indices:
                return 0.0
            total = 0.0
            for i in indices:
                v = values[i]
                total += v if v < rmax else rmax  # inf and NaN count as free to range_max
            return total / len(indices)

        return mean_free(self._left) - mean_free(self._right)


class AvoidThenEscape:
    """Obstacle avoidance with priority over a behaviour's motion, then a straight escape run.

    When an avoidance episode ends the robot drives straight ahead for `escape_distance`
    before its behaviour steers again (ARGoS pushes a FORWARD move after its avoidance turn);
    without it, a goal just beside an obstacle makes the avoidance turn and the goal turn undo
    each other forever with the robot standing still.
    """

    # Slots: every robot owns one (see `swarm_controllers.cpfa.behaviour.CpfaBehaviour`).
    __slots__ = (
        "_escape", "_escape_left", "_escape_ticks", "_was_avoiding", "avoidance",
    )

    def __init__(self, scenario: Scenario, escape_distance: float, *, keep_right: bool = False) -> None:
        r = scenario.robots
        self.avoidance = ObstacleAvoidance(
            scenario.controller.avoidance, scenario.sensors.scan, r.max_angular_speed,
            keep_right=keep_right,
        )
        self._escape = Command(r.max_linear_speed, 0.0)
        self._escape_ticks = max(
            1, math.ceil(escape_distance / (r.max_linear_speed * scenario.sim.dt) - 1e-9)
        )
        self._escape_left = 0
        self._was_avoiding = False

    @property
    def events(self) -> int:
        return self.avoidance.events

    @property
    def active(self) -> bool:
        return self.avoidance.active

    def reset(self) -> None:
        """Forget the current episode and escape run (the robot stopped moving)."""
        self.avoidance.reset()
        self._escape_left = 0
        self._was_avoiding = False

    def update(self, ranges: np.ndarray | Sequence[float]) -> Command | None:
        """The command that overrides the behaviour this tick (a turn away or the escape run),
        or None when the behaviour steers."""
        avoid = self.avoidance.update(ranges)
        if avoid is not None:
            self._was_avoiding = True
            return avoid
        if self._was_avoiding:  # the episode just ended: the escape run starts
            self._was_avoiding = False
            self._escape_left = self._escape_ticks
        if self._escape_left:
            self._escape_left -= 1
            return self._escape
        return None

    def turn_only(self, ranges: np.ndarray | Sequence[float]) -> Command | None:
        """The avoidance turn of a robot that stands still, without the escape run: it turns
        in place away from what its front sector sees and never drives off. In the authors'
        ARGoS code an IDLE robot calls ``Stop()`` before ``Move()`` every tick, so the forward
        step ``BaseController::CollisionDetection`` pushes after its turn is cancelled and only
        the turn is driven (MARSLab-UTRGV/DDSA-Distributed-Deterministic-Spiral-Search-Algorithm,
        branch luki-dev, source/Base/BaseController.cpp and source/DSA/DSA_controller.cpp,
        ``DSA_controller::ControlStep``, state IDLE). Episodes count as in `update`."""
        self._escape_left = 0
        self._was_avoiding = False
        return self.avoidance.update(ranges)
