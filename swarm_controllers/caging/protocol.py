"""The caging paper's messages msg<type, origin, destination, payload>, types 0-4 (sec. 3).

One frozen dataclass per type; `TYPE` is the paper's type number, `origin` and `destination`
robot ids. A message the paper sends "to j = 0 .. rho-1, j != i" is one message per
destination; every robot hears every message (the graph's topics, the batch runner's router)
and acts only on those addressed to it. On the graph they travel as the CAGING family
(`swarm_controllers.caging.codec`), one topic per type under ``/caging/``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from swarm_msgs_py.types import Coordinate, RobotId
from swarm_sim.protocol import ROBOTS


@dataclass(frozen=True, slots=True)
class _Message:
    """msg<type, origin, destination, ...>: what every type carries (the type is the class's TYPE)."""

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    """The tick it was sent in [ns]."""
    origin: RobotId
    destination: RobotId


@dataclass(frozen=True, slots=True)
class Recruitment(_Message):
    """Type 0, recruiter -> every other robot (Alg. 3 line 7): a recruiter r* exists; payload
    C_object and the recruiter's trajectory T_r*."""

    TYPE: ClassVar[int] = 0
    object_x: Coordinate
    """C_object when detected [m, world frame]."""
    object_y: Coordinate
    start_x: Coordinate
    """T_r* begins with the recruiter's start p_r*^0 [m, world frame] ..."""
    start_y: Coordinate
    trajectory: tuple[int, ...]
    """... then the indices of the landmarks it reached, in order (`swarm_controllers.caging.landmarks`)."""


@dataclass(frozen=True, slots=True)
class Summon(_Message):
    """Type 1, recruiter -> the robot mu_r*j (Alg. 5 line 7): take your place in the cage."""

    TYPE: ClassVar[int] = 1


@dataclass(frozen=True, slots=True)
class Positioned(_Message):
    """Type 2, a summoned robot -> every other robot (Alg. 4 line 15): I am at my cage position."""

    TYPE: ClassVar[int] = 2


@dataclass(frozen=True, slots=True)
class Oriented(_Message):
    """Type 3, robot -> every other robot (Alg. 6 line 13): I face landmark `leg`."""

    TYPE: ClassVar[int] = 3
    leg: int
    """Which landmark of the transport path (0 = the first). The paper's payload is empty; we
    carry the leg so that no message is ever counted for the wrong landmark."""


@dataclass(frozen=True, slots=True)
class Reached(_Message):
    """Type 4, robot -> every other robot (Alg. 6 line 24): I am at my place p_i+ around
    landmark `leg`."""

    TYPE: ClassVar[int] = 4
    leg: int
    """As in `Oriented`."""


CagingMessage = Recruitment | Summon | Positioned | Oriented | Reached
MESSAGE_TYPES: tuple[type, ...] = (Recruitment, Summon, Positioned, Oriented, Reached)
"""By type number."""
