"""A server's state topic as diagnostic_msgs/msg/DiagnosticArray, the generic part: each
paper's server encodes and decodes its own state (e.g. `depot_manager.state`) with these helpers.

Published reliable + transient-local whenever it changes, so a late joiner (RViz, `ros2 topic
echo`, the recorder) has the current state at once (`swarm_sim.outputs.ServerState`).
"""

from __future__ import annotations

from typing import Any

from swarm_msgs_py.cdr import codec
from swarm_msgs_py.diagnostics import TYPE_NAME, decode_diagnostics


def required(values: dict[str, Any], key: str) -> Any:
    """``values[key]``; ValueError naming the key if the state lacks it."""
    if key not in values:
        raise ValueError(f"no {key!r}")
    return values[key]


@codec(f"{TYPE_NAME} (server state)")
def decode_state(data: bytes) -> tuple[int, dict[str, dict[str, str]]]:
    """-> (stamp_ns, {status name: {key: value}}) for either state topic."""
    stamp_ns, statuses = decode_diagnostics(data)
    return stamp_ns, {s.name: dict(s.values) for s in statuses}
