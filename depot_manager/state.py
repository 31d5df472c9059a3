"""`/depot/state`: the depot manager's queues and docks as diagnostic_msgs/msg/DiagnosticArray.

Published reliable + transient-local whenever it changes, so a late joiner (RViz, `ros2 topic
echo`, the recorder) has the current state at once (`swarm_sim.outputs.ServerState`:
the value is a `DepotView`, decoded back exactly). One status ``queues`` whose values are each
entry line's queue length, one status ``docks`` with each dock's occupant ('' if free), one status
``inner_queues`` with the robots on each inner queue (single-queue wrapping), and one status
``slots`` whose values are ``<line>/<slot>`` -> robot for every owned slot.
"""

from __future__ import annotations

from typing import NamedTuple

from swarm_msgs_py.cdr import codec
from swarm_msgs_py.diagnostics import OK, TYPE_NAME, encode_diagnostics
from swarm_msgs_py.server_state import decode_state, required


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
                  ((key.rpartition("/"), robot) for key, robot in required(state, "slots").items()))
    return stamp_ns, DepotView(tuple((line, int(n)) for line, n in required(state, "queues").items()),
                               tuple(required(state, "docks").values()),
                               tuple(int(n) for n in required(state, "inner_queues").values()), slots)


def queue_lengths(state: dict[str, dict[str, str]]) -> tuple[int, ...]:
    """Per entry line, robots queued, from a decoded `/depot/state`."""
    return tuple(int(v) for v in state.get("queues", {}).values())
