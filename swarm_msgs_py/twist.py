"""`/<robot>/cmd_vel`: geometry_msgs/msg/TwistStamped <-> a robot's velocity command.

Mapping: header.stamp = the tick the command answers; header.frame_id ``<robot>/base_link``;
twist.linear.x = forward speed [m/s], twist.angular.z = turn rate [rad/s]; the other four
components are 0 and ignored when decoding. Decoding returns the floats as sent, NaN and inf
included: clamping them is the world's job (and counted in `RobotStats.clamped_commands`).
"""

from __future__ import annotations

import functools
import struct
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
from swarm_msgs_py.types import RobotId

TYPE_NAME = "geometry_msgs/msg/TwistStamped"

_TWIST = struct.Struct("<6d")


class TwistData(NamedTuple):
    stamp_ns: int
    """The tick this command answers [ns]."""
    linear: float
    """[m/s, body frame]"""
    angular: float
    """[rad/s]"""


@functools.lru_cache(maxsize=4096)
def _layout(robot: RobotId) -> tuple[struct.Struct, bytes]:
    frame = frames_fragment(f"{robot}/base_link", then_align=8)
    return struct.Struct(f"<4siI{len(frame)}s6d"), frame


def encode_twist(robot: RobotId, stamp_ns: int, linear: float, angular: float) -> bytes:
    try:
        sec, nanosec = split_stamp(stamp_ns)
        layout, frame = _layout(robot)
        return layout.pack(
            ENCAPSULATION, sec, nanosec, frame, linear, 0.0, 0.0, 0.0, 0.0, angular
        )
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc


def decode_twist(data: bytes) -> TwistData:
    try:
        stamp_ns, pos = skip_header(data)
        linear, _, _, _, _, angular = _TWIST.unpack_from(data, align(pos, 8))
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc
    return TwistData(stamp_ns, linear, angular)


PLAIN_TYPE_NAME = "geometry_msgs/msg/Twist"
"""A robot's own computer (TurtleBot-class drivers): the bare velocity, no stamp, no frame."""

_PLAIN = struct.Struct("<4s6d")


def encode_plain_twist(linear: float, angular: float) -> bytes:
    """geometry_msgs/msg/Twist: linear.x = `linear` [m/s], angular.z = `angular` [rad/s]."""
    try:
        return _PLAIN.pack(ENCAPSULATION, linear, 0.0, 0.0, 0.0, 0.0, angular)
    except CATCH as exc:
        raise failure(PLAIN_TYPE_NAME, exc) from exc


def decode_plain_twist(data: bytes) -> tuple[float, float]:
    """(linear.x, angular.z) of a geometry_msgs/msg/Twist, as sent (NaN and inf included)."""
    try:
        _, linear, _, _, _, _, angular = _PLAIN.unpack_from(data)
    except CATCH as exc:
        raise failure(PLAIN_TYPE_NAME, exc) from exc
    return linear, angular
