"""Response-threshold foragers: DRTM (Pang et al. 2023, drtm_task_allocation.md) and ARTM.

One state machine for both (Fig. 1, Table 1); they differ only in the threshold theta of eq. (7).

* **Waiting S_W.** Every robot starts waiting in the nest. A waiting robot stands still, except
  right after a deposit (below). It counts its ticks in S_W from 0 (t_1); when t_1 reaches T_1
  it draws: with probability P_s of eq. (7) ("roulette wheel selection" between leaving and
  staying) it switches to S_S and tells the nest (LEFT); if it stays, it draws again every
  ``draw_period`` ticks (default T_1: its timer restarts; see `ThresholdConfig.draw_period` for
  the every-tick reading of the ARGoS example). P_s uses the last `NestState` it heard:
  S(t) = F_d - F(t) (eq. (2)) and theta from the subclass; before it has heard the nest it does
  not draw. n is drawn once per robot, uniform in [2, 9].
* **Searching S_S** (ASM, eq. (1)): A(t) = 0, a random walk driven by the noise epsilon (full
  speed, turn rate ~ N(0, walk_turn_std^2) each tick), until a food token is detected; then
  A(t) = 1 and f(x) steers to the nearest detected token. The world picks it up when the robot
  is on it; the robot then switches to S_R (FOUND).
* **Returning S_R**: random walk until the light is detected (``sensors.light_range``), then
  approach the light. The world drops the token when the robot enters the nest; on that tick
  the robot switches to S_W (DEPOSITED) and, to free the nest's edge for the next carriers,
  keeps approaching the light for at most ``settle_steps`` ticks, stopping as soon as anything
  is ahead within the avoidance distance or it is within half the nest radius of the centre
  (the ARGoS foraging example's robots likewise look for a place in the nest for 50 ticks). It
  consumes no energy meanwhile: only S_S and S_R do (Sec. 3.1).
* **Obstacle avoidance** (Sec. 2.2) has priority over the ASM in S_S and S_R: the robot model's
  (`swarm_controllers.motion.Drive.avoidance`; the generic robot's is the scan-based avoidance of
  `swarm_controllers.avoidance`: turn away, then a straight escape run of one body length; the
  ``footbot_foraging`` model's the ARGoS foraging example's ``diffusion``). Steering to a token or
  the light goes through the model's motion layer too. Each episode is one OAE; the robot counts it and reports it to the nest (AVOIDED).
  Waiting robots do not move, so they neither avoid nor count.
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np

from swarm_controllers.avoidance import ray_angles, ray_window
from swarm_controllers.drtm.config import NestConfig, ThresholdConfig
from swarm_controllers.drtm.protocol import NestEvent, NestReport, NestState
from swarm_controllers.drtm.response_threshold import (
    ArtmThreshold,
    drtm_threshold,
    foraging_probability,
    mean_avoidance,
    stimulus,
    traffic_flow_density,
)
from swarm_controllers.motion import drive_for
from swarm_msgs_py.types import BehaviourStatus, Command, Observation, RobotId
from swarm_sim.scenario import Scenario

_BLOCK = 256
"""Random numbers are drawn from the robot's generator this many at a time (a scalar draw per
tick costs more than the rest of the step)."""


class ForagerState(Enum):
    """Fig. 1 of the DRTM paper."""

    WAITING = "waiting"
    SEARCHING = "searching"
    RETURNING = "returning"


class ThresholdForager:
    """One robot of Fig. 1; subclasses give theta (see the module docstring)."""

    def __init__(self, scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> None:
        th = ThresholdConfig.of(scenario)
        self.robot = robot
        self.config = th
        self._rng = rng
        self.exponent = int(rng.integers(th.exponent_min, th.exponent_max + 1))
        """n of eq. (7), fixed for the run."""
        self._period = th.period()
        self._robots = scenario.robots.count
        self._side = scenario.arena.size
        self._desired = NestConfig.of(scenario).desired_food
        self._drive = drive_for(scenario, rng)
        self._speed = scenario.robots.max_linear_speed
        self._max_turn = scenario.robots.max_angular_speed
        self._avoid = self._drive.avoidance(scenario.robots.diameter)
        half_front = scenario.controller.avoidance.front_fov / 2.0 + 1e-12
        self._front = ray_window(i for i, a in enumerate(ray_angles(scenario.sensors.scan)) if abs(a) <= half_front)
        """The front sector's rays (the generic avoidance's), watched while settling into the nest."""
        self._stop_distance = scenario.controller.avoidance.distance
        self._nest_xy = (float(scenario.depot.center[0]), float(scenario.depot.center[1]))
        self._settled_r2 = (scenario.depot.radius / 2.0) ** 2
        self._state = ForagerState.WAITING
        self._waited = 0
        """t_1: ticks in S_W so far."""
        self._settle = 0
        """Ticks of settling into the nest left."""
        self._trips = 0
        self._stamp = 0
        self.nest: NestState | None = None
        """The last state heard from the nest."""
        self.threshold_value: float | None = None
        """theta at the last draw."""
        self._normals: list[float] = []
        self._uniforms: list[float] = []

    # ------------------------------------------------------------------ threshold (subclasses)

    def threshold(self, nest: NestState) -> float:
        """theta for a draw, given the last state heard."""
        raise NotImplementedError

    def heard(self, nest: NestState) -> None:
        """A new state from the nest arrived (ARTM adapts here)."""

    # ------------------------------------------------------------------ Behaviour

    @property
    def state(self) -> ForagerState:
        return self._state

    @property
    def trips(self) -> int:
        return self._trips

    def step(self, obs: Observation) -> Command:
        self._stamp = obs.stamp_ns
        self._drive.begin(obs.stamp_ns)
        for m in obs.messages:
            if type(m) is NestState and (self.nest is None or m.stamp_ns >= self.nest.stamp_ns):
                self.nest = m
                self.heard(m)
        reports: list[NestEvent] = []
        if self._state is ForagerState.WAITING:
            linear, angular = self._waiting(obs, reports)
        elif self._state is ForagerState.SEARCHING:
            linear, angular = self._searching(obs, reports)
        else:
            linear, angular = self._returning(obs, reports)
        if not reports:
            return Command(linear, angular)
        return Command(linear, angular, tuple(NestReport(obs.stamp_ns, self.robot, e) for e in reports))

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        return BehaviourStatus(self.robot, self._stamp if stamp_ns is None else stamp_ns, self._state.value,
                               self._avoid.events, self._trips, (("exponent", str(self.exponent)),))

    # ------------------------------------------------------------------ states

    def _waiting(self, obs: Observation, reports: list[NestEvent]) -> tuple[float, float]:
        c = self.config
        if (self._waited >= c.min_wait_steps and (self._waited - c.min_wait_steps) % self._period == 0
                and self.nest is not None and self._draw()):
            self._state = ForagerState.SEARCHING
            self._settle = 0
            reports.append(NestEvent.LEFT)
            return self._searching(obs, reports)
        self._waited += 1
        return self._settling(obs) if self._settle else (0.0, 0.0)

    def _searching(self, obs: Observation, reports: list[NestEvent]) -> tuple[float, float]:
        sense = obs.sensed
        if sense.carrying:
            self._state = ForagerState.RETURNING
            reports.append(NestEvent.FOUND)
            return self._returning(obs, reports)
        avoiding = self._avoiding(obs, reports)
        if avoiding is not None:
            return avoiding
        if sense.resources:  # A(t) = 1: the nearest token is the attractor
            x, y = sense.resources[0]
            pose = obs.pose
            return self._drive.to_point(pose.x, pose.y, pose.yaw, x, y)
        return self._walk()

    def _returning(self, obs: Observation, reports: list[NestEvent]) -> tuple[float, float]:
        sense = obs.sensed
        if not sense.carrying:  # the world dropped the token in the nest
            self._state = ForagerState.WAITING
            self._trips += 1
            self._waited = 0
            self._settle = self.config.settle_steps
            self._avoid.reset()
            reports.append(NestEvent.DEPOSITED)
            return self._waiting(obs, reports)
        avoiding = self._avoiding(obs, reports)
        if avoiding is not None:
            return avoiding
        x, y = sense.light
        if x or y:  # A(t) = 1: the light is the attractor
            return self._drive.hold(math.atan2(y, x))
        return self._walk()

    # ------------------------------------------------------------------ motion

    def _avoiding(self, obs: Observation, reports: list[NestEvent]) -> tuple[float, float] | None:
        before = self._avoid.events
        command = self._avoid.update(obs.ranges)
        if self._avoid.events != before:
            reports.append(NestEvent.AVOIDED)
        return None if command is None else (command.linear, command.angular)

    def _walk(self) -> tuple[float, float]:
        """A(t) = 0: the noise term of eq. (1)."""
        turn = self.config.walk_turn_std * self._normal()
        return self._speed, min(max(turn, -self._max_turn), self._max_turn)

    def _settling(self, obs: Observation) -> tuple[float, float]:
        self._settle -= 1
        x, y = obs.sensed.light
        dx, dy = obs.pose.x - self._nest_xy[0], obs.pose.y - self._nest_xy[1]
        if not (x or y) or dx * dx + dy * dy <= self._settled_r2 or self._blocked(obs.ranges):
            self._settle = 0
            return 0.0, 0.0
        return self._drive.hold(math.atan2(y, x))

    def _blocked(self, ranges: np.ndarray) -> bool:
        return bool(np.min(ranges[self._front]) < self._stop_distance)

    # ------------------------------------------------------------------ randomness

    def _draw(self) -> bool:
        """Roulette wheel between leaving (P_s) and staying (1 - P_s)."""
        nest = self.nest
        theta = self.threshold_value = self.threshold(nest)
        p = foraging_probability(stimulus(self._desired, nest.food), theta, self.exponent)
        return p >= 1.0 or (p > 0.0 and self._uniform() < p)

    def _normal(self) -> float:
        if not self._normals:
            self._normals = self._rng.standard_normal(_BLOCK).tolist()
        return self._normals.pop()

    def _uniform(self) -> float:
        if not self._uniforms:
            self._uniforms = self._rng.random(_BLOCK).tolist()
        return self._uniforms.pop()


class DrtmBehaviour(ThresholdForager):
    """DRTM: theta = alpha k + beta M_A (eqs. (4)-(6)) from the nest's N_W and M_T2."""

    def threshold(self, nest: NestState) -> float:
        c = self.config
        k = traffic_flow_density(self._robots, nest.waiting, self._side)
        theta = drtm_threshold(k, mean_avoidance(nest.recent_oaes, self._robots), c.alpha, c.beta)
        return min(max(theta, c.threshold_min), c.threshold_max) if c.drtm_bounded else theta


class ArtmBehaviour(ThresholdForager):
    """ARTM: theta adapts to the food in the nest only (`ArtmThreshold`)."""

    def __init__(self, scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> None:
        super().__init__(scenario, robot, rng)
        c = self.config
        self._artm = ArtmThreshold(c.initial_threshold, c.threshold_min, c.threshold_max, c.artm_gain)

    def heard(self, nest: NestState) -> None:
        self._artm.update(stimulus(self._desired, nest.food))

    def threshold(self, nest: NestState) -> float:
        return self._artm.value
