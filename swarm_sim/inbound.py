"""What a node accepts from the bus: every message is untrusted input (ROS-free).

A node checks each message it decodes before its core sees it (`Inbound.admit`): every field
that names a robot (annotated `swarm_sim.types.RobotId`) must name a robot of this run, and the
message must be stamped for a tick the node can still take (`swarm_sim.messaging`: a message
sent at tick k is taken at tick k+1). What fails is dropped and counted in `Rejections` by
(where, reason); the node logs the first of each kind and then every 10th, 100th, ... one
(rate limiting without a wall clock), and publishes the counts on ``/diagnostics`` so they reach
the bag and the run's summary (``rejected_messages``).

Cores keep their own invariants too (a grant naming a slot the layout lacks, a report the depot
cannot apply): they count what they refuse in a `Rejections` of their own, keyed by the message
class, which their node merges into what it publishes.
"""

from __future__ import annotations

import dataclasses
import typing
from collections import Counter
from collections.abc import Callable, Iterable
from enum import Enum
from functools import cache

from swarm_sim.types import ROBOT_ID


class Reason(str, Enum):
    """Why a message was dropped."""

    MALFORMED = "malformed"
    """It does not decode (unknown kind or field, wrong type, non-finite number, bad CDR)."""
    UNKNOWN_ROBOT = "unknown robot"
    """It names a robot this run does not have."""
    WRONG_TICK = "wrong tick"
    """It is stamped for a tick other than the one it can be taken at."""
    LATE = "late"
    """A command for a tick the world has already closed: usually a slow robot's answer after
    its tick counted as stale (a forged one looks the same); dropped, as lockstep requires, and
    counted apart from other ticks' stamps."""
    DEAD = "declared dead"
    """Its sender was declared dead by the world (`swarm_sim.nodes.lockstep`)."""
    UNKNOWN_NODE = "unknown node"
    """It comes from, or is addressed to, a node this run does not have."""
    REFUSED = "refused"
    """It decoded and named known robots, but the core could not apply it."""


class Rejections:
    """Counts of dropped messages by (where, reason): ``where`` is a topic for what a node
    refuses, a message class for what a core refuses."""

    def __init__(self) -> None:
        self.counts: Counter[tuple[str, str]] = Counter()
        self.details: dict[tuple[str, str], str] = {}
        """The last detail given for each kind (for the log)."""

    def add(self, where: str, reason: Reason | str, detail: str = "") -> bool:
        """Count one; True when it is worth a log line (the 1st, 10th, 100th, ... of its kind)."""
        key = (where, reason.value if isinstance(reason, Reason) else str(reason))
        self.counts[key] += 1
        self.details[key] = detail
        n = self.counts[key]
        return n == 1 or (n % 10 == 0 and str(n).rstrip("0") == "1")

    @property
    def total(self) -> int:
        return sum(self.counts.values())

    def log_line(self, where: str, reason: Reason | str) -> str:
        key = (where, reason.value if isinstance(reason, Reason) else str(reason))
        n = self.counts[key]
        detail = self.details.get(key, "")
        return f"dropping a message on {where} ({key[1]}{': ' + detail if detail else ''}); {n} so far"


def total(*sources: Rejections | None) -> int:
    """Messages dropped by several `Rejections` together: counts only grow, so a node that
    publishes its `merged` counts on change compares this number every tick instead of the
    merged dicts (a dict built per robot per tick in a 112-robot controller process)."""
    return sum(s.total for s in sources if s is not None)


def merged(*sources: Rejections | None) -> dict[tuple[str, str], int]:
    """The counts of several `Rejections` (a node's and its cores') added up."""
    out: Counter[tuple[str, str]] = Counter()
    for s in sources:
        if s is not None:
            out.update(s.counts)
    return dict(sorted(out.items()))


@cache
def robot_fields(cls: type) -> tuple[str, ...]:
    """The fields of message dataclass `cls` that name a robot (annotated `RobotId`)."""
    if not dataclasses.is_dataclass(cls):
        return ()
    hints = typing.get_type_hints(cls, include_extras=True)
    return tuple(
        f.name for f in dataclasses.fields(cls)
        if typing.get_origin(hints.get(f.name)) is typing.Annotated and ROBOT_ID in hints[f.name].__metadata__
    )


class Inbound:
    """A node's check of the messages it decodes (see the module docstring).

    `now_ns` is the latest tick the node has seen (its last observation or ``/clock``);
    `released_ns` the tick it last took messages at. A message stamped s is admitted when
    ``released_ns - dt <= s <= now_ns + dt``: a sender may be one tick ahead of a receiver that
    has not yet seen the new tick, and a message that arrives a tick late is still taken (a
    forged one stamped long ago or in the future is not).
    """

    def __init__(self, robots: Iterable[str], dt_ns: int, rejections: Rejections,
                 log: Callable[[str], None]) -> None:
        self.robots = frozenset(robots)
        self.dt_ns = dt_ns
        self.rejections = rejections
        self._log = log
        self.now_ns = 0
        self.released_ns = 0

    def reject(self, where: str, reason: Reason, detail: str = "") -> None:
        if self.rejections.add(where, reason, detail):
            self._log(self.rejections.log_line(where, reason))

    def admit(self, where: str, message: object) -> bool:
        """Whether `message` (decoded from topic `where`) may reach the core; counts it if not."""
        for name in robot_fields(type(message)):
            robot = getattr(message, name)
            if robot not in self.robots:
                self.reject(where, Reason.UNKNOWN_ROBOT, f"{type(message).__name__}.{name} = {robot[:40]!r}")
                return False
        stamp = getattr(message, "stamp_ns", None)
        if stamp is not None and not self.released_ns - self.dt_ns <= stamp <= self.now_ns + self.dt_ns:
            self.reject(where, Reason.WRONG_TICK, f"{type(message).__name__} stamped {stamp} ns at tick {self.now_ns} ns")
            return False
        return True

    def post_all(self, where: str, family, data: bytes, post: Callable[[object], None]) -> int:
        """A raw subscription's body: decode `data` with `family`, admit each message, `post`
        those admitted. Returns how many were posted."""
        try:
            messages = family.decode(data)
        except ValueError as exc:
            self.reject(where, Reason.MALFORMED, str(exc)[:200])
            return 0
        posted = 0
        for m in messages:
            if self.admit(where, m):
                post(m)
                posted += 1
        return posted
