"""`/center/state` and `/depot/state`: the servers' state as diagnostic_msgs/msg/DiagnosticArray.

Published reliable + transient-local whenever it changes, so a late joiner (RViz, `ros2 topic
echo`, the recorder) has the current state at once.

- `/center/state`: one status per region, name ``region_<i>``, values ``length``,
  ``remaining`` [m of spiral], ``finished``, ``walkers`` (``robot_3:+1 robot_9:-1``: robot and
  walking direction), ``covered`` (``0.0-3.25 10.5-12.0``: covered arc-length intervals [m]).
- `/depot/state`: one status ``queues`` whose values are each entry line's queue length, one
  status ``docks`` with each dock's occupant ('' if free), one status ``inner_queues`` with the
  robots on each inner queue (single-queue wrapping), and one status ``slots`` whose values are
  ``<line>/<slot>`` -> robot for every owned slot.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from swarm_msgs_py import topics
from swarm_msgs_py.cdr import codec
from swarm_msgs_py.diagnostics import OK, TYPE_NAME, decode_diagnostics, encode_diagnostics
from swarm_sim.types import NS_PER_S


@codec(f"{TYPE_NAME} (center state)")
def encode_center_state(stamp_ns: int, regions: Sequence[Any]) -> bytes:
    """`regions`: `swarm_controllers.spiral.center.RegionState` records."""
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


@codec(f"{TYPE_NAME} (depot state)")
def encode_depot_state(
    stamp_ns: int, queues: Sequence[tuple[str, int]], docks: Sequence[str],
    inner_queues: Sequence[int], slots: Sequence[tuple[str, int, str]],
) -> bytes:
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


@codec(f"{TYPE_NAME} (server state)")
def decode_state(data: bytes) -> tuple[int, dict[str, dict[str, str]]]:
    """-> (stamp_ns, {status name: {key: value}}) for either state topic."""
    stamp_ns, statuses = decode_diagnostics(data)
    return stamp_ns, {s.name: dict(s.values) for s in statuses}


def queue_lengths(state: dict[str, dict[str, str]]) -> tuple[int, ...]:
    """Per entry line, robots queued, from a decoded `/depot/state`."""
    return tuple(int(v) for v in state.get("queues", {}).values())


def replay_depot_state(topic: str, data: bytes) -> list[tuple[str, float, tuple[int, ...]]]:
    """A recorded `/depot/state` message as the run trace's ``queue_lengths`` series point
    (what the batch runner takes from `DepotServer.series`); other topics add nothing."""
    if topic != topics.DEPOT_STATE:
        return []
    stamp_ns, state = decode_state(data)
    return [("queue_lengths", stamp_ns / NS_PER_S, queue_lengths(state))]
