"""The motion layer between a behaviour and the wheels, and the generic robot's steering.

Behaviours decide where to go; the robot model (``robots.model``, `swarm_sim.robots`) decides how
the robot moves there, as the authors' ``BaseController`` does for their behaviours. Every
behaviour gets its robot's `Drive` from `drive_for` and asks it for

- ``to_point(x, y, yaw, tx, ty)``: the twist toward a target point [m, world frame];
- ``hold(heading_error, ahead)``: the twist along a heading (`ahead` [m]: how far the behaviour
  means to go that way; models that move in whole legs drive that far);
- ``avoidance(escape_distance, keep_right=...)``: the robot's collision avoidance, with priority
  over the behaviour's motion (`swarm_controllers.avoidance.AvoidThenEscape`'s interface);
- ``begin(stamp_ns)``, once at the start of every tick (models with a state of their own advance
  it once a tick, whatever the behaviour asks in between);
- ``path_stop(ranges, cone)``: the model's own rule for a robot that keeps to a path (a queue
  lane): True when it stopped for something within `cone` [deg] ahead, False when nothing stopped
  it, None when the model has no such rule (the behaviour keeps its own).

The models' drives: `ContinuousDrive` (the generic robot and the Khepera III: steered continuously,
re-aimed every tick, `steer`), `swarm_controllers.robots.stop_turn_go.StopTurnGo` (the CPFA
lineage's foot-bot) and `swarm_controllers.robots.wheel_turning.WheelTurning` (the ARGoS foraging
example's foot-bot). A behaviour's own twist (standing still, a random walk's turn) goes to the
wheels as it is.

Plain `math` on purpose: these run for every robot every tick, and numpy's per-call overhead
on scalars costs more than the arithmetic (its functions imported by name: a module attribute
lookup per call added ~0.1 us to a `go_to_point_twist`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import atan2, cos, hypot, inf, remainder
from typing import Protocol

import numpy as np

from swarm_controllers.avoidance import AvoidThenEscape
from swarm_msgs_py.geometry import wrap_angle
from swarm_msgs_py.types import Command, Pose2D
from swarm_sim.registry import resolve
from swarm_sim.robots import model_of
from swarm_sim.scenario import Scenario

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


class Avoidance(Protocol):
    """A robot's collision avoidance (`AvoidThenEscape` and the robot models' own)."""

    @property
    def events(self) -> int:
        """Avoidance episodes so far."""
        ...

    @property
    def active(self) -> bool:
        """True while the last `update` found something to avoid."""
        ...

    def update(self, ranges: np.ndarray) -> Command | None:
        """The command overriding the behaviour this tick, or None."""
        ...

    def turn_only(self, ranges: np.ndarray) -> Command | None:
        """The avoidance of a robot that stands still: turns in place only."""
        ...

    def reset(self) -> None:
        """Forget the current episode (the robot stopped moving)."""
        ...


class Drive(Protocol):
    """A robot model's motion layer (see the module docstring)."""

    blind_legs: bool
    """A move, once started, runs to its end whatever the behaviour asks meanwhile (the CPFA
    lineage's stop-turn-go): a behaviour that must keep its path off an area decides so before
    the move starts, from any distance, as the queue authors' ``IsPathThroughRedCircle`` does."""

    def begin(self, stamp_ns: int) -> None: ...

    def to_point(self, x: float, y: float, yaw: float, tx: float, ty: float) -> tuple[float, float]: ...

    def hold(self, heading_error: float, ahead: float = inf) -> tuple[float, float]: ...

    def avoidance(self, escape_distance: float, *, keep_right: bool = False) -> Avoidance: ...

    def path_stop(self, ranges: np.ndarray, cone: float) -> bool | None: ...


class ContinuousDrive:
    """The generic robot's motion (and the Khepera III's): `go_to_point_twist` and `steer` within
    the scenario's speed limits, re-aimed every tick; avoidance by `AvoidThenEscape`. Stateless,
    so `begin` does nothing and `hold` drives on whatever `ahead` says."""

    __slots__ = ("limits", "scenario")
    blind_legs = False

    def __init__(self, scenario: Scenario, rng: np.random.Generator | None = None) -> None:
        self.scenario = scenario
        self.limits = DriveLimits.from_scenario(scenario)

    def begin(self, stamp_ns: int) -> None:
        pass

    def to_point(self, x: float, y: float, yaw: float, tx: float, ty: float) -> tuple[float, float]:
        return go_to_point_twist(x, y, yaw, tx, ty, self.limits)

    def hold(self, heading_error: float, ahead: float = inf) -> tuple[float, float]:
        return steer(heading_error, inf, self.limits)

    def avoidance(self, escape_distance: float, *, keep_right: bool = False) -> AvoidThenEscape:
        return AvoidThenEscape(self.scenario, escape_distance, keep_right=keep_right)

    def path_stop(self, ranges: np.ndarray, cone: float) -> None:
        return None


def drive_for(scenario: Scenario, rng: np.random.Generator | None = None) -> Drive:
    """The motion layer of the scenario's robot model (`swarm_sim.robots.RobotModel.motion`), for
    one robot; `rng`: the robot's behaviour generator (a model that draws spawns its own stream
    from it, so the behaviour's draws stay as they are)."""
    return resolve(model_of(scenario).motion)(scenario, rng)
