"""`/<robot>/scan`: sensor_msgs/msg/LaserScan <-> float32 ranges.

Mapping: header.frame_id ``<robot>/base_link``; angle_min = -fov/2; angle_increment =
fov/rays for a full circle (so the first and last rays do not coincide), else fov/(rays-1);
angle_max = angle_min + (rays-1)*angle_increment; time_increment = scan_time = 0 (the whole
scan is taken at the stamp); range_min/range_max from the scenario's `ScanConfig`; intensities empty.
Ranges travel as float32 (the world core already rounds them), ``inf`` for no return.
"""

from __future__ import annotations

import functools
import math
import struct
from typing import NamedTuple, Protocol

import numpy as np

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

TYPE_NAME = "sensor_msgs/msg/LaserScan"

_SEVEN_F32 = struct.Struct("<7f")
_U32 = struct.Struct("<I")
_NO_INTENSITIES = b"\x00\x00\x00\x00"


class ScanData(NamedTuple):
    stamp_ns: int
    ranges: np.ndarray
    """[m], float32, ray i at angle_min + i * angle_increment from the heading."""


class ScanShape(Protocol):
    """What the codec reads of a scan's shape: the scenario's scan section
    (`swarm_sim.scenario.ScanConfig`) is one; named here so the wire sits below the scenario."""

    @property
    def rays(self) -> int: ...
    @property
    def fov(self) -> float: ...
    @property
    def range_min(self) -> float: ...
    @property
    def range_max(self) -> float: ...


class ScanGeometry(NamedTuple):
    """The LaserScan angle fields for a `ScanShape` [rad, body frame]."""

    angle_min: float
    angle_max: float
    angle_increment: float


def scan_geometry(config: ScanShape) -> ScanGeometry:
    full_circle = config.fov >= 2 * math.pi - 1e-9
    if full_circle or config.rays == 1:
        increment = config.fov / config.rays
    else:
        increment = config.fov / (config.rays - 1)
    angle_min = -config.fov / 2
    return ScanGeometry(angle_min, angle_min + (config.rays - 1) * increment, increment)


@functools.lru_cache(maxsize=4096)
def _layout(robot: RobotId, config: ScanShape) -> tuple[struct.Struct, bytes]:
    """Everything before the ranges except the stamp is constant per robot and config."""
    g = scan_geometry(config)
    fields = _SEVEN_F32.pack(
        g.angle_min, g.angle_max, g.angle_increment, 0.0, 0.0, config.range_min, config.range_max
    )
    const = frames_fragment(f"{robot}/base_link", then_align=4) + fields
    return struct.Struct(f"<4siI{len(const)}sI"), const


def encode_scan(robot: RobotId, stamp_ns: int, ranges: np.ndarray, config: ScanShape) -> bytes:
    """`ranges` [m]: one per ray (``config.rays``), rounded to float32 on the wire."""
    try:
        ranges = np.asarray(ranges)
        if ranges.shape != (config.rays,):
            raise ValueError(f"ranges of shape {ranges.shape} for a {config.rays}-ray scan")
        sec, nanosec = split_stamp(stamp_ns)
        layout, const = _layout(robot, config)
        head = layout.pack(ENCAPSULATION, sec, nanosec, const, config.rays)
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc
    return head + ranges.astype("<f4", copy=False).tobytes() + _NO_INTENSITIES


def decode_scan(data: bytes) -> ScanData:
    try:
        stamp_ns, pos = skip_header(data)
        pos = align(pos, 4) + _SEVEN_F32.size
        (count,) = _U32.unpack_from(data, pos)
        pos += 4
        end = pos + 4 * count
        if end + 4 > len(data):  # the ranges and the intensities' count
            raise ValueError(f"{count} ranges overrun the {len(data)}-byte message")
        (n_intensities,) = _U32.unpack_from(data, end)
        if end + 4 + 4 * n_intensities > len(data):
            raise ValueError(f"{n_intensities} intensities overrun the {len(data)}-byte message")
    except CATCH as exc:
        raise failure(TYPE_NAME, exc) from exc
    return ScanData(stamp_ns, np.frombuffer(data, "<f4", count, pos).astype(np.float32))
