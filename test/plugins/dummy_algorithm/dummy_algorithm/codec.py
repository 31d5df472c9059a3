"""The dummy's sense on ``/<robot>/beacon``: geometry_msgs/msg/PointStamped, point = (range, bearing, 0)."""

from __future__ import annotations

import struct

from dummy_algorithm.messages import Ping
from dummy_algorithm.task import BeaconSense
from swarm_msgs_py.cdr import ENCAPSULATION, align, codec, frames_fragment, skip_header, split_stamp
from swarm_msgs_py.records import RecordFamily
from swarm_msgs_py.sensing import SenseTopic, Sensing
from swarm_sim.outputs import Series, ServerOutputs

TYPE_NAME = "geometry_msgs/msg/PointStamped"
_FRAME = frames_fragment("base_link", then_align=8)
_MSG = struct.Struct(f"<4siI{len(_FRAME)}s3d")
_POINT = struct.Struct("<3d")


@codec(TYPE_NAME)
def encode_beacon(stamp_ns: int, beacon: tuple[float, float]) -> bytes:
    sec, nanosec = split_stamp(stamp_ns)
    return _MSG.pack(ENCAPSULATION, sec, nanosec, _FRAME, beacon[0], beacon[1], 0.0)


@codec(TYPE_NAME)
def decode_beacon(data: bytes) -> tuple[int, tuple[float, float]]:
    stamp_ns, pos = skip_header(data)
    r, b, _ = _POINT.unpack_from(data, align(pos, 8))
    return stamp_ns, (r, b)


SENSING = Sensing(BeaconSense, (SenseTopic("beacon", TYPE_NAME, "beacon", encode_beacon, decode_beacon),))

PINGS = RecordFamily("pings", {Ping: "/dummy/pings"})
"""The dummy's message family: robots' pings to the counter server."""


def _ping(ping: Ping) -> dict[str, int]:
    return {"pings": 1}


OUTPUTS = ServerOutputs(series=(Series(PINGS.topics[Ping], _ping),))
"""The counter publishes nothing of its own; the trace's ``pings`` has a point per ping sent."""
