"""`/center/state`: the center's regions as diagnostic_msgs/msg/DiagnosticArray.

Published reliable + transient-local whenever it changes, so a late joiner (RViz, `ros2 topic
echo`, the recorder) has the current state at once (`swarm_sim.outputs.ServerState`:
the value is a `RegionView` tuple, decoded back exactly). One status per region, name
``region_<i>``, values ``length``, ``remaining`` [m of spiral], ``finished``, ``walkers``
(``robot_3:+1 robot_9:-1``: robot and walking direction), ``covered`` (``0.0-3.25 10.5-12.0``:
covered arc-length intervals [m]).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any, NamedTuple

from swarm_msgs_py.cdr import codec
from swarm_msgs_py.diagnostics import OK, TYPE_NAME, decode_diagnostics, encode_diagnostics
from swarm_msgs_py.server_state import required


class RegionView(NamedTuple):
    """One region as `/center/state` carries it (`swarm_controllers.spiral.center.RegionState`
    without its last update time)."""

    region: int
    length: float
    """Arc length of the region's spiral [m]."""
    remaining: float
    """Uncovered arc length [m]."""
    finished: bool
    walkers: tuple[tuple[str, int], ...]
    """(robot, walking direction +1/-1)."""
    covered: tuple[tuple[float, float], ...]
    """Covered arc-length intervals [m]."""


_INTERVAL = re.compile(r"(.*?[^e])-(.*)")
"""``a-b`` of two non-negative float reprs (a ``-`` after an ``e`` is an exponent's)."""


@codec(f"{TYPE_NAME} (center state)")
def encode_center_state(stamp_ns: int, regions: Sequence[Any]) -> bytes:
    """`regions`: `RegionView` (or `swarm_controllers.spiral.center.RegionState`) records."""
    statuses = []
    for s in regions:
        walkers = " ".join(f"{robot}:{direction:+d}" for robot, direction in s.walkers)
        covered = " ".join(f"{a!r}-{b!r}" for a, b in s.covered)
        values = (
            ("length", repr(float(s.length))), ("remaining", repr(float(s.remaining))),
            ("finished", "true" if s.finished else "false"), ("walkers", walkers), ("covered", covered),
        )
        statuses.append((OK, f"region_{s.region}", "", "center", values))
    return encode_diagnostics(stamp_ns, statuses)


@codec(f"{TYPE_NAME} (center state)")
def decode_center_state(data: bytes) -> tuple[int, tuple[RegionView, ...]]:
    stamp_ns, statuses = decode_diagnostics(data)
    regions = []
    for status in statuses:
        v = dict(status.values)
        walkers = tuple((robot, int(d)) for robot, _, d in (w.rpartition(":") for w in required(v, "walkers").split()))
        covered = []
        for text in required(v, "covered").split():
            match = _INTERVAL.fullmatch(text)
            if match is None:
                raise ValueError(f"covered interval {text[:40]!r}")
            covered.append((float(match[1]), float(match[2])))
        regions.append(RegionView(int(status.name.removeprefix("region_")), float(required(v, "length")),
                                  float(required(v, "remaining")), required(v, "finished") == "true", walkers, tuple(covered)))
    return stamp_ns, tuple(regions)
