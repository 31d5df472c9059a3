"""Messages between nodes other than the world: the robots and the servers (generic part).

ROS-free. Each message is a frozen dataclass with a ``stamp_ns`` (the tick it was sent in) and
a ``CHANNEL`` naming who receives it: ``robots`` (every robot controller receives it and keeps
what concerns it) or a server's channel (``depot``, ``center``...). `swarm_sim.messaging`
delivers it one tick later; in the graph over the topics of its message family
(`swarm_msgs_py.records.MessageFamily`), in the batch runner in process. Each paper keeps its
messages in its own protocol module (`depot_manager.protocol`, `swarm_controllers.spiral.protocol`).

Servers are stepped once per tick, after the robots: at tick k a server takes every message
stamped before k and answers with messages stamped k, which the robots see at tick k+1. A
robot's request therefore gets its answer two ticks after it was sent. What a server publishes
besides its messages (its ``state()`` on state topics, what it draws as `Lines` and `Points`)
and the run-trace series read off it are declared with its registry record
(`swarm_sim.outputs.ServerOutputs`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

ROBOTS = "robots"
"""The channel every robot controller receives."""


def channel_of(message: object) -> str:
    """The channel `message` travels on (its class's ``CHANNEL``)."""
    channel = getattr(type(message), "CHANNEL", None)
    if not isinstance(channel, str) or not channel:
        raise TypeError(f"{type(message).__name__} is not a message type (no CHANNEL)")
    return channel


class Server(Protocol):
    """A node core other than the world and the robots, stepped once per tick."""

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[object, ...]:
        """Handle `messages` (stamped before `stamp_ns`, deterministic order); return the
        messages to send, stamped `stamp_ns`."""
        ...

    # Optional, found with getattr:
    #   rejections: swarm_sim.inbound.Rejections -- messages the core refused, by class and reason;
    #   robot_lost(robot, stamp_ns) -> None -- the world declared `robot` dead: free what it held
    #   and refuse its later messages (graph runs only: in batch every robot answers every tick);
    #   state() -> {field: value} -- the values its registry record's state topics carry
    #   (`swarm_msgs_py.server_state.ServerState`), asked after every step.


@dataclass(frozen=True)
class Lines:
    """Polylines a server draws (its node publishes them as LINE_STRIP markers, id = position)."""

    ns: str
    lines: Sequence[np.ndarray]
    """Each (n, 2) [m, world frame]."""
    color: tuple[float, float, float, float]
    """r, g, b, a in [0, 1]."""
    width: float


@dataclass(frozen=True)
class Points:
    """A point set a server draws (one SPHERE_LIST marker, or CUBE_LIST with `cubes`)."""

    ns: str
    id: int
    points: np.ndarray
    """(n, 2) [m, world frame]."""
    color: tuple[float, float, float, float]
    size: float
    """[m]."""
    cubes: bool = False


Drawing = Sequence[Lines | Points]
"""What a server's markers function returns, ROS-free (`swarm_msgs_py.server_state.ServerMarkers`)."""
