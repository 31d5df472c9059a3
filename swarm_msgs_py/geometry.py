"""Small planar geometry helpers shared by the world, the codecs and the behaviours."""

from __future__ import annotations

import math


def wrap_angle(angle: float) -> float:
    """Wrap to (-pi, pi]."""
    wrapped = math.remainder(angle, 2 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def yaw_to_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by `yaw` about +z."""
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def quaternion_to_yaw(z: float, w: float) -> float:
    """Yaw of a rotation about +z given its quaternion's z and w; result in (-pi, pi]."""
    return wrap_angle(2.0 * math.atan2(z, w))


def wire_yaw(yaw: float) -> float:
    """The yaw a receiver decodes after it travelled as a quaternion (bit-exact)."""
    _, _, z, w = yaw_to_quaternion(yaw)
    return quaternion_to_yaw(z, w)
