"""The queue paper's protocol: robots <-> depot manager, and the robots' range-limited radio
(queue_depot_traffic.md secs. III-V).

ROS-free message dataclasses with enums for kinds and refusal reasons; on the graph they travel
as the DEPOT and RADIO families (`depot_manager.codec`), the enums as their values.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import ClassVar

from swarm_msgs_py.types import Coordinate, RobotId
from swarm_sim.protocol import ROBOTS

DEPOT = "depot"
"""The depot manager's channel."""


class ReportKind(Enum):
    JOIN = "join"
    """The robot, carrying, asks to join line `line` at slot `cell` (entry-point joining: slot 0
    of an entry line; tail joining: the slot behind the tail it found)."""
    AT = "at"
    """The robot has reached slot `cell` of `line` (frees the slots behind it)."""
    UNLOADED = "unloaded"
    """The robot's resource was dropped at its dock."""


class Refusal(Enum):
    """Why the depot manager refused a join (NONE: it is a grant)."""

    NONE = ""
    UNKNOWN_LINE = "unknown line"
    ALREADY_INSIDE = "already inside"
    UNKNOWN_CELL = "unknown cell"
    OCCUPIED = "occupied"
    NOT_BEHIND_TAIL = "not behind the tail"
    KEEP_CLEAR = "keep clear"


@dataclass(frozen=True, slots=True)
class DepotReport:
    """Robot -> depot manager.

    `kind` says what happened (`ReportKind`).
    """

    CHANNEL: ClassVar[str] = DEPOT
    stamp_ns: int
    robot: RobotId
    kind: ReportKind
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
    reason: Refusal = Refusal.NONE


@dataclass(frozen=True, slots=True)
class RadioQuery:
    """Robot -> robots within the scenario's radio range: "are you queued, and last?"."""

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    sender: RobotId
    x: Coordinate
    """Sender position [m, world frame]: receivers farther than the range drop the message."""
    y: Coordinate


@dataclass(frozen=True, slots=True)
class RadioReply:
    """Queued robot -> the asking robot (`to`): where it is queued and whether it is last."""

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    sender: RobotId
    to: RobotId
    x: Coordinate
    y: Coordinate
    line: str
    cell: int
    last: bool


def within_range(message: RadioQuery | RadioReply, x: float, y: float, radius: float) -> bool:
    """Whether a receiver at (x, y) hears `message`: range-limited robot-to-robot radio."""
    return (message.x - x) ** 2 + (message.y - y) ** 2 <= radius * radius
