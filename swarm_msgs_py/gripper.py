"""`/<robot>/gripper`: sensor_msgs/msg/JointState <-> whether the robot carries a resource.

Mapping: header.frame_id empty (a joint state has no frame); name ``["gripper"]``,
position ``[1.0]`` while carrying else ``[0.0]``; velocity and effort empty.
"""

from __future__ import annotations

import struct
from typing import NamedTuple

from swarm_msgs_py.cdr import CATCH, ENCAPSULATION, TIME, Reader, Writer, failure, read_stamp, split_stamp

TYPE_NAME = "sensor_msgs/msg/JointState"
JOINT_NAME = "gripper"


class GripperData(NamedTuple):
    stamp_ns: int
    carrying: bool


def _constant_part() -> bytes:
    """Everything between the stamp and the position value: it never changes."""
    w = Writer(offset=TIME.size)
    w.string("")  # header.frame_id
    w.strings([JOINT_NAME])  # name
    w.u32(1)  # position: one item, aligned to 8 next
    w.align(8)
    return w.body()


_CONST = _constant_part()
_MSG = struct.Struct(f"<4siI{len(_CONST)}sdII")  # ..., position[0], len(velocity), len(effort)


def encode_gripper(stamp_ns: int, carrying: bool) -> bytes:
    try:
        sec, nanosec = split_stamp(stamp_ns)
        return _MSG.pack(ENCAPSULATION, sec, nanosec, _CONST, 1.0 if carrying else 0.0, 0, 0)
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc


def decode_gripper(data: bytes) -> GripperData:
    """The gripper joint's position: carrying when above 0.5 (any other joints ignored).

    The world's own layout (`encode_gripper`'s: one joint, no velocity or effort) is read in
    one unpack, a fifth of the general decoding's 4.8 us (every robot, every tick); anything
    else goes the general way."""
    if len(data) == _MSG.size:
        head, _, _, const, position, velocities, efforts = _MSG.unpack(data)
        if head == ENCAPSULATION and const == _CONST and velocities == efforts == 0:
            try:
                return GripperData(read_stamp(data), bool(position > 0.5))
            except CATCH as exc:
                raise failure(TYPE_NAME, exc) from exc
    try:
        r = Reader(data)
        stamp_ns, _ = r.header()
        names = r.strings()
        position = r.f64_array()
        r.f64_array()  # velocity
        r.f64_array()  # effort
        if JOINT_NAME not in names:
            raise ValueError(f"no {JOINT_NAME!r} joint among {names}")
        index = names.index(JOINT_NAME)
        if index >= len(position):
            raise ValueError(f"{len(names)} joint names but {len(position)} positions")
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc
    return GripperData(stamp_ns, bool(position[index] > 0.5))
