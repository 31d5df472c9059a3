"""Messages between nodes other than the world: the robots, the center and the depot manager.

ROS-free. Each message is a frozen dataclass with a ``stamp_ns`` (the tick it was sent in) and
a ``CHANNEL`` naming who receives it; `swarm_sim.messaging` delivers it one tick later, in the
graph over one topic per channel (see `swarm_msgs_py.topics`), in the batch runner in process.

Channels:
- ``robots``: every robot controller receives it and keeps what concerns it (pheromones,
  assignments and grants addressed to it, radio messages from within range).
- ``center``: the MDBSA center (`swarm_controllers.center.CenterServer`).
- ``depot``: the depot manager (`depot_manager.server.DepotServer`).

Servers (center, depot manager) are stepped once per tick, after the robots: at tick k a server
takes every message stamped before k and answers with messages stamped k, which the robots see
at tick k+1. A robot's request therefore gets its answer two ticks after it was sent.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar, Protocol

from swarm_sim.types import PheromoneMessage, RobotId

ROBOTS, CENTER, DEPOT = "robots", "center", "depot"
CHANNELS = (ROBOTS, CENTER, DEPOT)


def channel_of(message: object) -> str:
    """The channel `message` travels on; PheromoneMessage predates this module (robots)."""
    if isinstance(message, PheromoneMessage):
        return ROBOTS
    channel = getattr(type(message), "CHANNEL", None)
    if channel not in CHANNELS:
        raise TypeError(f"{type(message).__name__} is not a message type (no CHANNEL)")
    return channel


class Server(Protocol):
    """A node core other than the world and the robots, stepped once per tick."""

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[object, ...]:
        """Handle `messages` (stamped before `stamp_ns`, deterministic order); return the
        messages to send, stamped `stamp_ns`."""
        ...


# --------------------------------------------------------------------------- center (MDBSA)


@dataclass(frozen=True, slots=True)
class ProgressReport:
    """Robot -> center, sent only while the robot is within the center's range.

    region: the region the robot walked (-1: none yet); s: how far its walk got [m of arc
    length from the spiral's start]; done: its walk is over (finished, or it met its partner)
    and it asks for a new one.
    """

    CHANNEL: ClassVar[str] = CENTER
    stamp_ns: int
    robot: RobotId
    x: float
    """Sender position when sending [m, world frame]; the center ignores reports from out of
    range."""
    y: float
    region: int
    s: float
    done: bool


@dataclass(frozen=True, slots=True)
class RegionAssignment:
    """Center -> robot: walk `region` from arc length `s0` in `direction` up to `stop_s`.

    region -1 means idle: ask again later. Arc lengths [m] are from the spiral's start.
    """

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    robot: RobotId
    region: int
    direction: int
    s0: float
    stop_s: float
    shared: bool


# --------------------------------------------------------------------------- depot manager


@dataclass(frozen=True, slots=True)
class DepotReport:
    """Robot -> depot manager.

    kind ``join``: the robot, carrying, asks to join line `line` at slot `cell` (entry-point
    joining: slot 0 of an entry line; tail joining: the slot behind the tail it found).
    kind ``at``: the robot has reached slot `cell` of `line` (frees the slots behind it).
    kind ``unloaded``: the robot's resource was dropped at its dock.
    """

    CHANNEL: ClassVar[str] = DEPOT
    stamp_ns: int
    robot: RobotId
    kind: str
    line: str = ""
    cell: int = -1


@dataclass(frozen=True, slots=True)
class DepotGrant:
    """Depot manager -> robot: the robot may drive along its route up to slot `cell` of
    `line`. cell -1: a refused join, `reason` says why. last: the robot is the last one
    queued on its entry line (what tail-joining robots ask each other)."""

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    robot: RobotId
    line: str
    cell: int
    last: bool = False
    reason: str = ""


# --------------------------------------------------------------------------- robot radio


@dataclass(frozen=True, slots=True)
class RadioQuery:
    """Robot -> robots within the scenario's radio range: "are you queued, and last?"."""

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    sender: RobotId
    x: float
    """Sender position [m, world frame]: receivers farther than the range drop the message."""
    y: float


@dataclass(frozen=True, slots=True)
class RadioReply:
    """Queued robot -> the asking robot (`to`): where it is queued and whether it is last."""

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    sender: RobotId
    to: RobotId
    x: float
    y: float
    line: str
    cell: int
    last: bool


def within_range(message: RadioQuery | RadioReply, x: float, y: float, radius: float) -> bool:
    """Whether a receiver at (x, y) hears `message`: range-limited robot-to-robot radio."""
    return (message.x - x) ** 2 + (message.y - y) ** 2 <= radius * radius
