"""The CPFA lineage's ``BaseController``: the queue and spiral papers' foot-bots move in stop-turn-go steps.

Traced to the authors' code: Tameem786/Collision_Free_CPFA (branch ``main``, their Q_SE) and
Artglz/Collision_Free_CPFA (their Q_MT), ``source/Base/BaseController.cpp``; the spiral paper's
MARSLab-UTRGV/Adaptive-Multiple-Distributed-Spiral-Search-Algorithm (branch ``luki-dev``,
``Distributed/source/Base/BaseController.cpp``) has the same motion. Every one of them runs:

- ``SetNextMovement`` (the robot is stopped and has nothing to do): farther than the distance
  tolerance from the target, turn in place while the heading error is above the angle tolerance,
  else drive the whole distance in one blind FORWARD move; each move is pushed, then popped a tick
  later (the robot stands two ticks of their 32 ticks/s: `PLAN_TIME`). A move runs to its end
  whatever the behaviour asks meanwhile: the target is only read when the robot stops again.
- ``SetTargetAngleDistance``: a turn of a degrees lasts 0.105 a / ``RobotRotationSpeed`` [cm/s]
  seconds (`TURN_CM_PER_DEGREE`), with the wheels at +-``RobotRotationSpeed``, 14 cm apart: it
  turns 0.105 a / 7 rad = 0.859 a, and the next stop turns out the rest;
  ``SetTargetTravelDistance``: a FORWARD of d m lasts 100 d / ``RobotForwardSpeed`` seconds.
- ``CollisionDetection`` (every tick, before the move): the 24 proximity readings' mean vector,
  if non-zero and within ``GoStraightAngleRangeInDegrees`` (+-80 deg; here
  ``sensors.proximity_ring.ahead``) of the heading, stops the robot, empties the stack, pushes a
  FORWARD of ``SearchStepSize`` and turns by the vector's angle: clockwise whichever side the
  vector is on (``SetLeftTurn(angle)`` for angle <= 0 and ``SetRightTurn(angle)`` for angle > 0
  both end in the RIGHT state), and sets ``collisionDelay`` = now + U(0.5, 1.0) s. Until that
  delay has passed, a turning robot drives forward at full speed instead, unless it collides on
  that tick (``Move``, cases LEFT and RIGHT, "qilu 10/26/2016"). The DDSA authors' BaseController
  turns *away* instead, by 37.5 deg plus the angle, and always turns
  (``robots.stop_turn_go.collision_turn: away``).
- A robot standing idle (``Stop()`` before every ``Move()``) only turns on a collision; its pushed
  step never runs (`turn_only`).
- A robot that follows a queue's path does not avoid: the queue authors' ``CPFA_controller::
  CollisionDetection`` (Tameem786 and Artglz/Collision_Free_CPFA, states FOLLOWING_ENTRY_PATH,
  FOLLOWING_EXIT_PATH / EXITING) calls ``Stop()`` when the readings' vector is non-zero and within
  ``GoStraightAngleRangeInDegreesInRegion`` (+-30 deg) of the heading: the move under way is
  dropped (``TicksToWaitWhileMoving = 0``, state STOP) and the next one is planned toward the
  target of that time, once nothing stops it (`path_stop`).

Time runs continuously inside a tick: the robot's twist over a tick is the mean of the moves it
made in it (a move that ends inside a tick leaves the robot standing for the rest of it), so
a leg's turn takes angle / turn rate and its drive distance / speed, however they fall on our
0.1 s ticks; the authors' rounding up to 1/32 s ticks and the tick a stopping wheel coasts are
left out. The angle and distance tolerances and ``SearchStepSize`` are the scenario's
(``robots.stop_turn_go``); the speeds its ``robots.max_linear_speed`` and
``robots.max_angular_speed`` (the ``footbot_cpfa`` model's: 16 cm/s and 2 x 8 / 14 rad/s).

A tick's motion is worked out once, from the state at its start, the collision seen in it and the
behaviour's last request in it (as ARGoS's ``Move`` sees the last ``SetTarget`` of the step), so
the order in which a behaviour asks for avoidance and motion does not matter; on a tick the
behaviour drives the wheels itself (standing at a dock, a queue's brake) the moves wait.
"""

from __future__ import annotations

import math
from math import atan2, hypot, inf, remainder

import numpy as np

from swarm_controllers.robots.ring import RingSensor
from swarm_msgs_py.types import Command
from swarm_sim.robots.footbot import INTERWHEEL_DISTANCE
from swarm_sim.scenario import Scenario

PLAN_TIME = 2.0 / 32.0
"""[s] a robot stands before each planned move: the STOP tick that pushes it and the tick that
pops it, at the authors' ``ticks_per_second="32"``."""
POP_TIME = 1.0 / 32.0
"""[s] it stands before the FORWARD step pushed by a collision (popped on the STOP tick)."""
TURN_CM_PER_DEGREE = 0.105
"""``SetTargetAngleDistance``: s = 0.105 x angle [deg], turned for s / ``RobotRotationSpeed`` s."""
COLLISION_DELAY = (0.5, 1.0)
"""[s] ``collisionDelay`` after a collision: U(0.5, 1.0) s."""
AWAY_OFFSET = 37.5
"""[deg] the DDSA authors' turn away from a collision: 37.5 deg beyond the readings' angle."""

_STOP, _TURN, _FORWARD = 0, 1, 2
_TWO_PI = 2.0 * math.pi
_EMPTY: tuple = ()


class StopTurnGo:
    """One robot's ``BaseController`` (see the module docstring); a `swarm_controllers.motion.Drive`."""

    __slots__ = (
        "_angle_tol", "_away", "_collided", "_cos_ahead", "_delay_draw", "_dist_tol", "_dt", "_hit", "_idle",
        "_looked", "_next", "_request", "_ring", "_rng", "_stamp", "_state", "_step", "_v", "_w", "_wheel_cm",
        "active", "events",
    )
    blind_legs = True
    """A FORWARD move runs its whole distance (see the module docstring)."""

    def __init__(self, scenario: Scenario, rng: np.random.Generator | None = None) -> None:
        r = scenario.robots
        cfg = r.stop_turn_go
        self._v = r.max_linear_speed
        self._w = r.max_angular_speed
        self._wheel_cm = 100.0 * self._w * INTERWHEEL_DISTANCE / 2.0
        """``RobotRotationSpeed`` [cm/s]: the wheel speed that turns the robot at `_w`."""
        self._dt = scenario.sim.dt
        self._angle_tol = cfg.angle_tolerance
        self._dist_tol = cfg.distance_tolerance
        self._step = cfg.collision_step
        self._away = cfg.collision_turn == "away"
        self._ring = RingSensor(scenario)
        self._cos_ahead = math.cos(math.radians(scenario.sensors.proximity_ring.ahead))
        self._rng = (rng if rng is not None else np.random.default_rng(0)).spawn(1)[0]
        """The collision delays' own stream: the behaviour's draws stay as they are."""
        self._state: tuple = (_EMPTY, 0.0, False)
        """At the tick's start: (moves, delay left [s], the moves are a collision's)."""
        self._next = self._state
        """The state after this tick's motion; the same as `_state` while the tick has driven nothing
        (a behaviour that sets its own twist leaves the motion where it was)."""
        self._collided = False
        """A collision on the last tick (an episode goes on)."""
        self._stamp = -1
        self._hit: float | None = None
        """This tick's collision: the readings' angle [deg], None if none (or not looked yet)."""
        self._looked = False
        self._delay_draw = 0.0
        self._request: tuple | None = None
        self._idle = False
        self.events = 0
        """Collision episodes (a tick with a collision after one without)."""
        self.active = False
        """A collision this tick."""

    # ------------------------------------------------------------------ Drive

    def begin(self, stamp_ns: int) -> None:
        if stamp_ns != self._stamp:
            self._stamp = stamp_ns
            self._state = self._next
            self._collided = self.active
            self._hit = None
            self._looked = False
            self._request = None
            self._idle = False
            self.active = False

    def to_point(self, x: float, y: float, yaw: float, tx: float, ty: float) -> tuple[float, float]:
        dx, dy = tx - x, ty - y
        self._request = (remainder(atan2(dy, dx) - yaw, _TWO_PI), hypot(dx, dy), True)
        return self._tick()

    def hold(self, heading_error: float, ahead: float = inf) -> tuple[float, float]:
        """Turn to the heading, then drive `ahead` [m] (``SearchStepSize`` when infinite), at least
        the distance tolerance: the authors' robots count a target nearer than that as reached,
        and a behaviour that still asks to go on (its leg not quite walked) gets there."""
        self._request = (heading_error, max(ahead if ahead < inf else self._step, self._dist_tol), False)
        return self._tick()

    def avoidance(self, escape_distance: float = 0.0, *, keep_right: bool = False) -> StopTurnGo:
        """Itself: ``CollisionDetection`` is part of ``Move`` (the escape is its `collision_step`,
        and it always turns clockwise)."""
        return self

    def path_stop(self, ranges: np.ndarray, cone: float) -> bool:
        """The queue authors' rule on a path: something within `cone` [deg] of the heading stops the
        robot and drops the move under way (``Stop()``); call it after the tick's motion was asked."""
        if not self._ring.blocks(ranges, cone):
            return False
        self._next = (_EMPTY, max(self._state[1] - self._dt, 0.0), False)
        return True

    # ------------------------------------------------------------------ Avoidance

    def update(self, ranges: np.ndarray) -> Command | None:
        """On a collision, the turn it starts; while the turn and its step run, their motion; else None."""
        self._detect(ranges)
        if self._hit is None and not self._state[2]:
            return None
        return Command(*self._tick())

    def turn_only(self, ranges: np.ndarray) -> Command | None:
        self._idle = True
        self._detect(ranges)
        twist = self._tick()
        return Command(*twist) if self._hit is not None else None

    def reset(self) -> None:
        self.active = False

    def collide(self, angle: float) -> None:
        """A collision this tick at `angle` [deg, body frame], as if the summed readings pointed
        there: for a behaviour whose own rule finds the way blocked where they miss the cone
        (`swarm_controllers.spiral.ddsa.LaneAvoidance` with ``controller.spiral.lane_unjam``).
        No-op if the ring already saw a collision this tick; `update` then starts its turn."""
        if self._looked and self._hit is not None:
            return
        self._looked = True
        self._hit = angle
        self._delay_draw = float(self._rng.uniform(*COLLISION_DELAY))
        self.active = True
        if not self._collided:
            self.events += 1

    # ------------------------------------------------------------------ the tick

    def _detect(self, ranges: np.ndarray) -> None:
        if self._looked:
            return
        self._looked = True
        x, y = self._ring.vector(ranges)
        norm = hypot(x, y)
        if norm > 0.0 and x >= self._cos_ahead * norm:
            self._hit = math.degrees(atan2(y, x))
            self._delay_draw = float(self._rng.uniform(*COLLISION_DELAY))
            self.active = True
            if not self._collided:
                self.events += 1

    def _tick(self) -> tuple[float, float]:
        """This tick's twist from the state at its start; sets the state for the next tick."""
        moves, delay, seq = self._state
        hit = self._hit
        if hit is not None:
            if self._away:  # left by 37.5 - angle for readings on the right (angle <= 0), else right
                turn = ((_TURN, TURN_CM_PER_DEGREE * (AWAY_OFFSET + abs(hit)) / self._wheel_cm,
                         1.0 if hit <= 0.0 else -1.0),)
            else:
                turn = ((_TURN, TURN_CM_PER_DEGREE * abs(hit) / self._wheel_cm, -1.0),) if hit else ()
            moves = turn if self._idle else (*turn, (_STOP, POP_TIME, 0.0), (_FORWARD, self._step / self._v, 0.0))
            delay, seq = (0.0 if self._away else self._delay_draw), True
        elif self._idle:
            moves, seq = _EMPTY, False
        if not moves and self._request is not None and hit is None:
            moves, seq = self._plan(*self._request), False
        forward_turns = delay > 0.0 and hit is None
        lin = ang = 0.0
        left = self._dt
        out = list(moves)
        while out and left > 0.0:
            kind, duration, sign = out[0]
            use = duration if duration < left else left
            if kind == _FORWARD or (kind == _TURN and forward_turns):
                lin += self._v * use
            elif kind == _TURN:
                ang += sign * self._w * use
            duration -= use
            left -= use
            if duration <= 1e-12:
                out.pop(0)
            else:
                out[0] = (kind, duration, sign)
        if self._idle:
            out = []
        self._next = (tuple(out), max(delay - self._dt, 0.0), seq and bool(out))
        return lin / self._dt, ang / self._dt

    def _plan(self, error: float, distance: float, to_target: bool) -> tuple:
        """``SetNextMovement``: at the target stop; else turn out the heading error, or drive."""
        if to_target and distance < self._dist_tol or not distance > 0.0:
            return _EMPTY
        if abs(error) > self._angle_tol:
            seconds = TURN_CM_PER_DEGREE * math.degrees(abs(error)) / self._wheel_cm
            return (_STOP, PLAN_TIME, 0.0), (_TURN, seconds, 1.0 if error > 0 else -1.0)
        return (_STOP, PLAN_TIME, 0.0), (_FORWARD, distance / self._v, 0.0)
