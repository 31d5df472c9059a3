"""The transport task's sense (`swarm_controllers.caging.task.CagingSense`) and state on the graph.

| topic | type | what |
|---|---|---|
| ``/<robot>/proximity`` | diagnostic_msgs/msg/DiagnosticArray | one status ``proximity``, values ``(ir_k, id)`` per sensor k in order; id "" = nothing detected |
| ``/<robot>/bodies`` | diagnostic_msgs/msg/DiagnosticArray | one status per sensed body: name = its id (``object``, ``robot_3``), values ``x``, ``y`` [m, world frame] |
| ``/caging/object`` | geometry_msgs/msg/PoseStamped | the object's true position (frame ``world``, z = 0, identity orientation) |
| ``/caging/robots`` | geometry_msgs/msg/PoseArray | every robot's true position in robot order (frame ``world``, z = 0, identity orientations) |

Floats travel as ``repr`` text or float64, so positions round-trip exactly (orientations are not
carried: a quaternion does not give a yaw back bit for bit, and the measures need positions).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from swarm_controllers.caging.task import CagingSense
from swarm_msgs_py.cdr import Reader, Writer, codec
from swarm_msgs_py.diagnostics import OK, decode_diagnostics, encode_diagnostics
from swarm_msgs_py.diagnostics import TYPE_NAME as DIAGNOSTICS
from swarm_msgs_py.sensing import SenseTopic, Sensing, StateTopic

PROXIMITY = "proximity"
BODIES = "bodies"
OBJECT_TOPIC = "/caging/object"
ROBOTS_TOPIC = "/caging/robots"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
POSE_ARRAY = "geometry_msgs/msg/PoseArray"
WORLD_FRAME = "world"

Position = tuple[float, float]
"""(x, y) [m, world frame]."""


@codec(f"{DIAGNOSTICS} (proximity)")
def encode_proximity(stamp_ns: int, proximity: Sequence[str]) -> bytes:
    return encode_diagnostics(stamp_ns, [(OK, PROXIMITY, "", "", [(f"ir_{k}", v) for k, v in enumerate(proximity)])])


@codec(f"{DIAGNOSTICS} (proximity)")
def decode_proximity(data: bytes) -> tuple[int, tuple[str, ...]]:
    stamp_ns, statuses = decode_diagnostics(data)
    if len(statuses) != 1 or statuses[0].name != PROXIMITY:
        raise ValueError(f"expected one {PROXIMITY!r} status, got {[s.name for s in statuses]}")
    values = statuses[0].values
    keys = [k for k, _ in values]
    if keys != [f"ir_{k}" for k in range(len(values))]:
        raise ValueError(f"sensor keys {keys[:10]} are not ir_0, ir_1, ... in order")
    return stamp_ns, tuple(v for _, v in values)


def _finite(text: str, key: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{key}: {text!r} is not a finite number")
    return value


@codec(f"{DIAGNOSTICS} (bodies)")
def encode_bodies(stamp_ns: int, bodies: Sequence[tuple[str, float, float]]) -> bytes:
    return encode_diagnostics(stamp_ns, [(OK, name, "", "", [("x", repr(float(x))), ("y", repr(float(y)))])
                                         for name, x, y in bodies])


@codec(f"{DIAGNOSTICS} (bodies)")
def decode_bodies(data: bytes) -> tuple[int, tuple[tuple[str, float, float], ...]]:
    stamp_ns, statuses = decode_diagnostics(data)
    out = []
    for s in statuses:
        if [k for k, _ in s.values] != ["x", "y"]:
            raise ValueError(f"body {s.name!r}: keys {[k for k, _ in s.values]}, expected ['x', 'y']")
        out.append((s.name, _finite(s.values[0][1], f"{s.name}.x"), _finite(s.values[1][1], f"{s.name}.y")))
    return stamp_ns, tuple(out)


def _write_pose(w: Writer, position: Position) -> None:
    x, y = position
    w.f64(float(x), float(y), 0.0, 0.0, 0.0, 0.0, 1.0)


def _read_pose(r: Reader) -> Position:
    x, y, _, _, _, _, _ = r.unpack("d", 7)
    return (x, y)


@codec(POSE_STAMPED)
def encode_object(stamp_ns: int, position: Position) -> bytes:
    w = Writer()
    w.header(stamp_ns, WORLD_FRAME)
    _write_pose(w, position)
    return w.message()


@codec(POSE_STAMPED)
def decode_object(data: bytes) -> tuple[int, Position]:
    r = Reader(data)
    stamp_ns, _ = r.header()
    return stamp_ns, _read_pose(r)


@codec(POSE_ARRAY)
def encode_robots(stamp_ns: int, positions: Sequence[Position]) -> bytes:
    w = Writer()
    w.header(stamp_ns, WORLD_FRAME)
    w.u32(len(positions))
    for position in positions:
        _write_pose(w, position)
    return w.message()


@codec(POSE_ARRAY)
def decode_robots(data: bytes) -> tuple[int, tuple[Position, ...]]:
    r = Reader(data)
    stamp_ns, _ = r.header()
    return stamp_ns, tuple(_read_pose(r) for _ in range(r.sequence_length(56)))


SENSING = Sensing(CagingSense, (
    SenseTopic(PROXIMITY, DIAGNOSTICS, "proximity", encode_proximity, decode_proximity),
    SenseTopic(BODIES, DIAGNOSTICS, "bodies", encode_bodies, decode_bodies),
))

STATE = (
    StateTopic(OBJECT_TOPIC, POSE_STAMPED, "object", encode_object, decode_object),
    StateTopic(ROBOTS_TOPIC, POSE_ARRAY, "robots", encode_robots, decode_robots),
)
