"""The ARGoS foraging example's rule (ilpincy/argos3-examples, ``controllers/footbot_foraging``):
the rule of the DRTM reference run, which runs that controller unchanged in ARGoS in the DRTM
paper's arena. With it on our side, our robots and physics (this rule) can be compared with
ARGoS's (the same rule) apart from the rule (DRTM's, `swarm_controllers.drtm.behaviour`).

Written from the example's ``CFootBotForaging`` (``footbot_foraging.cpp``), not copied; parameters
in `ExampleRuleConfig` (``controller.example``), motion in the ``footbot_foraging`` model's
`swarm_controllers.robots.wheel_turning` (``SetWheelSpeedsFromVector``, ``DiffusionVector``).
Each robot keeps RestToExploreProb and ExploreToRestProb, always clipped to [0, 1].

* **Resting** (``Rest()``): every robot starts resting, its TimeRested at the minimum resting
  time (``SStateData::Reset``: so it draws from its second tick on). Once TimeRested exceeds
  ``minimum_resting_time`` it draws each tick: with RestToExploreProb it starts exploring (LEFT)
  and TimeRested restarts at 0; otherwise TimeRested grows. It stands still and counts nothing.
* **Exploring** (``Explore()``): a robot that now carries a token (the world picked it up, as the
  example's loop functions do: it never steers to food) applies the food rule (ExploreToRestProb
  down, RestToExploreProb up by their ``food_rule_*`` deltas) and returns home (FOUND). One that
  has explored more than ``minimum_unsuccessful_explore_time`` ticks without a find draws each
  tick: with ExploreToRestProb it returns home empty, else ExploreToRestProb rises and
  RestToExploreProb falls by the food-rule deltas. Otherwise it walks: its TimeExploring-
  Unsuccessfully grows, and on every tick the diffusion vector reports a collision (every tick
  of it, as the example does) ExploreToRestProb rises and RestToExploreProb falls by
  ``collision_rule_explore_to_rest_delta_prob``. Its heading vector is ``max_speed`` x the diffusion
  vector, minus ``max_speed`` / 4 x the unit vector to the light while in the nest
  (anti-phototaxis). On the tick it turns home it sets no wheels (they keep the last tick's
  speeds, as ARGoS's actuator does).
* **Returning** (``ReturnToNest()``): after more than ``minimum_search_for_place_in_nest_time``
  consecutive ticks in the nest it stops and rests; outside the nest that count restarts. Its
  heading vector is ``max_speed`` x (diffusion vector + unit vector to the light).

"In the nest" is the example's ``UpdateState()``: its motor ground sensors 2 and 3 both read the
nest's grey. ARGoS puts those at (-6.3, -1.16) and (6.3, -1.16) cm (the right-hand pair, though the
example's comment calls them the back pair); here both points, from the robot's pose and
`swarm_sim.robots.footbot.MOTOR_GROUND_SENSORS`, lie in the depot disc (the nest).

* **The social rule** (``Rest()``): a robot that comes to rest tells the others whether its last
  exploration found food (the example broadcasts it over range-and-bearing for one tick: TOLD_SUCCESSFUL
  or TOLD_UNSUCCESSFUL to the nest here, which relays the counts in its next `NestState`). A
  resting robot that does not leave on the tick it hears them moves its probabilities by the
  ``social_rule_*`` deltas once per robot told: a success raises RestToExploreProb and lowers
  ExploreToRestProb, a failure the reverse. Its own telling is not counted. Every resting robot
  hears every telling, a tick later than in ARGoS (robot -> nest -> robot); in ARGoS a robot
  within range-and-bearing's 3 m (the whole nest) hears it unless other robots block the line of
  sight, which the reference run measures both ways (``--no-occlusions``).

Reporting to the nest's ledger (`swarm_controllers.drtm.nest`), whose energy counts, like the
example's loop functions, every robot not resting as walking: LEFT when it stops resting, FOUND
on each pick-up, AVOIDED once per collision episode (the tick the diffusion vector's collision
flag rises, exploring or returning). When it rests it reports DEPOSITED once per token the world
dropped in the nest during the trip (the world drops the token as its centre enters the nest, so
the ledger credits it a little over 5 s late: the 51 ticks the robot looks for a place in the
nest), or RETURNED_EMPTY after a trip that delivered nothing (an unsuccessful exploration). A
token dropped while resting (the world's drop came late) is reported DEPOSITED at once.
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np

from swarm_controllers.drtm.config import ExampleRuleConfig
from swarm_controllers.drtm.protocol import NestEvent, NestReport, NestState
from swarm_controllers.robots.wheel_turning import WheelTurning
from swarm_msgs_py.types import BehaviourStatus, Command, Observation, RobotId
from swarm_sim.robots.footbot import MOTOR_GROUND_SENSORS
from swarm_sim.scenario import Scenario

ANTI_PHOTOTAXIS = 0.25
"""The light's weight against the diffusion vector while exploring in the nest (``Explore()``)."""
_NEST_SENSORS = (MOTOR_GROUND_SENSORS[2], MOTOR_GROUND_SENSORS[3])
"""The ground sensors ``UpdateState()`` reads."""
_BLOCK = 256
"""Uniforms are drawn from the robot's generator this many at a time."""


class ExampleState(Enum):
    """``SStateData::EState``."""

    RESTING = "resting"
    EXPLORING = "exploring"
    RETURNING = "returning"


class ForagingExampleBehaviour:
    """One robot of the ARGoS foraging example (see the module docstring)."""

    def __init__(self, scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> None:
        c = ExampleRuleConfig.of(scenario)
        self.robot = robot
        self.config = c
        self._rng = rng
        self._wheels = WheelTurning(scenario)
        self._max = scenario.robots.max_linear_speed
        """``max_speed`` [m/s]."""
        self._nest_xy = (float(scenario.depot.center[0]), float(scenario.depot.center[1]))
        self._nest_r2 = scenario.depot.radius ** 2
        self._state = ExampleState.RESTING
        self.rest_to_explore = c.initial_rest_to_explore_prob
        self.explore_to_rest = c.initial_explore_to_rest_prob
        self.time_rested = c.minimum_resting_time
        self.time_exploring_unsuccessfully = 0
        self.time_searching_for_place_in_nest = 0
        self._command = (0.0, 0.0)
        """The wheels as last set (ARGoS's actuator keeps them until set again)."""
        self._colliding = False
        """The diffusion vector reported a collision on the last tick."""
        self._carrying = False
        self._delivered = 0
        """Tokens dropped in the nest since the robot last rested."""
        self._result: NestEvent | None = None
        """The last exploration's result, told when the robot comes to rest (TOLD_*)."""
        self._told_ns: int | None = None
        """When it last told: the first nest state stamped after it counts its own telling."""
        self._heard_ns = -1
        """The stamp of the last nest state heard."""
        self._events = 0
        self._trips = 0
        self._stamp = 0
        self._uniforms: list[float] = []

    @property
    def state(self) -> ExampleState:
        return self._state

    def step(self, obs: Observation) -> Command:
        self._stamp = obs.stamp_ns
        self._wheels.begin(obs.stamp_ns)
        reports: list[NestEvent] = []
        carrying = obs.sensed.carrying
        if carrying and not self._carrying:
            reports.append(NestEvent.FOUND)
        elif self._carrying and not carrying:
            self._delivered += 1
            self._trips += 1
        self._carrying = carrying
        news = None
        for m in obs.messages:
            if type(m) is NestState and m.stamp_ns > self._heard_ns:
                news, self._heard_ns = m, m.stamp_ns
        colliding = False
        if self._state is ExampleState.RESTING:
            self._rest(reports, news)
        elif self._state is ExampleState.EXPLORING:
            colliding = self._explore(obs, reports)
        else:
            colliding = self._return(obs, reports)
        if colliding and not self._colliding:
            self._events += 1
            reports.append(NestEvent.AVOIDED)
        self._colliding = colliding
        linear, angular = self._command
        if not reports:
            return Command(linear, angular)
        return Command(linear, angular, tuple(NestReport(obs.stamp_ns, self.robot, e) for e in reports))

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        return BehaviourStatus(self.robot, self._stamp if stamp_ns is None else stamp_ns, self._state.value,
                               self._events, self._trips)

    # ------------------------------------------------------------------ states

    def _rest(self, reports: list[NestEvent], news: NestState | None) -> None:
        """``Rest()``: the wheels stay stopped; `news`, a nest state first heard this tick."""
        if self._delivered:  # the world dropped the token after the robot had come to rest
            reports.extend([NestEvent.DEPOSITED] * self._delivered)
            self._delivered = 0
        if self.time_rested > self.config.minimum_resting_time and self._uniform() < self.rest_to_explore:
            self._state = ExampleState.EXPLORING
            self.time_rested = 0
            reports.append(NestEvent.LEFT)
        else:
            self.time_rested += 1
            if news is not None:
                self._hear(news)

    def _hear(self, news: NestState) -> None:
        """The social rule: the deltas once per other robot told (see the module docstring)."""
        good, bad = news.told_successful, news.told_unsuccessful
        if self._told_ns is not None and news.stamp_ns > self._told_ns:
            if self._result is NestEvent.TOLD_SUCCESSFUL:
                good -= 1
            else:
                bad -= 1
            self._told_ns = None
        c = self.config
        for _ in range(max(good, 0)):
            self._shift(-c.social_rule_explore_to_rest_delta_prob, c.social_rule_rest_to_explore_delta_prob)
        for _ in range(max(bad, 0)):
            self._shift(c.social_rule_explore_to_rest_delta_prob, -c.social_rule_rest_to_explore_delta_prob)

    def _explore(self, obs: Observation, reports: list[NestEvent]) -> bool:
        """``Explore()``; True if the diffusion vector reported a collision."""
        c = self.config
        if self._carrying:  # success: the food rule
            self._shift(-c.food_rule_explore_to_rest_delta_prob, c.food_rule_rest_to_explore_delta_prob)
            home, self._result = True, NestEvent.TOLD_SUCCESSFUL
        elif self.time_exploring_unsuccessfully > c.minimum_unsuccessful_explore_time:
            home = self._uniform() < self.explore_to_rest
            if home:
                self._result = NestEvent.TOLD_UNSUCCESSFUL
            else:
                self._shift(c.food_rule_explore_to_rest_delta_prob, -c.food_rule_rest_to_explore_delta_prob)
        else:
            home = False
        if home:  # no wheels set this tick
            self.time_exploring_unsuccessfully = 0
            self.time_searching_for_place_in_nest = 0
            self._state = ExampleState.RETURNING
            return False
        self.time_exploring_unsuccessfully += 1
        in_nest = self._in_nest(obs)
        dx, dy, collision = self._diffusion(obs.ranges)
        if collision:
            delta = c.collision_rule_explore_to_rest_delta_prob
            self._shift(delta, -delta)
        m = self._max
        if in_nest:
            lx, ly = self._to_light(obs)
            self._set_wheels(m * dx - m * ANTI_PHOTOTAXIS * lx, m * dy - m * ANTI_PHOTOTAXIS * ly)
        else:
            self._set_wheels(m * dx, m * dy)
        return collision

    def _return(self, obs: Observation, reports: list[NestEvent]) -> bool:
        """``ReturnToNest()``; True if the diffusion vector reported a collision."""
        if self._in_nest(obs):
            if self.time_searching_for_place_in_nest > self.config.minimum_search_for_place_in_nest_time:
                self._command = (0.0, 0.0)
                self._state = ExampleState.RESTING
                self.time_searching_for_place_in_nest = 0
                reports.extend([NestEvent.DEPOSITED] * self._delivered if self._delivered
                               else [NestEvent.RETURNED_EMPTY])
                reports.append(self._result)
                self._told_ns = obs.stamp_ns
                self._delivered = 0
                return False
            self.time_searching_for_place_in_nest += 1
        else:
            self.time_searching_for_place_in_nest = 0
        dx, dy, collision = self._diffusion(obs.ranges)
        lx, ly = self._to_light(obs)
        m = self._max
        self._set_wheels(m * dx + m * lx, m * dy + m * ly)
        return collision

    # ------------------------------------------------------------------ senses and wheels

    def _diffusion(self, ranges: np.ndarray) -> tuple[float, float, bool]:
        """``DiffusionVector``: (x, y) unit [body frame] and whether it is a collision."""
        near = self._wheels.diffusion(ranges)
        if near is None:
            return 1.0, 0.0, False
        x, y, length = near
        return -x / length, -y / length, True

    @staticmethod
    def _to_light(obs: Observation) -> tuple[float, float]:
        """``CalculateVectorToLight``: the unit vector to the light [body frame], zero unseen."""
        x, y = obs.sensed.light
        length = math.hypot(x, y)
        return (x / length, y / length) if length > 0.0 else (0.0, 0.0)

    def _in_nest(self, obs: Observation) -> bool:
        """``UpdateState()``: both of its ground sensors over the nest (see the module docstring)."""
        pose = obs.pose
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)
        px, py = pose.x - self._nest_xy[0], pose.y - self._nest_xy[1]
        for bx, by in _NEST_SENSORS:
            x, y = px + c * bx - s * by, py + s * bx + c * by
            if x * x + y * y > self._nest_r2:
                return False
        return True

    def _set_wheels(self, vx: float, vy: float) -> None:
        self._command = self._wheels.twist_from_vector(vx, vy)

    def _shift(self, explore_to_rest: float, rest_to_explore: float) -> None:
        """Move both probabilities, each clipped to [0, 1] (``ProbRange.TruncValue``)."""
        self.explore_to_rest = min(max(self.explore_to_rest + explore_to_rest, 0.0), 1.0)
        self.rest_to_explore = min(max(self.rest_to_explore + rest_to_explore, 0.0), 1.0)

    def _uniform(self) -> float:
        """U[0, 1) (``m_pcRNG->Uniform(ProbRange)``)."""
        if not self._uniforms:
            self._uniforms = self._rng.random(_BLOCK).tolist()
        return self._uniforms.pop()
