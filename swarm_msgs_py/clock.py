"""`/clock`: rosgraph_msgs/msg/Clock <-> sim time as integer nanoseconds."""

from __future__ import annotations

import struct

from swarm_msgs_py.cdr import (
    CATCH,
    ENCAPSULATION,
    check_encapsulation,
    failure,
    read_stamp,
    split_stamp,
)

TYPE_NAME = "rosgraph_msgs/msg/Clock"

_CLOCK = struct.Struct("<4siI")


def encode_clock(stamp_ns: int) -> bytes:
    try:
        return _CLOCK.pack(ENCAPSULATION, *split_stamp(stamp_ns))
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc


def decode_clock(data: bytes) -> int:
    """Sim time [ns]."""
    try:
        check_encapsulation(data)
        return read_stamp(data)
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc
