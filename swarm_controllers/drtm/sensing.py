"""The nest task's sense (`swarm_controllers.drtm.task.NestSense`) on the graph.

| topic | type | field |
|---|---|---|
| ``/<robot>/resources`` | geometry_msgs/msg/PoseArray (`resources` codec) | food tokens within the detection radius, nearest first |
| ``/<robot>/gripper`` | sensor_msgs/msg/JointState (`gripper` codec) | carrying |
| ``/<robot>/light`` | geometry_msgs/msg/Vector3Stamped, frame ``base_link`` | the light vector: vector = (x, y, 0), length = intensity, zero when not detected |
"""

from __future__ import annotations

import struct

from swarm_controllers.drtm.task import NestSense
from swarm_msgs_py import gripper, resources, topics
from swarm_msgs_py.cdr import CATCH, ENCAPSULATION, align, failure, frames_fragment, skip_header, split_stamp
from swarm_msgs_py.sensing import SenseTopic, Sensing

LIGHT = "light"
"""Relative topic name of the light sense."""
LIGHT_TYPE = "geometry_msgs/msg/Vector3Stamped"
_FRAME = frames_fragment("base_link", then_align=8)
_MSG = struct.Struct(f"<4siI{len(_FRAME)}s3d")
_VECTOR = struct.Struct("<3d")


def encode_light(stamp_ns: int, light: tuple[float, float]) -> bytes:
    try:
        sec, nanosec = split_stamp(stamp_ns)
        return _MSG.pack(ENCAPSULATION, sec, nanosec, _FRAME, light[0], light[1], 0.0)
    except CATCH as exc:
        raise failure(LIGHT_TYPE, exc) from exc


def decode_light(data: bytes) -> tuple[int, tuple[float, float]]:
    try:
        stamp_ns, pos = skip_header(data)
        x, y, _ = _VECTOR.unpack_from(data, align(pos, 8))
    except CATCH as exc:
        raise failure(LIGHT_TYPE, exc) from exc
    return stamp_ns, (x, y)


SENSING = Sensing(NestSense, (
    SenseTopic(topics.RESOURCES, resources.TYPE_NAME, "resources",
               resources.encode_resources, resources.decode_resources),
    SenseTopic(topics.GRIPPER, gripper.TYPE_NAME, "carrying",
               gripper.encode_gripper, gripper.decode_gripper),
    SenseTopic(LIGHT, LIGHT_TYPE, "light", encode_light, decode_light),
))
