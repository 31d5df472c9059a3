"""The DRTM paper's protocol: robots -> nest server, nest server -> robots (drtm_task_allocation.md).

ROS-free. A robot reports what the nest's ledger needs from it (Sec. 3.1: which robots are in
S_S or S_R, the tokens delivered, every OAE) as `NestReport` events; the nest answers every
tick with `NestState`, everything a robot knows of the nest: F(t) for eq. (2), N_W for eq. (4)
and M_T2 for eq. (5). On the graph they travel as the NEST family (`swarm_controllers.drtm.codec`).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import ClassVar

from swarm_msgs_py.types import RobotId
from swarm_sim.protocol import ROBOTS

NEST = "nest"
"""The nest server's channel."""


class NestEvent(Enum):
    """What a robot tells the nest (Fig. 1's transitions, and OAEs)."""

    LEFT = "left"
    """S_W -> S_S: the robot went foraging; it consumes energy from this tick on."""
    FOUND = "found"
    """S_S -> S_R: the robot captured a food token."""
    DEPOSITED = "deposited"
    """S_R -> S_W: the robot delivered its token to the nest and stopped consuming energy."""
    AVOIDED = "avoided"
    """One obstacle-avoidance event (costs E_a)."""
    RETURNED_EMPTY = "returned_empty"
    """The robot came back to rest without a token (the ARGoS foraging example's unsuccessful
    exploration): it stops consuming energy, nothing is delivered."""
    TOLD_SUCCESSFUL = "told_successful"
    """The robot came to rest and tells the resting robots its last exploration found food (the
    ARGoS foraging example's social rule, which it broadcasts over range-and-bearing)."""
    TOLD_UNSUCCESSFUL = "told_unsuccessful"
    """As TOLD_SUCCESSFUL, for an exploration given up without a find."""


@dataclass(frozen=True, slots=True)
class NestReport:
    """Robot -> nest: `event` happened at tick `stamp_ns`."""

    CHANNEL: ClassVar[str] = NEST
    stamp_ns: int
    robot: RobotId
    event: NestEvent


@dataclass(frozen=True, slots=True)
class NestState:
    """Nest -> every robot, once per tick: the ledger after the reports stamped before `stamp_ns`."""

    CHANNEL: ClassVar[str] = ROBOTS
    stamp_ns: int
    food: float
    """F(t): net food in the nest [tokens] (may be negative)."""
    waiting: int
    """N_W: robots in S_W."""
    recent_oaes: int
    """M_T2: OAEs reported within the last T_2 seconds."""
    total_oaes: int
    """OAEs reported since the start."""
    told_successful: int = 0
    """TOLD_SUCCESSFUL reports applied at this tick (the robots that came to rest in the last)."""
    told_unsuccessful: int = 0
    """TOLD_UNSUCCESSFUL reports applied at this tick."""
