"""The behaviour API: what every robot controller offers, and the registry that builds one.

A behaviour is a plain object stepped once per tick with the robot's `Observation`; it returns
the `Command` for that tick. Everything it knows comes from the observations (time included:
``obs.stamp_ns`` / ``obs.t``), the scenario and the seeded generator it was built with, so the
controller node and the batch runner, which both build it through `make_behaviour` with
`behaviour_rng`, drive identical objects.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol, runtime_checkable

import numpy as np

from swarm_sim.protocol import CENTER, DEPOT, Server
from swarm_sim.scenario import Scenario
from swarm_sim.types import BehaviourStatus, Command, Observation, RobotId, robot_index


@runtime_checkable
class Behaviour(Protocol):
    """One robot's controller."""

    def step(self, obs: Observation) -> Command:
        """The command answering the tick `obs` describes; messages go out with it."""
        ...

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        """The behaviour's own state and counters (state name, obstacle-avoidance events,
        completed trips), stamped `stamp_ns` (default: the last observation's stamp).
        Read-only: asking does not change the behaviour."""
        ...


BehaviourFactory = Callable[[Scenario, RobotId, np.random.Generator], Behaviour]


def _cpfa(scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> Behaviour:
    from swarm_controllers.cpfa import CpfaBehaviour

    return CpfaBehaviour(scenario, robot, rng)


def _ddsa(scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> Behaviour:
    from swarm_controllers.ddsa import DdsaBehaviour

    return DdsaBehaviour(scenario, robot, rng)


def _mdbsa(distributed: bool) -> BehaviourFactory:
    def factory(scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> Behaviour:
        from swarm_controllers.mdbsa import MdbsaBehaviour

        return MdbsaBehaviour(scenario, robot, rng, distributed=distributed)

    return factory


def _queue(scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> Behaviour:
    from swarm_controllers.queueing import QueueBehaviour

    return QueueBehaviour(scenario, robot, rng)


# Factories import their module lazily, so a behaviour's module loads only when it is used.
_FACTORIES: dict[str, BehaviourFactory] = {
    "cpfa": _cpfa, "ddsa": _ddsa, "mdbsa_c": _mdbsa(False), "mdbsa_d": _mdbsa(True),
    "queue": _queue,
}
CENTER_BEHAVIOURS = ("mdbsa_c", "mdbsa_d")
"""Behaviours that need the center node (region assignment)."""


def register_behaviour(name: str, factory: BehaviourFactory) -> None:
    """Make `name` a valid ``controller.behaviour``; refuses to replace an existing one."""
    if name in _FACTORIES:
        raise ValueError(f"behaviour {name!r} is already registered")
    _FACTORIES[name] = factory


def known_behaviours() -> tuple[str, ...]:
    return tuple(sorted(_FACTORIES))


def make_behaviour(scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> Behaviour:
    """Build the behaviour ``scenario.controller.behaviour`` names for `robot`."""
    robot_index(robot)  # refuse ids that are not robot_<i>
    name = scenario.controller.behaviour
    factory = _FACTORIES.get(name)
    if factory is None:
        raise ValueError(
            f"controller.behaviour: unknown behaviour {name!r} (known: {', '.join(known_behaviours())})"
        )
    return factory(scenario, robot, rng)


def behaviour_rng(seed: int, robot: RobotId) -> np.random.Generator:
    """The generator a robot's behaviour draws from: seeded by (run seed, robot index), so the
    graph and the batch runner, and every process split of the graph, seed it identically."""
    return np.random.default_rng([seed, robot_index(robot)])


def server_channels(scenario: Scenario) -> tuple[str, ...]:
    """The servers (see `swarm_sim.protocol`) a scenario needs, by channel: the center for
    MDBSA, the depot manager when the depot has queues. The graph starts one node each."""
    channels = []
    if scenario.controller.behaviour in CENTER_BEHAVIOURS:
        channels.append(CENTER)
    if scenario.depot.queue != "none":
        channels.append(DEPOT)
    return tuple(channels)


def make_servers(scenario: Scenario) -> dict[str, Server]:
    """The server cores `server_channels` names, built from the scenario."""
    servers: dict[str, Server] = {}
    for channel in server_channels(scenario):
        if channel == CENTER:
            from swarm_controllers.center import CenterServer

            servers[channel] = CenterServer(scenario)
        else:
            from depot_manager.server import DepotServer

            servers[channel] = DepotServer(scenario)
    return servers
