"""The transport task's sense (`swarm_controllers.caging.task.CagingSense`) and state on the graph.

The sense travels on ``/<robot>/sense`` (`swarm_msgs_py.sensing`), one status per field:

| status | values |
|---|---|
| ``proximity`` | (``ir_k``, id) per sensor k in order; id "" = nothing detected |
| ``bodies`` | (id, ``"x y"``) per sensed body (``object``, ``robot_3``) [m, world frame] |

| state topic | type | what |
|---|---|---|
| ``/caging/object`` | geometry_msgs/msg/PoseStamped | the object's true position (frame ``world``, z = 0, identity orientation) |
| ``/caging/robots`` | geometry_msgs/msg/PoseArray | every robot's true position in robot order (frame ``world``, z = 0, identity orientations) |

Floats travel as ``repr`` text or float64, so positions round-trip exactly (orientations are not
carried: a quaternion does not give a yaw back bit for bit, and the measures need positions).
"""

from __future__ import annotations

from collections.abc import Sequence

from swarm_controllers.caging.task import CagingSense
from swarm_msgs_py.cdr import Reader, Writer, codec
from swarm_msgs_py.sensing import Pairs, SenseField, Sensing, StateTopic, numbers_text, parse_numbers

PROXIMITY = "proximity"
BODIES = "bodies"
OBJECT_TOPIC = "/caging/object"
ROBOTS_TOPIC = "/caging/robots"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
POSE_ARRAY = "geometry_msgs/msg/PoseArray"
WORLD_FRAME = "world"

Position = tuple[float, float]
"""(x, y) [m, world frame]."""


def encode_proximity(proximity: Sequence[str]) -> Pairs:
    return tuple([(f"ir_{k}", v) for k, v in enumerate(proximity)])


def decode_proximity(pairs: Pairs) -> tuple[str, ...]:
    keys = [k for k, _ in pairs]
    if keys != [f"ir_{k}" for k in range(len(pairs))]:
        raise ValueError(f"sensor keys {[k[:40] for k in keys[:10]]} are not ir_0, ir_1, ... in order")
    return tuple([v for _, v in pairs])


def encode_bodies(bodies: Sequence[tuple[str, float, float]]) -> Pairs:
    return tuple([(name, numbers_text((x, y))) for name, x, y in bodies])


def decode_bodies(pairs: Pairs) -> tuple[tuple[str, float, float], ...]:
    return tuple([(name, *parse_numbers(text, 2, f"body {name[:40]!r}")) for name, text in pairs])


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


SENSING = Sensing(CagingSense, (SenseField(PROXIMITY, encode_proximity, decode_proximity),
                                 SenseField(BODIES, encode_bodies, decode_bodies)))

STATE = (
    StateTopic(OBJECT_TOPIC, POSE_STAMPED, "object", encode_object, decode_object),
    StateTopic(ROBOTS_TOPIC, POSE_ARRAY, "robots", encode_robots, decode_robots),
)
