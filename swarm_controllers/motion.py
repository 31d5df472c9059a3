"""Steering for a differential-drive robot: turn in place, or drive with a proportional turn.

Plain `math` on purpose: these run for every robot every tick, and numpy's per-call overhead
on scalars costs more than the arithmetic (its functions imported by name: a module attribute
lookup per call added ~0.1 us to a `go_to_point_twist`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import atan2, cos, hypot, inf, remainder

from swarm_sim.geometry import wrap_angle
from swarm_sim.scenario import Scenario
from swarm_sim.types import Command, Pose2D

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class DriveLimits:
    """What the steering may ask of the wheels."""

    max_linear: float
    """[m/s], forward only."""
    max_angular: float
    """[rad/s], either direction."""
    dt: float
    """Control tick [s]; sets the gains so one tick never overshoots."""
    turn_in_place: float = 0.5
    """Heading errors larger than this [rad] are turned out on the spot before driving."""

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> DriveLimits:
        r = scenario.robots
        return cls(r.max_linear_speed, r.max_angular_speed, scenario.sim.dt)


def steer(heading_error: float, distance: float, limits: DriveLimits) -> tuple[float, float]:
    """(linear [m/s], angular [rad/s]) that reduce `heading_error` [rad] and cover `distance` [m].

    The turn rate halves the heading error per tick (gain 0.5/dt, saturated at max_angular), so
    it never overshoots. Above `turn_in_place` the robot only turns; below it drives at up to
    max_linear, scaled by cos(error) and capped at distance/dt so it stops on a point target.
    A non-finite error gives (0, 0).
    """
    if not -inf < heading_error < inf:  # nan or inf
        return 0.0, 0.0
    w_max = limits.max_angular
    angular = 0.5 / limits.dt * heading_error
    if angular > w_max:
        angular = w_max
    elif angular < -w_max:
        angular = -w_max
    if abs(heading_error) > limits.turn_in_place:
        return 0.0, angular
    linear = distance / limits.dt
    if not linear < limits.max_linear:  # also catches inf / nan distances
        linear = limits.max_linear
    if linear < 0.0:
        linear = 0.0
    return linear * cos(heading_error), angular


def go_to_point_twist(
    x: float, y: float, yaw: float, target_x: float, target_y: float, limits: DriveLimits
) -> tuple[float, float]:
    """`steer` toward a point [m, world frame] from pose (x, y, yaw)."""
    dx = target_x - x
    dy = target_y - y
    error = atan2(dy, dx) - yaw
    if not -inf < error < inf:
        return 0.0, 0.0
    return steer(remainder(error, _TWO_PI), hypot(dx, dy), limits)


def go_to_point(pose: Pose2D, target: tuple[float, float], limits: DriveLimits) -> Command:
    """A command that drives `pose` toward `target` [m, world frame] within the limits."""
    linear, angular = go_to_point_twist(pose.x, pose.y, pose.yaw, target[0], target[1], limits)
    return Command(linear, angular)


def hold_heading(pose: Pose2D, heading: float, limits: DriveLimits) -> Command:
    """A command that turns to `heading` [rad, world frame] and drives along it at full speed."""
    error = heading - pose.yaw
    if not -inf < error < inf:
        return Command()
    linear, angular = steer(wrap_angle(error), inf, limits)
    return Command(linear, angular)
