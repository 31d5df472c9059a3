"""`/center/state` and `/depot/state`: the servers' state as diagnostic_msgs/msg/DiagnosticArray.

Published reliable + transient-local whenever it changes, so a late joiner (RViz, `ros2 topic
echo`, the recorder) has the current state at once (`swarm_msgs_py.server_outputs.ServerState`:
the value is a `RegionView` tuple or a `DepotView`, decoded back exactly).

- `/center/state`: one status per region, name ``region_<i>``, values ``length``,
  ``remaining`` [m of spiral], ``finished``, ``walkers`` (``robot_3:+1 robot_9:-1``: robot and
  walking direction), ``covered`` (``0.0-3.25 10.5-12.0``: covered arc-length intervals [m]).
- `/depot/state`: one status ``queues`` whose values are each entry line's queue length, one
  status ``docks`` with each dock's occupant ('' if free), one status ``inner_queues`` with the
  robots on each inner queue (single-queue wrapping), and one status ``slots`` whose values are
  ``<line>/<slot>`` -> robot for every owned slot.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any, NamedTuple

from swarm_msgs_py.cdr import codec
from swarm_msgs_py.diagnostics import OK, TYPE_NAME, decode_diagnostics, encode_diagnostics


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


class DepotView(NamedTuple):
    """The depot as `/depot/state` carries it."""

    queues: tuple[tuple[str, int], ...]
    """(entry line, robots queued on it)."""
    docks: tuple[str, ...]
    """Each dock's occupant ('' if free)."""
    inner_queues: tuple[int, ...]
    """Robots on each inner queue."""
    slots: tuple[tuple[str, int, str], ...]
    """(line, slot, owner) of every owned slot."""


def _get(values: dict[str, Any], key: str) -> Any:
    if key not in values:
        raise ValueError(f"no {key!r}")
    return values[key]


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
        walkers = tuple((robot, int(d)) for robot, _, d in (w.rpartition(":") for w in _get(v, "walkers").split()))
        covered = []
        for text in _get(v, "covered").split():
            match = _INTERVAL.fullmatch(text)
            if match is None:
                raise ValueError(f"covered interval {text[:40]!r}")
            covered.append((float(match[1]), float(match[2])))
        regions.append(RegionView(int(status.name.removeprefix("region_")), float(_get(v, "length")),
                                  float(_get(v, "remaining")), _get(v, "finished") == "true", walkers, tuple(covered)))
    return stamp_ns, tuple(regions)


@codec(f"{TYPE_NAME} (depot state)")
def encode_depot_state(stamp_ns: int, depot: DepotView) -> bytes:
    queues, docks, inner_queues, slots = depot
    statuses = [
        (OK, "queues", "robots queued per entry line", "depot_manager",
         tuple((line, str(n)) for line, n in queues)),
        (OK, "docks", "occupant per dock", "depot_manager",
         tuple((f"dock_{k}", robot) for k, robot in enumerate(docks))),
        (OK, "inner_queues", "robots per inner queue", "depot_manager",
         tuple((f"inner_queue_{k}", str(n)) for k, n in enumerate(inner_queues))),
        (OK, "slots", "owner per owned slot", "depot_manager",
         tuple((f"{line}/{cell}", robot) for line, cell, robot in slots)),
    ]
    return encode_diagnostics(stamp_ns, statuses)


@codec(f"{TYPE_NAME} (depot state)")
def decode_depot_state(data: bytes) -> tuple[int, DepotView]:
    stamp_ns, state = decode_state(data)
    slots = tuple((line, int(cell), robot) for (line, _, cell), robot in
                  ((key.rpartition("/"), robot) for key, robot in _get(state, "slots").items()))
    return stamp_ns, DepotView(tuple((line, int(n)) for line, n in _get(state, "queues").items()),
                               tuple(_get(state, "docks").values()),
                               tuple(int(n) for n in _get(state, "inner_queues").values()), slots)


@codec(f"{TYPE_NAME} (server state)")
def decode_state(data: bytes) -> tuple[int, dict[str, dict[str, str]]]:
    """-> (stamp_ns, {status name: {key: value}}) for either state topic."""
    stamp_ns, statuses = decode_diagnostics(data)
    return stamp_ns, {s.name: dict(s.values) for s in statuses}


def queue_lengths(state: dict[str, dict[str, str]]) -> tuple[int, ...]:
    """Per entry line, robots queued, from a decoded `/depot/state`."""
    return tuple(int(v) for v in state.get("queues", {}).values())
