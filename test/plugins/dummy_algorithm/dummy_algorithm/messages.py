"""The dummy's one message, robot -> counter server, and its family on ``/dummy/pings``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

COUNTER = "counter"
"""The counter server's channel."""


@dataclass(frozen=True, slots=True)
class Ping:
    CHANNEL: ClassVar[str] = COUNTER
    stamp_ns: int
    robot: str
    distance: float
    """[m] from the beacon when sent."""
