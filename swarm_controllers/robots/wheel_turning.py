"""The ARGoS foraging example's foot-bot motion: ``SetWheelSpeedsFromVector`` and ``diffusion``.

Traced to ilpincy/argos3-examples, ``controllers/footbot_foraging/footbot_foraging.cpp`` with the
parameters of ``experiments/foraging.argos`` (``robots.wheel_turning``), the DRTM paper's set-up:

- ``SetWheelSpeedsFromVector(v)``: the heading is v's angle a in the body frame, the base wheel
  speed min(|v|, ``max_speed``) (10 cm/s). A three-state turning mechanism with hysteresis: from
  HARD_TURN to SOFT_TURN once |a| <= 70 deg; from SOFT_TURN to HARD_TURN above 90 deg and to
  NO_TURN at or below 10 deg; from NO_TURN to HARD_TURN above 90 deg and to SOFT_TURN above 10 deg
  (it starts in NO_TURN). NO_TURN drives both wheels at the base speed; SOFT_TURN the inner wheel
  at base x f and the outer at base x (2 - f), f = (90 deg - |a|) / 90 deg; HARD_TURN the wheels
  at -+``max_speed`` (turning in place toward a). Wheels 0.14 m apart.
- ``DiffusionVector``: the 24 proximity readings summed as vectors; within +-5 deg of the heading
  and shorter than ``delta`` = 0.1 the robot goes straight (no collision), else it heads away
  from the vector's direction (a collision: an obstacle-avoidance event starts).
- Homing (``ReturnToNest``): v = ``max_speed`` x (diffusion vector + unit vector to the light);
  with nothing near, the diffusion vector is straight ahead, so the robot turns by half the goal's
  angle. Every goal a behaviour gives (`to_point`, `hold`) is steered to that way.

Our choices where the example is silent: it never drives to a point, so near a point target the
speed is capped at distance / dt as the generic robot's is; while avoiding, the example's homing
robot adds the light vector to the away vector, ours heads away only (avoidance has priority, as
in every behaviour here). A tick's motion is worked out from the turning mechanism at its start,
so asking for avoidance and motion in either order gives the same result.
"""

from __future__ import annotations

import math
from math import atan2, cos, hypot, inf, remainder, sin

import numpy as np

from swarm_controllers.robots.ring import RingSensor
from swarm_msgs_py.types import Command
from swarm_sim.robots.footbot import INTERWHEEL_DISTANCE
from swarm_sim.scenario import Scenario

NO_TURN, SOFT_TURN, HARD_TURN = 0, 1, 2
_TWO_PI = 2.0 * math.pi


class WheelTurning:
    """One foraging-example foot-bot's motion (see the module docstring); a `swarm_controllers.motion.Drive`."""

    __slots__ = (
        "_collided", "_delta", "_dt", "_hard", "_looked", "_max", "_mech", "_next", "_none", "_override",
        "_ring", "_soft", "_stamp", "_straight", "active", "events",
    )
    blind_legs = False
    """The example's robots re-aim at every step."""

    def __init__(self, scenario: Scenario, rng: np.random.Generator | None = None) -> None:
        cfg = scenario.robots.wheel_turning
        self._max = scenario.robots.max_linear_speed
        """``max_speed`` [m/s] of a wheel."""
        self._hard = math.radians(cfg.hard_turn_angle)
        self._soft = math.radians(cfg.soft_turn_angle)
        self._none = math.radians(cfg.no_turn_angle)
        self._straight = math.radians(cfg.go_straight_angle)
        self._delta = cfg.delta
        self._dt = scenario.sim.dt
        self._ring = RingSensor(scenario)
        self._mech = NO_TURN
        """The turning mechanism at the tick's start."""
        self._next = (NO_TURN, False)
        """(mechanism, collided) for the next tick."""
        self._stamp = -1
        self._looked = False
        self._override: Command | None = None
        self._collided = False
        self.events = 0
        """Obstacle-avoidance episodes (a tick with a collision after one without)."""
        self.active = False

    # ------------------------------------------------------------------ Drive

    def begin(self, stamp_ns: int) -> None:
        if stamp_ns != self._stamp:
            self._stamp = stamp_ns
            self._mech, self._collided = self._next
            self._next = (self._mech, False)
            self._looked = False
            self._override = None
            self.active = False

    def to_point(self, x: float, y: float, yaw: float, tx: float, ty: float) -> tuple[float, float]:
        dx, dy = tx - x, ty - y
        d = hypot(dx, dy)
        if not d > 0.0:
            return 0.0, 0.0
        return self._goal(remainder(atan2(dy, dx) - yaw, _TWO_PI), d / self._dt)

    def hold(self, heading_error: float, ahead: float = inf) -> tuple[float, float]:
        """Along a heading, at the speed ``SetWheelSpeedsFromVector`` gives (`ahead` is not read:
        the example steers by vectors, not legs)."""
        return self._goal(heading_error, inf)

    def avoidance(self, escape_distance: float = 0.0, *, keep_right: bool = False) -> WheelTurning:
        """Itself: ``diffusion`` (no escape run: the example steers by the readings every tick)."""
        return self

    def path_stop(self, ranges: np.ndarray, cone: float) -> None:
        """The foraging example keeps to no paths: the behaviour's own rule."""
        return None

    # ------------------------------------------------------------------ Avoidance

    def update(self, ranges: np.ndarray) -> Command | None:
        if not self._looked:
            self._looked = True
            near = self.diffusion(ranges)
            if near is None:
                return None
            x, y, length = near
            self.active = True
            if not self._collided:
                self.events += 1
            self._override = Command(*self.twist_from_vector(-self._max * x / length, -self._max * y / length, inf))
            self._next = (self._next[0], True)
        return self._override

    turn_only = update

    def diffusion(self, ranges: np.ndarray) -> tuple[float, float, float] | None:
        """``DiffusionVector``: None when the robot may go straight (no collision), else the sum of
        the proximity readings (x, y) [body frame] and its length; the robot heads away from it.
        Pure: it neither counts nor steers."""
        x, y = self._ring.vector(ranges)
        length = hypot(x, y)
        if abs(atan2(y, x)) <= self._straight and length < self._delta:
            return None
        return x, y, length

    def reset(self) -> None:
        self._next = (self._next[0], False)

    # ------------------------------------------------------------------ SetWheelSpeedsFromVector

    def _goal(self, error: float, cap: float) -> tuple[float, float]:
        if self._override is not None:  # avoiding this tick: its turn stands
            return self._override.linear, self._override.angular
        m = self._max
        return self.twist_from_vector(m + m * cos(error), m * sin(error), cap)

    def twist_from_vector(self, vx: float, vy: float, cap: float = inf) -> tuple[float, float]:
        """``SetWheelSpeedsFromVector``: (linear [m/s], angular [rad/s]) for heading vector (vx, vy)
        [m/s, body frame], the base speed at most `cap` [m/s]. Advances the turning mechanism."""
        angle = atan2(vy, vx)
        a = abs(angle)
        base = min(hypot(vx, vy), self._max, cap)
        mech = self._mech
        if mech == HARD_TURN and a <= self._soft:
            mech = SOFT_TURN
        if mech == SOFT_TURN:
            if a > self._hard:
                mech = HARD_TURN
            elif a <= self._none:
                mech = NO_TURN
        if mech == NO_TURN:
            if a > self._hard:
                mech = HARD_TURN
            elif a > self._none:
                mech = SOFT_TURN
        self._next = (mech, self._next[1])
        if mech == NO_TURN:
            return base, 0.0
        if mech == SOFT_TURN:
            factor = (self._hard - a) / self._hard
            slow, fast = base * factor, base * (2.0 - factor)
            linear = base
        else:
            slow, fast = -self._max, self._max
            linear = 0.0
        turn = (fast - slow) / INTERWHEEL_DISTANCE
        return linear, turn if angle > 0.0 else -turn
