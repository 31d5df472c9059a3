"""diagnostic_msgs/msg/DiagnosticArray: a generic codec plus the typed payloads built on it.

DiagnosticArray carries named key/value string pairs, which `ros2 topic echo` shows readably
and which hold our irregular records without custom interfaces. Floats travel as ``repr()``
strings and ints as ``str()`` so every value round-trips exactly. header.frame_id is empty.

Typed payloads (one status per record, level OK):

- `/world/events` (`encode_events`): name ``pickup`` or ``drop``, hardware_id = robot,
  message = a human-readable summary, values ``resource``, ``zone`` (drop only), ``x``, ``y``,
  ``stamp_ns`` (the event's own stamp; the array's header stamp is the publishing tick); or
  name ``node_down`` (level ERROR), hardware_id = the robot or server channel, values ``kind``
  (``robot``/``server``), ``ticks`` (missed in a row), ``stamp_ns``.
- `/world/robot_stats` (`encode_robot_stats`): name = hardware_id = robot, values
  ``collision_time_s`` (body contact), ``pickups``, ``deliveries``, ``clamped_commands``,
  ``stale_ticks``, ``avoidance_time_s`` (proximity ring saw something ahead).
- `/<robot>/status` (`encode_status`): one status, name = hardware_id = robot,
  message = state, values ``state``, ``obstacle_avoidance_events``, ``trips``, ``finished`` =
  ``true`` once the behaviour's task is over (left out before), then the behaviour's extra pairs
  in order.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import NamedTuple

from swarm_msgs_py.cdr import Reader, Writer, codec
from swarm_msgs_py.types import NODE_KINDS, BehaviourStatus, DropEvent, NodeDownEvent, PickupEvent, RobotId, RobotStats

TYPE_NAME = "diagnostic_msgs/msg/DiagnosticArray"

OK, WARN, ERROR, STALE = 0, 1, 2, 3
"""diagnostic_msgs/msg/DiagnosticStatus levels."""

_MIN_STATUS_SIZE = 1 + 3 * 5 + 4
"""level, three empty strings, values count (padding aside): bounds a status count."""
MAX_STATUSES = 65536
"""The most statuses an array may hold (ours: one per robot, event or message of a tick)."""
MAX_VALUES = 4096
"""The most key/value pairs a status may hold (ours: a depot's owned slots at most)."""


class Status(NamedTuple):
    """One diagnostic_msgs/msg/DiagnosticStatus."""

    level: int
    name: str
    message: str = ""
    hardware_id: str = ""
    values: tuple[tuple[str, str], ...] = ()


class DiagnosticsData(NamedTuple):
    stamp_ns: int
    statuses: tuple[Status, ...]


# --------------------------------------------------------------------------- generic


@codec(TYPE_NAME)
def encode_diagnostics(
    stamp_ns: int,
    statuses: Sequence[tuple[int, str, str, str, Sequence[tuple[str, str]]]],
) -> bytes:
    """`statuses`: (level, name, message, hardware_id, [(key, value), ...]) each."""
    w = Writer()
    w.header(stamp_ns, "")
    w.u32(len(statuses))
    for level, name, message, hardware_id, values in statuses:
        w.u8(level)
        w.string(name)
        w.string(message)
        w.string(hardware_id)
        w.u32(len(values))
        for key, value in values:
            w.string(key)
            w.string(value)
    return w.message()


@codec(TYPE_NAME)
def decode_diagnostics(data: bytes) -> DiagnosticsData:
    r = Reader(data)
    stamp_ns, _ = r.header()
    statuses = []
    count = r.sequence_length(_MIN_STATUS_SIZE)
    if count > MAX_STATUSES:  # refused before any status is read
        raise ValueError(f"{count} statuses (at most {MAX_STATUSES})")
    for _ in range(count):
        level = r.u8()
        name, message, hardware_id = r.string(), r.string(), r.string()
        n = r.sequence_length(10)
        if n > MAX_VALUES:
            raise ValueError(f"status {name[:40]!r}: {n} values (at most {MAX_VALUES})")
        values = tuple((r.string(), r.string()) for _ in range(n))
        statuses.append(Status(level, name, message, hardware_id, values))
    return DiagnosticsData(stamp_ns, tuple(statuses))


def count(text: str, key: str) -> int:
    """A counter's text -> its value: a decimal int in 0..2**63-1, else a ValueError naming `key`
    (a recorded 10**39 once reached numpy and crashed the plots)."""
    if not (text.isascii() and text.isdigit()) or len(text) > 19 or int(text) >= 2**63:
        raise ValueError(f"{key}: expected a count in 0..2**63-1, got {text[:40]!r}")
    return int(text)


def finite(text: str, key: str) -> float:
    """A float's text -> its value, refused unless finite."""
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{key}: expected a number, got {text[:40]!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise ValueError(f"{key}: expected a finite number, got {text[:40]!r}")
    return value


def _fields(status: Status, expected: Sequence[str], what: str) -> dict[str, str]:
    keys = [k for k, _ in status.values]
    if sorted(keys) != sorted(expected):
        raise ValueError(f"{what} {status.name!r}: keys {keys}, expected {list(expected)}")
    return dict(status.values)


# --------------------------------------------------------------------------- /world/events

_PICKUP_KEYS = ("resource", "x", "y", "stamp_ns")
_DROP_KEYS = ("resource", "zone", "x", "y", "stamp_ns")
_DOWN_KEYS = ("kind", "ticks", "stamp_ns")

WorldEvent = PickupEvent | DropEvent | NodeDownEvent


def _event_status(event: WorldEvent) -> Status:
    if isinstance(event, NodeDownEvent):
        return Status(
            ERROR, "node_down", f"{event.kind} {event.node} declared dead after {event.ticks} missed ticks",
            event.node, (("kind", event.kind), ("ticks", str(int(event.ticks))), ("stamp_ns", str(int(event.stamp_ns)))),
        )  # fmt: skip
    x, y = repr(float(event.x)), repr(float(event.y))
    resource, stamp = str(int(event.resource)), str(int(event.stamp_ns))
    if isinstance(event, PickupEvent):
        return Status(
            OK, "pickup", f"{event.robot} picked up resource {resource}", event.robot,
            (("resource", resource), ("x", x), ("y", y), ("stamp_ns", stamp)),
        )  # fmt: skip
    if isinstance(event, DropEvent):
        return Status(
            OK, "drop", f"{event.robot} delivered resource {resource} to {event.zone}",
            event.robot,
            (("resource", resource), ("zone", event.zone), ("x", x), ("y", y), ("stamp_ns", stamp)),
        )  # fmt: skip
    raise ValueError(f"not a world event: {event!r}")


@codec(f"{TYPE_NAME} (world events)")
def encode_events(stamp_ns: int, events: Iterable[WorldEvent]) -> bytes:
    """All events of one tick in one array, in the order given."""
    return encode_diagnostics(stamp_ns, [_event_status(e) for e in events])


@codec(f"{TYPE_NAME} (world events)")
def decode_events(data: bytes) -> tuple[int, tuple[WorldEvent, ...]]:
    """-> (the array's stamp [ns], the events in message order)."""
    stamp_ns, statuses = decode_diagnostics(data)
    events: list[WorldEvent] = []
    for s in statuses:
        if s.name == "pickup":
            f = _fields(s, _PICKUP_KEYS, "event")
            events.append(
                PickupEvent(
                    s.hardware_id, count(f["stamp_ns"], "stamp_ns"), count(f["resource"], "resource"),
                    finite(f["x"], "x"), finite(f["y"], "y"),
                )  # fmt: skip
            )
        elif s.name == "drop":
            f = _fields(s, _DROP_KEYS, "event")
            events.append(
                DropEvent(
                    s.hardware_id, count(f["stamp_ns"], "stamp_ns"), count(f["resource"], "resource"), f["zone"],
                    finite(f["x"], "x"), finite(f["y"], "y"),
                )  # fmt: skip
            )
        elif s.name == "node_down":
            f = _fields(s, _DOWN_KEYS, "event")
            if f["kind"] not in NODE_KINDS:
                raise ValueError(f"event node_down: kind {f['kind']!r} not one of {NODE_KINDS}")
            events.append(NodeDownEvent(s.hardware_id, count(f["stamp_ns"], "stamp_ns"), f["kind"],
                                        count(f["ticks"], "ticks")))
        else:
            raise ValueError(f"unknown event {s.name!r} (expected 'pickup', 'drop' or 'node_down')")
    return stamp_ns, tuple(events)


# --------------------------------------------------------------------------- /world/robot_stats

_STATS_KEYS = ("collision_time_s", "pickups", "deliveries", "clamped_commands", "stale_ticks",
               "avoidance_time_s")


@codec(f"{TYPE_NAME} (robot stats)")
def encode_robot_stats(stamp_ns: int, stats: Mapping[RobotId, RobotStats]) -> bytes:
    """One status per robot, in the mapping's order."""
    return encode_diagnostics(
        stamp_ns,
        [
            Status(
                OK, robot, "", robot,
                (
                    ("collision_time_s", repr(float(s.collision_time_s))),
                    ("pickups", str(int(s.pickups))),
                    ("deliveries", str(int(s.deliveries))),
                    ("clamped_commands", str(int(s.clamped_commands))),
                    ("stale_ticks", str(int(s.stale_ticks))),
                    ("avoidance_time_s", repr(float(s.avoidance_time_s))),
                ),
            )  # fmt: skip
            for robot, s in stats.items()
        ],
    )


@codec(f"{TYPE_NAME} (robot stats)")
def decode_robot_stats(data: bytes) -> tuple[int, dict[RobotId, RobotStats]]:
    """-> (stamp [ns], stats by robot in message order)."""
    stamp_ns, statuses = decode_diagnostics(data)
    out: dict[RobotId, RobotStats] = {}
    for s in statuses:
        # Bags recorded before avoidance_time_s existed (issue 11) lack it: 0.0, not a refusal.
        old = "avoidance_time_s" not in (k for k, _ in s.values)
        f = _fields(s, _STATS_KEYS[:-1] if old else _STATS_KEYS, "robot")
        if old:
            f["avoidance_time_s"] = "0.0"
        if s.name in out:
            raise ValueError(f"robot {s.name!r} appears twice")
        out[s.name] = RobotStats(
            finite(f["collision_time_s"], "collision_time_s"), count(f["pickups"], "pickups"),
            count(f["deliveries"], "deliveries"), count(f["clamped_commands"], "clamped_commands"),
            count(f["stale_ticks"], "stale_ticks"), finite(f["avoidance_time_s"], "avoidance_time_s"),
        )  # fmt: skip
    return stamp_ns, out


# --------------------------------------------------------------------------- /<robot>/status

_BEHAVIOUR_KEYS = ("state", "obstacle_avoidance_events", "trips")
_FINISHED = ("finished", "true")
"""The fourth pair of a finished behaviour's status (absent otherwise, so the bytes of every
other status are what they were before the flag existed)."""


@codec(f"{TYPE_NAME} (behaviour status)")
def encode_status(status: BehaviourStatus) -> bytes:
    values = (
        ("state", status.state),
        ("obstacle_avoidance_events", str(int(status.obstacle_avoidance_events))),
        ("trips", str(int(status.trips))),
        *((_FINISHED,) if status.finished else ()),
        *((str(k), str(v)) for k, v in status.extra),
    )
    return encode_diagnostics(
        status.stamp_ns, [Status(OK, status.robot, status.state, status.robot, values)]
    )


@codec(f"{TYPE_NAME} (behaviour status)")
def decode_status(data: bytes) -> BehaviourStatus:
    stamp_ns, statuses = decode_diagnostics(data)
    if len(statuses) != 1:
        raise ValueError(f"expected one status, got {len(statuses)}")
    s = statuses[0]
    keys = tuple(k for k, _ in s.values[:3])
    if keys != _BEHAVIOUR_KEYS:
        raise ValueError(f"status {s.name!r}: leading keys {keys}, expected {_BEHAVIOUR_KEYS}")
    (_, state), (_, avoid), (_, trips) = s.values[:3]
    finished = s.values[3:4] == (_FINISHED,)
    return BehaviourStatus(s.name, stamp_ns, state, count(avoid, "obstacle_avoidance_events"), count(trips, "trips"),
                           s.values[3 + finished:], finished)


# --------------------------------------------------------------------------- /diagnostics

_SEP = " | "


@codec(f"{TYPE_NAME} (rejected messages)")
def encode_rejections(stamp_ns: int, node: str, counts: Mapping[tuple[str, str], int]) -> bytes:
    """One status per node (name = hardware_id = the node), level WARN once it has dropped
    anything; values ``<topic or message class> | <reason>`` = the count so far."""
    total = sum(counts.values())
    values = tuple((f"{where}{_SEP}{reason}", str(int(n))) for (where, reason), n in counts.items())
    return encode_diagnostics(
        stamp_ns, [Status(WARN if total else OK, node, f"{total} messages rejected", node, values)]
    )


@codec(f"{TYPE_NAME} (rejected messages)")
def decode_rejections(data: bytes) -> tuple[int, dict[str, dict[tuple[str, str], int]]]:
    """-> (stamp [ns], per node its counts by (where, reason))."""
    stamp_ns, statuses = decode_diagnostics(data)
    out: dict[str, dict[tuple[str, str], int]] = {}
    for s in statuses:
        counts: dict[tuple[str, str], int] = {}
        for key, value in s.values:
            where, sep, reason = key.rpartition(_SEP)
            if not sep:
                raise ValueError(f"rejections of {s.name[:40]!r}: bad entry {key[:80]!r}")
            counts[(where, reason)] = count(value, f"rejections of {s.name[:40]!r}: {key[:80]!r}")
        out[s.name] = counts
    return stamp_ns, out
