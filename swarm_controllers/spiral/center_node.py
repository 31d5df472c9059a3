"""The center node: MDBSA region assignment (`swarm_controllers.spiral.center.CenterServer`) on the graph.

Robots report progress and ask for regions on ``/center/reports`` (only while within the
center's range); assignments go out on ``/center/assignments``. The node publishes the regions'
walkers and progress on ``/center/state`` and the regions and their planned spirals on
``/center/markers`` (both reliable + transient-local) whenever they change.
"""

from __future__ import annotations

import sys

from swarm_controllers.spiral.center import region_paths
from swarm_controllers.spiral.protocol import CENTER
from swarm_controllers.spiral.geometry import region_centers, region_side
from swarm_controllers.spiral.regions import RegionConfig
from swarm_msgs_py import markers, server_state, topics
from swarm_msgs_py.qos import STATE_LATCHED
from swarm_sim.nodes.server_node import ServerNode, ServerNodeConfig, run_server

_REGION = (0.6, 0.6, 0.6, 1.0)
_PATH = (0.2, 0.6, 1.0, 0.8)


class CenterNode(ServerNode):
    CHANNEL = CENTER

    def __init__(self, config: ServerNodeConfig | None = None, **kwargs) -> None:
        super().__init__("center", config, **kwargs)
        self._state_pub = self.create_publisher(topics.type_of(topics.CENTER_STATE), topics.CENTER_STATE, STATE_LATCHED)
        self._markers_pub = self.create_publisher(
            topics.type_of(topics.CENTER_MARKERS), topics.CENTER_MARKERS, STATE_LATCHED
        )
        self._last_state = None
        regions, size = RegionConfig.of(self.scenario).count, self.scenario.arena.size
        half = region_side(regions, size) / 2
        squares = [
            [(x - half, y - half), (x + half, y - half), (x + half, y + half), (x - half, y + half), (x - half, y - half)]
            for x, y in region_centers(regions, size)
        ]
        drawn = markers.line_markers("regions", squares, _REGION, 0.02) + markers.line_markers(
            "planned_paths", [p.waypoints for p in region_paths(self.scenario)], _PATH, 0.01
        )
        self._markers_pub.publish(markers.serialize_markers(drawn))

    def publish_state(self, stamp_ns: int) -> None:
        state = self.server.snapshot()
        key = [(s.walkers, s.covered, s.finished) for s in state]
        if key != self._last_state:
            self._last_state = key
            self._state_pub.publish(server_state.encode_center_state(stamp_ns, state))


def main(argv: list[str] | None = None) -> int:
    return run_server(CenterNode, "swarm-center", argv)


if __name__ == "__main__":
    sys.exit(main())
