"""The spiral paper's protocol between the robots and the MDBSA center (mdbsa_spiral_search.md
sec. IV: robots report their progress near the center, the center assigns regions), and between
the two walkers of a region ("A robot can communicate with another robot in the same region").

ROS-free message dataclasses; on the graph they travel as the CENTER and WALKERS families
(`swarm_controllers.spiral.codec`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from swarm_msgs_py.types import Coordinate, RobotId
from swarm_sim.protocol import ROBOTS

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


@dataclass(frozen=True, slots=True)
class WalkProgress:
    """Robot -> robots (peer radio): how far the sender's walk of `region` has got.

    Sec. IV: "A robot can communicate with another robot in the same region"; two walkers of a
    shared region "will eventually meet at some point in their spiral path and complete the
    search in the region" (Fig. 5). A walker sends it every few gaps of progress; the walker
    of the same region in the other direction stops there (`mdbsa.MdbsaBehaviour`), as the
    authors' robots read each other's next point from shared memory
    (``firstSpiralTarget`` / ``secondSpiralTarget`` in ``DSA_controller::ReachSpiralTargets``).
    Receivers other than that walker ignore it.
    """

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    robot: RobotId
    region: int
    direction: int
    """+1: walking from the spiral's start, -1: from its end."""
    s: float
    """The walk's frontier [m of arc length from the spiral's start]."""
