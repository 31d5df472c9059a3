"""The dummy behaviour: turn to the beacon, drive to it, ping the counter server every 2 s."""

from __future__ import annotations

import numpy as np

from dummy_algorithm.messages import Ping
from swarm_msgs_py.types import NS_PER_S, BehaviourStatus, Command, Observation

PING_PERIOD_NS = 2 * NS_PER_S
ARRIVED = 0.5
"""[m] from the beacon."""


class DummyBehaviour:
    def __init__(self, scenario, robot: str, rng: np.random.Generator) -> None:
        self.robot = robot
        self._v = scenario.robots.max_linear_speed
        self._w = scenario.robots.max_angular_speed
        self._state = "seeking"
        self._pings = 0
        self._stamp = 0

    def step(self, obs: Observation) -> Command:
        self._stamp = obs.stamp_ns
        distance, bearing = obs.sensed.beacon
        self._state = "arrived" if distance < ARRIVED else "seeking"
        messages = ()
        if obs.stamp_ns % PING_PERIOD_NS == 0:
            self._pings += 1
            messages = (Ping(obs.stamp_ns, self.robot, distance),)
        if self._state == "arrived":
            return Command(0.0, 0.0, messages)
        angular = float(np.clip(2.0 * bearing, -self._w, self._w))
        linear = self._v if abs(bearing) < 0.5 else 0.0
        return Command(linear, angular, messages)

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        return BehaviourStatus(self.robot, self._stamp if stamp_ns is None else stamp_ns, self._state, 0, 0,
                               (("pings", str(self._pings)),))
