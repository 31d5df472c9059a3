"""What a node accepts from the bus: every message is untrusted input (ROS-free).

Every subscription of every node hands its bytes to one guard, `Inbound.decode`, before any
other work: a message longer than its topic's cap (`Bounds`) is refused unread (a 19 MB array
took 1.5 s to decode in every robot node), then it is decoded, and whatever the decoder raises
is a refusal, never an exception in the node's callback. A decoded message is then checked before
its core sees it: a message of another node (`Inbound.admit`) must name robots of this run in
every field annotated `swarm_msgs_py.types.RobotId`, hold coordinates within the arena in every field
annotated `swarm_msgs_py.types.Coordinate`, and be stamped for a tick the node can still take
(`swarm_sim.messaging`: a message sent at tick k is taken at tick k+1); an observation from the
world (`Inbound.sense_guard`) must be stamped on a tick of the run and hold finite numbers within
the arena and the robots' limits (`Bounds`). Numbers are checked before a core computes with
them: a 1e308 coordinate made a core raise OverflowError.

What fails is dropped and counted in `Rejections` by (where, reason); the node logs the first of
each kind and then every 10th, 100th, ... one (rate limiting without a wall clock), and publishes
the counts on ``/diagnostics`` so they reach the bag and the run's summary
(``rejected_messages``).

Cores keep their own invariants too (a grant naming a slot the layout lacks, a report the depot
cannot apply): they count what they refuse in a `Rejections` of their own, keyed by the message
class, which their node merges into what it publishes.
"""

from __future__ import annotations

import dataclasses
import math
import typing
from collections import Counter, deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from enum import Enum
from functools import cache
from typing import Any

import numpy as np

from swarm_msgs_py.types import COORDINATE, ROBOT_ID


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
    TOO_BIG = "too big"
    """It is longer than its topic's cap (`Bounds`): refused before it was decoded."""
    OUT_OF_BOUNDS = "out of bounds"
    """A number in it is not finite, or beyond the arena or the robots' limits (`Bounds`)."""
    UNAUTHENTICATED = "unauthenticated"
    """It lacks the run's tag, or its tag is wrong (`swarm_msgs_py.auth`): not sent by this run."""
    REPLAYED = "replayed"
    """The very bytes of a message already taken: a copy, replayed from the bus."""
    FOREIGN = "foreign publisher"
    """A publisher that is not one of the run's nodes was seen on the topic (`swarm_sim.nodes.taint`)."""


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
def marked_fields(cls: type, mark: object) -> tuple[str, ...]:
    """The fields of message dataclass `cls` annotated with `mark` (``Annotated[X, mark]``)."""
    if not dataclasses.is_dataclass(cls):
        return ()
    hints = typing.get_type_hints(cls, include_extras=True)
    return tuple(
        f.name for f in dataclasses.fields(cls)
        if typing.get_origin(hints.get(f.name)) is typing.Annotated and mark in hints[f.name].__metadata__
    )


def robot_fields(cls: type) -> tuple[str, ...]:
    """The fields of message dataclass `cls` that name a robot (annotated `RobotId`)."""
    return marked_fields(cls, ROBOT_ID)


COORDINATE_MARGIN = 1.0
"""How far beyond the arena's walls a coordinate may lie [m] (a robot pushed against a wall, a
rounding): farther is no place of this run."""
SPEED_SLACK = 2.0
"""Measured speeds may exceed a robot's limits when others push it (0.181 m/s measured at a
0.16 m/s limit): up to `SPEED_SLACK` times the limit plus 0.5 m/s or 2 pi rad/s passes."""


@dataclass(frozen=True)
class Bounds:
    """What a message of a run can physically hold, from its scenario."""

    coordinate: float
    """|x|, |y| of any position [m, world frame]: the arena's half side, its walls and
    `COORDINATE_MARGIN`; every other number a sense holds (intensities, ids) is smaller."""
    speed: float
    """|forward speed| in odometry [m/s]."""
    turn_rate: float
    """|turn rate| in odometry [rad/s]."""
    dt_ns: int
    end_ns: int
    """The run's last tick [ns]: observations are stamped on the ticks 0, dt, ..., end."""
    rays: int
    """Ranges in a scan."""
    message_bytes: int
    """Cap on a message of another node (a family's array of one tick) [bytes]: 64 KiB plus
    2 KiB per robot (measured: at most 0.6 KiB per robot per tick, caging's type 4 messages)."""
    sense_bytes: int
    """Cap on an observation from the world [bytes]: 64 KiB plus 64 bytes per resource and per
    robot (a PoseArray pose is 56) and 4 per scan ray."""

    @classmethod
    def of(cls, scenario: Any) -> Bounds:
        robots, arena = scenario.robots, scenario.arena
        return cls(
            coordinate=arena.size / 2 + arena.wall_thickness + COORDINATE_MARGIN,
            speed=SPEED_SLACK * robots.max_linear_speed + 0.5,
            turn_rate=SPEED_SLACK * robots.max_angular_speed + 2 * math.pi,
            dt_ns=scenario.dt_ns,
            end_ns=scenario.ticks * scenario.dt_ns,
            rays=scenario.sensors.scan.rays,
            message_bytes=65536 + 2048 * robots.count,
            sense_bytes=65536 + 64 * (scenario.resources.count + robots.count) + 4 * scenario.sensors.scan.rays,
        )


def within(value: Any, limit: float) -> bool:
    """Whether every float in `value` (nested tuples, lists, dataclasses, float arrays) is finite
    and within +-`limit`; ints, bools and strings pass. (Type tests by identity first: it runs on
    every observation of every robot.)"""
    t = type(value)
    if t is float:
        return -limit <= value <= limit  # NaN fails
    if t is bool or t is int or t is str or value is None:
        return True
    if t is tuple or t is list or isinstance(value, tuple):  # NamedTuples too
        for v in value:
            if not within(v, limit):
                return False
        return True
    if t is np.ndarray:
        if value.dtype.kind != "f" or value.size == 0:
            return True
        return bool(-limit <= value.min() and value.max() <= limit)  # NaN fails
    if isinstance(value, float):  # numpy scalars
        return -limit <= value <= limit
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return all(within(getattr(value, f.name), limit) for f in dataclasses.fields(value))
    return True


class Inbound:
    """A node's check of the messages it decodes (see the module docstring).

    `now_ns` is the latest tick the node has seen (its last observation or ``/clock``);
    `released_ns` the tick it last took messages at. A message stamped s is admitted when
    ``released_ns - dt <= s <= now_ns + dt``: a sender may be one tick ahead of a receiver that
    has not yet seen the new tick, and a message that arrives a tick late is still taken (a
    forged one stamped long ago or in the future is not).
    """

    def __init__(self, robots: Iterable[str], dt_ns: int, rejections: Rejections,
                 log: Callable[[str], None], bounds: Bounds | None = None) -> None:
        """`bounds`: the run's (`Bounds.of`); None checks no numbers and caps no size (tests of
        the other rules)."""
        self.robots = frozenset(robots)
        self.dt_ns = dt_ns
        self.rejections = rejections
        self._log = log
        self.bounds = bounds
        self.now_ns = 0
        self.released_ns = 0
        self.unique = False
        """Refuse a message's bytes seen before (`post_all`): set where messages carry the run's
        tag (`swarm_msgs_py.auth`), so a copy of one cannot be replayed within its tick window."""
        self._seen: set[int] = set()
        """Hashes of the bytes of the messages taken lately (`forget_before` prunes them)."""
        self._seen_order: deque[tuple[int, int]] = deque()
        """(the tick a message was taken at, its hash), oldest first."""

    def forget_before(self, stamp_ns: int) -> None:
        """Drop the replay memory of ticks before `stamp_ns` (their stamps are out of the window)."""
        order, seen = self._seen_order, self._seen
        while order and order[0][0] < stamp_ns:
            seen.discard(order.popleft()[1])

    def reject(self, where: str, reason: Reason, detail: str = "") -> None:
        if self.rejections.add(where, reason, detail):
            self._log(self.rejections.log_line(where, reason))

    def decode(self, where: str, decode: Callable[[bytes], Any], data: bytes, max_bytes: int | None) -> Any:
        """The guard every subscription's bytes pass first: None (counted) if `data` is longer than
        `max_bytes` or `decode` raises anything at all, else what `decode` returns."""
        if max_bytes is not None and len(data) > max_bytes:
            self.reject(where, Reason.TOO_BIG, f"{len(data)} bytes (at most {max_bytes})")
            return None
        try:
            return decode(data)
        except Exception as exc:  # noqa: BLE001 - whatever a message makes a decoder raise, the node lives
            # A decoder's error may say why in its `reason` (`swarm_msgs_py.auth.Unauthenticated`).
            self.reject(where, getattr(exc, "reason", Reason.MALFORMED), str(exc)[:200])
            return None

    def sense_guard(self, where: str, decode: Callable[[bytes], Any], kind: str,
                    deliver: Callable[[Any], None], refused: Callable[[], None] = lambda: None,
                    ) -> Callable[[bytes], None]:
        """One observation topic's whole guard as one subscription callback: `deliver(decoded)`
        (stamp, value, ...) if the message is within `Bounds.sense_bytes`, decodable, its numbers
        finite and within bounds (`kind`: ``odometry``: the pose within the arena, speeds within
        the robot's limits, stamped on a tick of the run; ``scan``: one range per ray, none NaN or
        negative but -inf, REP 117's too close; ``value``: every float within the coordinate
        bound, `within`), else count it and call `refused()`. Only odometry's stamp is checked: a
        controller steps when all its topics carry one stamp, so that one is the tick's. All
        inlined, one closure per kind: every robot runs it on every observation (450 times a tick
        in a 112-robot controller process), and every comparison fails for NaN."""
        b = self.bounds
        reject = self.reject
        if b is None:
            def unchecked(data: bytes) -> None:
                deliver(decode(data))

            return unchecked
        cap, c, end, dt = b.sense_bytes, b.coordinate, b.end_ns, b.dt_ns
        speed, turn, rays = b.speed, b.turn_rate, b.rays
        too_big, malformed, out, wrong = Reason.TOO_BIG, Reason.MALFORMED, Reason.OUT_OF_BOUNDS, Reason.WRONG_TICK

        def failed(data: bytes, exc: Exception | None = None) -> None:
            if exc is None:
                reject(where, too_big, f"{len(data)} bytes (at most {cap})")
            else:  # a decoder may raise anything: the node lives
                reject(where, getattr(exc, "reason", malformed), str(exc)[:200])
            refused()

        def bad(reason: Reason, stamp: int) -> None:
            reject(where, reason, f"stamped {stamp} ns: no tick of this run" if reason is wrong
                   else "a number not finite, or beyond the arena or the robot's limits")
            refused()

        if kind == "odometry":
            def guarded(data: bytes) -> None:
                if len(data) > cap:
                    return failed(data)
                try:
                    d = decode(data)
                except Exception as exc:  # noqa: BLE001
                    return failed(data, exc)
                stamp, pose, v, w = d
                if not (-c <= pose.x <= c and -c <= pose.y <= c and -4.0 <= pose.yaw <= 4.0
                        and -speed <= v <= speed and -turn <= w <= turn):
                    return bad(out, stamp)
                if not (0 <= stamp <= end and stamp % dt == 0):
                    return bad(wrong, stamp)
                deliver(d)
        elif kind == "scan":
            neg_inf, smallest = -np.inf, np.minimum.reduce

            def guarded(data: bytes) -> None:
                if len(data) > cap:
                    return failed(data)
                try:
                    d = decode(data)
                except Exception as exc:  # noqa: BLE001
                    return failed(data, exc)
                ranges = d[1]
                if len(ranges) != rays or not (smallest(ranges) >= 0.0 or ((ranges >= 0.0) | (ranges == neg_inf)).all()):
                    return bad(out, d[0])
                deliver(d)
        else:
            def guarded(data: bytes) -> None:
                if len(data) > cap:
                    return failed(data)
                try:
                    d = decode(data)
                except Exception as exc:  # noqa: BLE001
                    return failed(data, exc)
                value = d[1]
                if type(value) is not bool and not within(value, c):
                    return bad(out, d[0])
                deliver(d)

        return guarded

    def admit(self, where: str, message: object) -> bool:
        """Whether `message` (decoded from topic `where`) may reach the core; counts it if not."""
        cls = type(message)
        for name in robot_fields(cls):
            robot = getattr(message, name)
            if robot not in self.robots:
                self.reject(where, Reason.UNKNOWN_ROBOT, f"{cls.__name__}.{name} = {robot[:40]!r}")
                return False
        if self.bounds is not None:
            c = self.bounds.coordinate
            for name in marked_fields(cls, COORDINATE):
                if not -c <= getattr(message, name) <= c:
                    self.reject(where, Reason.OUT_OF_BOUNDS, f"{cls.__name__}.{name} = {getattr(message, name):.3g} m")
                    return False
        stamp = getattr(message, "stamp_ns", None)
        if stamp is not None and not self.released_ns - self.dt_ns <= stamp <= self.now_ns + self.dt_ns:
            self.reject(where, Reason.WRONG_TICK, f"{type(message).__name__} stamped {stamp} ns at tick {self.now_ns} ns")
            return False
        return True

    def post_all(self, where: str, family, data: bytes, post: Callable[[object], None],
                 decode: Callable[[bytes], Any] | None = None) -> int:
        """A raw subscription's body: decode `data` with `decode` (default `family.decode`; the
        guard: capped at `Bounds.message_bytes`), admit each message, `post` those admitted.
        Returns how many were posted. With `unique` on, the very bytes of a message taken within
        the last two ticks are refused as a replay (ours send each array once)."""
        messages = self.decode(where, decode or family.decode, data, self.bounds and self.bounds.message_bytes)
        if messages is None:
            return 0
        if self.unique:
            digest = hash(data)
            if digest in self._seen:
                self.reject(where, Reason.REPLAYED, "the same bytes again (a replay of a message of this run?)")
                return 0
            self._seen.add(digest)
            self._seen_order.append((self.now_ns, digest))
        posted = 0
        for m in messages:
            if self.admit(where, m):
                post(m)
                posted += 1
        return posted
