"""The behaviour API: what every robot controller offers, and how its generator is seeded.

A behaviour is a plain object stepped once per tick with the robot's `Observation`; it returns
the `Command` for that tick. Everything it knows comes from the observations (time included:
``obs.stamp_ns`` / ``obs.t``), the scenario and the seeded generator it was built with, so the
controller node and the batch runner, which both build it through
`swarm_sim.registry.make_behaviour` with `behaviour_rng`, drive identical objects.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from swarm_msgs_py.types import BehaviourStatus, Command, Observation, RobotId, robot_index


@runtime_checkable
class Behaviour(Protocol):
    """One robot's controller. It may also have a ``finished`` attribute (True once its task is
    over; `swarm_sim.scenario.SimConfig.stop_when_finished`), which its status then reports too
    (``BehaviourStatus.finished``: how the world node learns it on the graph)."""

    def step(self, obs: Observation) -> Command:
        """The command answering the tick `obs` describes; messages go out with it."""
        ...

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        """The behaviour's own state and counters (state name, obstacle-avoidance events,
        completed trips), stamped `stamp_ns` (default: the last observation's stamp).
        Read-only: asking does not change the behaviour."""
        ...


def behaviour_rng(seed: int, robot: RobotId) -> np.random.Generator:
    """The generator a robot's behaviour draws from: seeded by (run seed, robot index), so the
    graph and the batch runner, and every process split of the graph, seed it identically."""
    return np.random.default_rng([seed, robot_index(robot)])
