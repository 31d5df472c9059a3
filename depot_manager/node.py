"""The depot-manager node: queue and dock admission (`depot_manager.server.DepotServer`) on the graph.

Robots ask to join and report the slots they reach on ``/depot/reports``; grants go out on
``/depot/grants``. The node publishes the queues and docks on ``/depot/state`` whenever they
change and markers on ``/depot/markers`` (every line, dock, entry and exit point, and which
slots are owned) at most once per `MARKER_PERIOD` of sim time; both reliable + transient-local.
"""

from __future__ import annotations

import sys

import numpy as np

from depot_manager.config import QueueConfig
from depot_manager.protocol import DEPOT
from swarm_msgs_py import markers, server_state, topics
from swarm_msgs_py.qos import STATE_LATCHED
from swarm_sim.nodes.server_node import ServerNode, ServerNodeConfig, run_server
from swarm_sim.types import NS_PER_S

MARKER_PERIOD = 1.0
"""Sim seconds between slot-occupancy marker updates."""

_ENTRY = (0.1, 0.1, 0.1, 0.9)
_EXIT = (0.1, 0.3, 0.9, 0.9)
_INNER = (0.6, 0.2, 0.8, 0.9)
_DOCK = (0.1, 0.7, 0.2, 1.0)
_FREE = (0.7, 0.7, 0.7, 0.5)
_OWNED = (0.9, 0.1, 0.1, 0.9)


class DepotManagerNode(ServerNode):
    CHANNEL = DEPOT

    def __init__(self, config: ServerNodeConfig | None = None, **kwargs) -> None:
        super().__init__("depot_manager", config, **kwargs)
        self._state_pub = self.create_publisher(topics.type_of(topics.DEPOT_STATE), topics.DEPOT_STATE, STATE_LATCHED)
        self._markers_pub = self.create_publisher(
            topics.type_of(topics.DEPOT_MARKERS), topics.DEPOT_MARKERS, STATE_LATCHED
        )
        self._last_state = None
        self._markers_at = -1

    def publish_state(self, stamp_ns: int) -> None:
        s = self.server.admission.snapshot()
        key = (s.entry_queue_lengths, s.dock_occupants, s.inner_queue_counts, s.occupied)
        if key == self._last_state:
            return
        self._last_state = key
        self._state_pub.publish(server_state.encode_depot_state(
            stamp_ns, tuple(zip(s.entry_lines, s.entry_queue_lengths)), s.dock_occupants,
            s.inner_queue_counts, s.occupied,
        ))
        if self._markers_at < 0 or stamp_ns - self._markers_at >= MARKER_PERIOD * NS_PER_S:
            self._markers_at = stamp_ns
            self._markers_pub.publish(markers.serialize_markers(self._markers(stamp_ns, s.occupied)))

    def _markers(self, stamp_ns: int, occupied) -> list:
        layout, adm = self.server.layout, self.server.admission
        lanes = QueueConfig.of(self.scenario).lane_spacing
        owned = {(line, cell) for line, cell, _ in occupied}
        cells = [(line, i, p) for line in adm.lines() for i, p in enumerate(adm.cells(line))]
        free = np.array([p for line, i, p in cells if (line, i) not in owned]).reshape(-1, 2)
        taken = np.array([p for line, i, p in cells if (line, i) in owned]).reshape(-1, 2)
        return (
            markers.line_markers("entry_lines", [ln.points for ln in layout.entry_lines], _ENTRY, 0.01, stamp_ns)
            + markers.line_markers("exit_lines", [ln.points for ln in layout.exit_lines], _EXIT, 0.01, stamp_ns)
            + markers.line_markers("inner_queues", [ln.points for ln in layout.inner_queues], _INNER, 0.01, stamp_ns)
            + markers.point_markers("docks", 0, np.array([d.stop for d in layout.docks]), _DOCK, lanes, stamp_ns, cubes=True)
            + markers.point_markers("entry_points", 0, layout.entry_points, _ENTRY, 0.08, stamp_ns)
            + markers.point_markers("exit_points", 0, layout.exit_points, _EXIT, 0.08, stamp_ns)
            + markers.point_markers("slots_free", 0, free, _FREE, 0.04, stamp_ns)
            + markers.point_markers("slots_owned", 0, taken, _OWNED, 0.06, stamp_ns)
        )


def main(argv: list[str] | None = None) -> int:
    return run_server(DepotManagerNode, "swarm-depot-manager", argv)


if __name__ == "__main__":
    sys.exit(main())
