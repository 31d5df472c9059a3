"""The spiral paper's protocol between the robots and the MDBSA center (mdbsa_spiral_search.md
sec. IV: robots report their progress near the center, the center assigns regions).

ROS-free message dataclasses; on the graph they travel as the CENTER family
(`swarm_controllers.spiral.codec`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from swarm_sim.protocol import ROBOTS
from swarm_sim.types import Coordinate, RobotId

CENTER = "center"
"""The center's channel."""


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
    x: Coordinate
    """Sender position when sending [m, world frame]; the center ignores reports from out of
    range."""
    y: Coordinate
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
