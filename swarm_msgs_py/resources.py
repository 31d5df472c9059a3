"""`/<robot>/resources`: geometry_msgs/msg/PoseArray <-> detected resource positions.

Mapping: header.frame_id ``world``; one pose per resource within the detection radius,
nearest first: position (x, y, 0) [m, world frame], identity orientation.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from typing import NamedTuple

from swarm_msgs_py.cdr import (
    CATCH,
    ENCAPSULATION,
    align,
    failure,
    frames_fragment,
    skip_header,
    split_stamp,
)

TYPE_NAME = "geometry_msgs/msg/PoseArray"
WORLD_FRAME = "world"

_POSE = struct.Struct("<7d")
_FRAME = frames_fragment(WORLD_FRAME, then_align=4)
_HEAD = struct.Struct(f"<4siI{len(_FRAME)}sI")
_U32 = struct.Struct("<I")
_POSES_PAD = bytes(-(_HEAD.size - len(ENCAPSULATION)) % 8)
"""Padding between the count and the first pose (none for the "world" frame)."""


class ResourcesData(NamedTuple):
    stamp_ns: int
    resources: tuple[tuple[float, float], ...]
    """[m, world frame], in message order (nearest first)."""


def encode_resources(stamp_ns: int, resources: Sequence[tuple[float, float]]) -> bytes:
    """`resources`: (x, y) [m, world frame] each, nearest first."""
    try:
        sec, nanosec = split_stamp(stamp_ns)
        head = _HEAD.pack(ENCAPSULATION, sec, nanosec, _FRAME, len(resources))
        if not resources:
            return head
        pose = _POSE.pack
        return b"".join(
            [head, _POSES_PAD, *(pose(x, y, 0.0, 0.0, 0.0, 0.0, 1.0) for x, y in resources)]
        )
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc


def decode_resources(data: bytes) -> ResourcesData:
    try:
        stamp_ns, pos = skip_header(data)
        pos = align(pos, 4)
        (count,) = _U32.unpack_from(data, pos)
        pos += 4
        if count:
            pos = align(pos, 8)
        if pos + count * _POSE.size > len(data):
            raise ValueError(f"{count} poses overrun the {len(data)}-byte message")
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc
    unpack, size = _POSE.unpack_from, _POSE.size
    return ResourcesData(
        stamp_ns, tuple(unpack(data, pos + i * size)[:2] for i in range(count))
    )
