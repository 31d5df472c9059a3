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
from swarm_sim.types import NODE_KINDS, BehaviourStatus, DropEvent, NodeDownEvent, PickupEvent, RobotId, RobotStats

TYPE_NAME = "diagnostic_msgs/msg/DiagnosticArray"

OK, WARN, ERROR, STALE = 0, 1, 2, 3
"""diagnostic_msgs/msg/DiagnosticStatus levels."""

_MIN_STATUS_SIZE = 1 + 3 * 5 + 4
"""level, three empty strings, values count (padding aside): bounds a status count."""


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
    for _ in range(r.sequence_length(_MIN_STATUS_SIZE)):
        level = r.u8()
        name, message, hardware_id = r.string(), r.string(), r.string()
        values = tuple((r.string(), r.string()) for _ in range(r.sequence_length(10)))
        statuses.append(Status(level, name, message, hardware_id, values))
    return DiagnosticsData(stamp_ns, tuple(statuses))


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
                    s.hardware_id, int(f["stamp_ns"]), int(f["resource"]),
                    float(f["x"]), float(f["y"]),
                )  # fmt: skip
            )
        elif s.name == "drop":
            f = _fields(s, _DROP_KEYS, "event")
            events.append(
                DropEvent(
                    s.hardware_id, int(f["stamp_ns"]), int(f["resource"]), f["zone"],
                    float(f["x"]), float(f["y"]),
                )  # fmt: skip
            )
        elif s.name == "node_down":
            f = _fields(s, _DOWN_KEYS, "event")
            if f["kind"] not in NODE_KINDS:
                raise ValueError(f"event node_down: kind {f['kind']!r} not one of {NODE_KINDS}")
            events.append(NodeDownEvent(s.hardware_id, int(f["stamp_ns"]), f["kind"], int(f["ticks"])))
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
            float(f["collision_time_s"]), int(f["pickups"]), int(f["deliveries"]),
            int(f["clamped_commands"]), int(f["stale_ticks"]), float(f["avoidance_time_s"]),
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
    return BehaviourStatus(s.name, stamp_ns, state, int(avoid), int(trips), s.values[3 + finished:], finished)


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
            if not sep or not value.isdigit():
                raise ValueError(f"rejections of {s.name!r}: bad entry {key!r} = {value!r}")
            counts[(where, reason)] = int(value)
        out[s.name] = counts
    return stamp_ns, out
