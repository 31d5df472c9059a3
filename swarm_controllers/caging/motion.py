"""The caging paper's motion control: discrete PIDs and the state machines of Fig. 1.

Fig. 1a (moving to a point): ROTATE in place while the heading error |alpha_p| exceeds sigma,
else MOVE forward with speed PID(D_p) while turning by PID(alpha_p), ARRIVED once D_p <= the
tolerance (d, or Delta when approaching the object). Fig. 1b (spinning toward a landmark): SPIN
by PID(alpha_p) until |alpha_p| <= sigma, then ALIGNED. During transport (Alg. 6 line 22) the
same machine follows a planar velocity built from the seven PIDs of Table 1 (`Formation`).

alpha_p is eq. (4) read as the signed angle from the heading to the bearing of the target,
wrapped to [-pi, pi] (the printed |arctan(D_p) - beta| loses the sign a PID needs). Speeds are
clamped to the robot's limits; a PID is reset whenever its target changes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

from swarm_controllers.caging.config import CagingConfig, PidGains
from swarm_msgs_py.types import Pose2D

Point = tuple[float, float]


class Pid:
    """u = kp e + ki sum(e dt) + kd (e - e_prev) / dt; no derivative on the first step."""

    __slots__ = ("kp", "ki", "kd", "dt", "_integral", "_previous")

    def __init__(self, gains: PidGains, dt: float) -> None:
        self.kp, self.ki, self.kd, self.dt = gains.kp, gains.ki, gains.kd, dt
        self.reset()

    def reset(self) -> None:
        self._integral = 0.0
        self._previous: float | None = None

    def __call__(self, error: float) -> float:
        self._integral += error * self.dt
        derivative = 0.0 if self._previous is None else (error - self._previous) / self.dt
        self._previous = error
        return self.kp * error + self.ki * self._integral + self.kd * derivative


def bearing_error(pose: Pose2D, target: Point) -> float:
    """alpha_p, eq. (4): signed angle [rad] from the heading to the target's bearing."""
    return math.remainder(math.atan2(target[1] - pose.y, target[0] - pose.x) - pose.yaw, 2.0 * math.pi)


def deadband(error: float, tolerance: float) -> float:
    """What exceeds "value +- tolerance" (Alg. 6 line 22: maintain D +- d, theta = phi +- sigma)."""
    if error > tolerance:
        return error - tolerance
    if error < -tolerance:
        return error + tolerance
    return 0.0


class Motion(Enum):
    """States of Fig. 1a and 1b."""

    ROTATE = "rotate"
    MOVE = "move"
    ARRIVED = "arrived"
    SPIN = "spin"
    ALIGNED = "aligned"


@dataclass(frozen=True)
class Limits:
    linear: float
    """[m/s]"""
    angular: float
    """[rad/s]"""
    dt: float
    """[s]"""
    sigma: float
    """[rad]"""

    def clamp(self, v: float, w: float) -> tuple[float, float]:
        return max(-self.linear, min(self.linear, v)), max(-self.angular, min(self.angular, w))


class GoTo:
    """Fig. 1a with the PIDs alpha_p and D_p: drive to a point, stop within a tolerance."""

    def __init__(self, cfg: CagingConfig, limits: Limits) -> None:
        self.limits = limits
        self._heading = Pid(cfg.heading, limits.dt)
        self._distance = Pid(cfg.distance, limits.dt)
        self.state = Motion.ROTATE

    def reset(self) -> None:
        self._heading.reset()
        self._distance.reset()
        self.state = Motion.ROTATE

    def step(self, pose: Pose2D, target: Point, tolerance: float) -> tuple[float, float]:
        """(linear [m/s], angular [rad/s]) toward `target`; `state` says where the machine is."""
        distance = math.hypot(target[0] - pose.x, target[1] - pose.y)
        if distance <= tolerance:
            self.state = Motion.ARRIVED
            return 0.0, 0.0
        alpha = bearing_error(pose, target)
        turn = self._heading(alpha)
        if abs(alpha) > self.limits.sigma:
            if self.state is not Motion.ROTATE:
                self._distance.reset()
            self.state = Motion.ROTATE
            return self.limits.clamp(0.0, turn)
        self.state = Motion.MOVE
        return self.limits.clamp(max(0.0, self._distance(distance)), turn)


class Spin:
    """Fig. 1b with the PID alpha_p: turn in place to face a point."""

    def __init__(self, cfg: CagingConfig, limits: Limits) -> None:
        self.limits = limits
        self._heading = Pid(cfg.heading, limits.dt)
        self.state = Motion.SPIN

    def reset(self) -> None:
        self._heading.reset()
        self.state = Motion.SPIN

    def step(self, pose: Pose2D, target: Point) -> tuple[float, float]:
        alpha = bearing_error(pose, target)
        if abs(alpha) <= self.limits.sigma:
            self.state = Motion.ALIGNED
            return 0.0, 0.0
        self.state = Motion.SPIN
        return self.limits.clamp(0.0, self._heading(alpha))


HOLD_DISTANCE = 2.0
"""[in d]: how near p_i+ a robot the formation holds still counts as arrived (`Formation`)."""
HOLD_SPEED = 0.005
"""[m/s]"""
HOLD_TICKS = 20
"""Control ticks (2 s at 10 Hz)."""


@dataclass(frozen=True)
class Neighbour:
    """A cage neighbour as robot i sees it during transport."""

    position: Point
    """Its sensed centre [m, world frame]."""
    chord: float
    """Ideal D_ell or D_r: the distance between the two cage positions [m]."""
    separation: float
    """Ideal theta_ell or theta_r: the angle between the two cage positions around the object,
    k phi for neighbours k places apart [rad]."""
    side: int
    """+1 left (counter-clockwise around the object), -1 right."""


class Formation:
    """Alg. 6 line 22: move toward p_i+ keeping D_object, D_ell, D_r within +-d and theta_ell,
    theta_r at their ideal angle within +-sigma, with the seven PIDs of Table 1.

    Each PID turns the part of its error beyond the tolerance into a planar velocity: D_lambda
    toward p_i+ (at most the robot's top speed, so that on a long leg the corrections still
    count), D_object toward the object's centre when the robot is more than d farther than its
    cage distance (only then: the object moves only when the robots behind it touch and push it,
    and holding them off it stalled the cage short of its places), D_ell / D_r along the line to
    that neighbour, theta_ell / theta_r around the object's centre (tangent to the circle
    around it: this keeps the robots spread around the object, so that one pushing it off
    centre does not slide past it; measured around the cage's own centre instead, the cage let
    the object slip out on long legs). The robot drives that sum as a differential-drive robot can: speed = its length
    times the cosine of the heading error, turn rate = PID(alpha_p) on its direction, backing up
    when it points behind; ARRIVED within d of p_i+. The paper names the seven variables and
    their gains but not how they combine ("a state machine similar to Fig. 1a"): summing is our
    reading. Unlike Fig. 1a the robot does not stop to rotate while the heading error exceeds
    sigma: the corrections turn the sum by a few degrees all the time, and with stop-and-rotate
    (measured) the rear robots stood turning while the front ones drove off, tearing the cage.

    Beyond the paper: a robot held within HOLD_DISTANCE x d of p_i+ by the other PIDs (asking for
    less than HOLD_SPEED for HOLD_TICKS ticks) counts as arrived. The object, caged with the
    clearance of eq. (5), ends each leg a few centimetres short of lambda, so the robots spread
    around it sit a little off their p_i+; with four robots (measured) the pull toward p_i+ and
    the angle PIDs balanced 3-15 mm outside d and the cage waited for ever.
    """

    def __init__(self, cfg: CagingConfig, limits: Limits, cage_radius: float) -> None:
        self.limits = limits
        self.d = cfg.distance_tolerance
        self.R = cage_radius
        self._held = 0
        """Ticks in a row the robot has been held short of p_i+ (see `step`)."""
        dt = limits.dt
        self._heading = Pid(cfg.heading, dt)
        self._distance = Pid(cfg.distance, dt)
        self._object = Pid(cfg.object_distance, dt)
        self._neighbour_distance = {1: Pid(cfg.neighbour_distance, dt), -1: Pid(cfg.neighbour_distance, dt)}
        self._neighbour_angle = {1: Pid(cfg.neighbour_angle, dt), -1: Pid(cfg.neighbour_angle, dt)}
        self.state = Motion.ROTATE

    def reset(self) -> None:
        for pid in (self._heading, self._distance, self._object, *self._neighbour_distance.values(),
                    *self._neighbour_angle.values()):
            pid.reset()
        self.state = Motion.ROTATE
        self._held = 0

    def velocity(self, pose: Pose2D, target: Point, obj: Point | None, neighbours: Sequence[Neighbour]) -> Point:
        """The planar velocity the seven PIDs ask for [m/s, world frame]."""
        x, y = pose.x, pose.y
        dx, dy = target[0] - x, target[1] - y
        d_lambda = math.hypot(dx, dy)
        speed = self.limits.clamp(self._distance(d_lambda), 0.0)[0]  # no faster than the robot goes
        vx, vy = speed * dx / d_lambda, speed * dy / d_lambda
        if obj is not None:
            ox, oy = obj[0] - x, obj[1] - y
            d_obj = math.hypot(ox, oy)
            if d_obj > 0:  # only "too far": robots behind the object must touch it to push it
                u = self._object(max(0.0, deadband(d_obj - self.R, self.d)))
                vx, vy = vx + u * ox / d_obj, vy + u * oy / d_obj
        for n in neighbours:
            nx, ny = n.position[0] - x, n.position[1] - y
            d_n = math.hypot(nx, ny)
            if d_n > 0:
                u = self._neighbour_distance[n.side](deadband(d_n - n.chord, self.d))
                vx, vy = vx + u * nx / d_n, vy + u * ny / d_n
            if obj is not None:
                mine = math.atan2(y - obj[1], x - obj[0])
                theirs = math.atan2(n.position[1] - obj[1], n.position[0] - obj[0])
                theta = n.side * math.remainder(theirs - mine, 2.0 * math.pi)
                u = self._neighbour_angle[n.side](deadband(theta - n.separation, self.limits.sigma))
                # toward the neighbour around the object: counter-clockwise for the left one
                vx, vy = vx - n.side * u * math.sin(mine), vy + n.side * u * math.cos(mine)
        return vx, vy

    def step(self, pose: Pose2D, target: Point, obj: Point | None, neighbours: Sequence[Neighbour]) -> tuple[float, float]:
        """(linear, angular) for this tick; `state` ARRIVED once within d of `target`."""
        d_lambda = math.hypot(target[0] - pose.x, target[1] - pose.y)
        if d_lambda <= self.d or self._held >= HOLD_TICKS:
            self.state = Motion.ARRIVED
            return 0.0, 0.0
        vx, vy = self.velocity(pose, target, obj, neighbours)
        alpha = math.remainder(math.atan2(vy, vx) - pose.yaw, 2.0 * math.pi)
        direction = 1.0
        if abs(alpha) > math.pi / 2:  # it points behind: back up instead of turning round
            direction, alpha = -1.0, math.remainder(alpha - math.pi, 2.0 * math.pi)
        self.state = Motion.MOVE
        v, w = self.limits.clamp(direction * math.hypot(vx, vy) * math.cos(alpha), self._heading(alpha))
        held = d_lambda <= HOLD_DISTANCE * self.d and abs(v) < HOLD_SPEED
        self._held = self._held + 1 if held else 0
        return v, w
