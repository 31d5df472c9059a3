"""`/<robot>/odom`: nav_msgs/msg/Odometry <-> planar pose and body velocities.

Mapping: header.frame_id ``world``, child_frame_id ``<robot>/base_link``; position (x, y, 0);
orientation = `swarm_msgs_py.geometry.yaw_to_quaternion(yaw)`; twist.linear.x = forward speed,
twist.angular.z = turn rate, other twist components 0; both covariances all zero.
Decoding yields ``Pose2D(x, y, wire_yaw(yaw))`` exactly, which the world core already feeds
its batch-run observations so graph and batch runs see identical inputs.
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
    skip_string,
    split_stamp,
)
from swarm_msgs_py.geometry import quaternion_to_yaw, yaw_to_quaternion
from swarm_msgs_py.types import Pose2D, RobotId

TYPE_NAME = "nav_msgs/msg/Odometry"
WORLD_FRAME = "world"

_POSE_TWIST = struct.Struct("<7d288x6d288x")
"""pose.pose (position xyz, orientation xyzw), 36 zero covariances, twist, 36 zeros."""


class OdometryData(NamedTuple):
    stamp_ns: int
    pose: Pose2D
    """[m, m, rad; world frame]"""
    linear_velocity: float
    """[m/s, body frame]"""
    angular_velocity: float
    """[rad/s]"""


@functools.lru_cache(maxsize=4096)
def _layout(robot: RobotId) -> tuple[struct.Struct, bytes]:
    """One struct for the whole message; the frame ids are constant bytes per robot."""
    frames = frames_fragment(WORLD_FRAME, f"{robot}/base_link", then_align=8)
    return struct.Struct(f"<4siI{len(frames)}s{_POSE_TWIST.format[1:]}"), frames


def encode_odometry(
    robot: RobotId,
    stamp_ns: int,
    pose: Pose2D,
    linear_velocity: float,
    angular_velocity: float,
) -> bytes:
    try:
        sec, nanosec = split_stamp(stamp_ns)
        _, _, qz, qw = yaw_to_quaternion(pose.yaw)
        layout, frames = _layout(robot)
        return layout.pack(
            ENCAPSULATION, sec, nanosec, frames,
            pose.x, pose.y, 0.0, 0.0, 0.0, qz, qw,
            linear_velocity, 0.0, 0.0, 0.0, 0.0, angular_velocity,
        )  # fmt: skip
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc


def decode_odometry(data: bytes) -> OdometryData:
    try:
        stamp_ns, pos = skip_header(data)
        pos = align(skip_string(data, align(pos, 4)), 8)
        x, y, _, _, _, qz, qw, v, _, _, _, _, w = _POSE_TWIST.unpack_from(data, pos)
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc
    return OdometryData(stamp_ns, Pose2D(x, y, quaternion_to_yaw(qz, qw)), v, w)
