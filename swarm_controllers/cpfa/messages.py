"""The CPFA's one message (ROS-free): the pheromone waypoint robots lay at the nest."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from swarm_msgs_py.types import Coordinate
from swarm_sim.protocol import ROBOTS


@dataclass(frozen=True, slots=True)
class PheromoneMessage:
    """A pheromone waypoint laid at the nest (Hecker & Moses 2015, sec. 2.3).

    x, y: the resource site the waypoint points to [m, world frame]; stamp_ns: when it was laid.
    Receivers compute its decayed strength from the time since `stamp_ns`.
    """

    stamp_ns: int
    x: Coordinate
    y: Coordinate

    CHANNEL: ClassVar[str] = ROBOTS
    """Every robot hears it (`swarm_sim.protocol.channel_of`)."""
