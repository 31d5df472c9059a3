"""`/nest/pheromones`: geometry_msgs/msg/PointStamped <-> `PheromoneMessage` (CPFA).

Mapping: header.stamp = when the waypoint was laid; header.frame_id ``world``;
point (x, y, 0) = the resource site it points to [m, world frame].
"""

from __future__ import annotations

import struct

from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_msgs_py.cdr import (
    ENCAPSULATION,
    align,
    codec,
    frames_fragment,
    skip_header,
    split_stamp,
)

TYPE_NAME = "geometry_msgs/msg/PointStamped"
PHEROMONES_TOPIC = "/nest/pheromones"
WORLD_FRAME = "world"

_POINT = struct.Struct("<3d")
_FRAME = frames_fragment(WORLD_FRAME, then_align=8)
_MSG = struct.Struct(f"<4siI{len(_FRAME)}s3d")


@codec(TYPE_NAME)
def encode_pheromone(message: PheromoneMessage) -> bytes:
    sec, nanosec = split_stamp(message.stamp_ns)
    return _MSG.pack(ENCAPSULATION, sec, nanosec, _FRAME, message.x, message.y, 0.0)


@codec(TYPE_NAME)
def decode_pheromone(data: bytes) -> PheromoneMessage:
    stamp_ns, pos = skip_header(data)
    x, y, _ = _POINT.unpack_from(data, align(pos, 8))
    return PheromoneMessage(stamp_ns, x, y)


class PheromoneFamily:
    """The CPFA's pheromones as a message family (`swarm_msgs_py.records.MessageFamily`): one
    PointStamped per waypoint on ``/nest/pheromones``."""

    name = "pheromones"
    type_name = TYPE_NAME
    topics = {PheromoneMessage: PHEROMONES_TOPIC}

    def encode(self, stamp_ns: int, messages) -> list[bytes]:
        return [encode_pheromone(m) for m in messages]

    def decode(self, data: bytes) -> tuple[PheromoneMessage, ...]:
        return (decode_pheromone(data),)


PHEROMONES = PheromoneFamily()
