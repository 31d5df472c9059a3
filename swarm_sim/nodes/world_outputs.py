"""What the world node shows besides the robots' observations, after every tick.

- ``/world/events``: the world task's events (pick-ups, drops, ...) and the nodes declared dead;
- ``/world/robot_stats``: every robot's counters, every `stats_period` sim seconds and at the end;
- ``/world/markers``: the scenario's world drawn for RViz/Foxglove, every `markers_period` sim
  seconds and at the end (latched);
- ``/diagnostics``: the commands and acks the world dropped (`swarm_sim.nodes.endpoint.RejectionReport`);
- the live view (``swarm-run --foxglove``, `swarm_sim.nodes.live_view`), started once the run's
  topics exist.

Everything but the diagnostics is recorded as published (`swarm_sim.nodes.world_recording`).
"""

from __future__ import annotations

from collections.abc import Sequence

from rclpy.node import Node

from swarm_msgs_py import auth, diagnostics, topics
from swarm_sim.inbound import Rejections
from swarm_sim.nodes import markers
from swarm_sim.nodes.endpoint import RejectionReport
from swarm_sim.nodes.qos import EVENTS, STATE_LATCHED
from swarm_sim.nodes.world_recording import WorldRecording
from swarm_sim.scenario import Scenario
from swarm_sim.world import World


class WorldOutputs:
    def __init__(self, node: Node, recording: WorldRecording, scenario: Scenario, rejections: Rejections, *,
                 stats_period: float, markers_period: float) -> None:
        self._recording = recording
        self._scenario = scenario
        self._events_pub = recording.publisher(topics.WORLD_EVENTS, EVENTS)
        self._stats_pub = recording.publisher(topics.WORLD_ROBOT_STATS, STATE_LATCHED)
        self._markers_pub = recording.publisher(topics.WORLD_MARKERS, STATE_LATCHED)
        self._stats_every = max(1, round(stats_period / scenario.sim.dt))
        self._markers_every = max(1, round(markers_period / scenario.sim.dt))
        # Latched and not recorded by the world itself: every node publishes its counts there and
        # the recorder records them all (the world's included) through one subscription.
        self.report = RejectionReport(node, rejections)

    def publish(self, world: World, events: Sequence[object] = (), *, final: bool = False) -> None:
        """After a tick: `events` (the nodes declared dead at it) and the task's, the stats and
        markers when due (`final`: all of them, the run is over), the rejection counts."""
        t_ns, publish = world.t_ns, self._recording.publish
        events = [*events, *world.drain_events()]
        if events:
            publish(self._events_pub, auth.sign(diagnostics.encode_events(t_ns, events)), topics.WORLD_EVENTS)
        if final or world.tick % self._stats_every == 0:
            publish(self._stats_pub, auth.sign(diagnostics.encode_robot_stats(t_ns, world.stats)), topics.WORLD_ROBOT_STATS)
        if final or world.tick % self._markers_every == 0:
            data = markers.encode_markers(self._scenario, t_ns, world.task.placed(), world.true_poses())
            publish(self._markers_pub, data, topics.WORLD_MARKERS)
        self.report.publish(t_ns)

    def start_live_view(self, discover) -> None:
        """Serve Foxglove clients once the run's topics exist (`discover()` finds the others')."""
        live = self._recording.live
        if live is not None:
            discover()
            live.start()
            print(f"[world] live view: {live.url} (Foxglove: Open connection -> Foxglove WebSocket)", flush=True)
