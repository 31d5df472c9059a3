"""The world node's recorder hooks: every topic it publishes or hears goes into the run's bag.

The world writes what it publishes (and the commands, acks and robots' messages it receives)
as the very bytes on the wire, stamped with the sim time (`swarm_sim.nodes.recorder.Recorder`);
topics other nodes publish are found by `discover` and recorded as they arrive. With a live view
(`swarm_sim.nodes.live_view`) the same bytes also go to the Foxglove clients. Without a bag and a
live view every hook does nothing.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Collection, Mapping
from pathlib import Path

from rclpy.node import Node

from swarm_msgs_py import topics
from swarm_sim.nodes.live_view import LiveView
from swarm_sim.nodes.qos import STATE_LATCHED
from swarm_sim.nodes.recorder import Recorder
from swarm_sim.scenario import Scenario, scenario_to_dict


class WorldRecording:
    """The recorder of a world node (None: nothing recorded), from its config's ``bag`` and
    ``foxglove_port``; `now_ns` gives the sim time to stamp messages with."""

    def __init__(self, node: Node, config, scenario: Scenario, robots: int, now_ns: Callable[[], int],
                 types: Mapping[str, str] | None = None,
                 accept: Callable[[str, bytes], bool | None] | None = None) -> None:
        """`types`, `accept`: the run's topics' own types and the check of a discovered topic's
        messages (`swarm_sim.nodes.recorder.Recorder`)."""
        self._node = node
        self.recorder: Recorder | None = None
        if config.bag or config.foxglove_port >= 0:
            meta = {
                "scenario_name": scenario.name,
                "scenario": json.dumps(scenario_to_dict(scenario)),
                "seed": str(config.seed),
                "mode": config.mode,
                "robots": str(robots),
            }
            live = _live_view(config.foxglove_host, config.foxglove_port)
            self.recorder = Recorder(node, Path(config.bag) if config.bag else None, meta, now_ns, live, types, accept)

    def publisher(self, topic: str, qos, type_name: str | None = None):
        """A publisher of the world's, on a recorded topic."""
        type_name = type_name or topics.type_string(topic)
        self.add(topic, type_name, latched=qos is STATE_LATCHED)
        return self._node.create_publisher(topics.import_type(type_name), topic, qos)

    def add(self, topic: str, type_name: str, latched: bool = False) -> None:
        """A topic the world records itself (what it publishes or hears)."""
        if self.recorder is not None:
            self.recorder.add(topic, type_name, latched)

    def skip(self, topic: str) -> None:
        """A topic discovery leaves out (copies of a topic recorded already)."""
        if self.recorder is not None:
            self.recorder.skipped.add(topic)

    def write(self, topic: str, data: bytes) -> None:
        if self.recorder is not None:
            self.recorder.write(topic, data)

    def write_taken(self, topic: str, data: bytes, taken: bool) -> None:
        """A message the world received: on `topic` if it took it, else on the topic's refused
        channel (analysis reads what the run took, `swarm_msgs_py.topics.refused`)."""
        if self.recorder is not None:
            if taken:
                self.recorder.write(topic, data)
            else:
                self.recorder.write_refused(topic, data)

    def publish(self, pub, data: bytes, topic: str, *, send: bool = True) -> None:
        """Publish `data` (unless not `send`) and record it."""
        if send:
            pub.publish(data)
        self.write(topic, data)

    def publish_all(self, items: list[tuple[Callable[[bytes], None], str, bytes]], *, send: bool = True) -> None:
        """`publish` for many (a publisher's publish of bytes, topic, data), recorded in one go
        afterwards."""
        if send:
            for publish, _, data in items:
                publish(data)
        if self.recorder is not None:
            self.recorder.write_all([(topic, data) for _, topic, data in items])

    def discover(self, on_new: Callable[[str], None]) -> None:
        """Record every topic other nodes publish; `on_new(topic)` is told of each new one."""
        if self.recorder is not None:
            self.recorder.discover(on_new)

    def poll(self) -> float:
        """Let the bag flush and split on time; returns the wall seconds that took."""
        if self.recorder is None:
            return 0.0
        t0 = time.monotonic()
        self.recorder.poll()
        return time.monotonic() - t0

    @property
    def live(self) -> LiveView | None:
        return self.recorder.live if self.recorder is not None else None

    def close(self, each: Collection[str] = (), **metadata: str) -> None:
        """Write the run's totals into the bag's metadata and close it; `each`: the topics whose
        offered QoS is asked for one by one (`Recorder.record_offered_qos`)."""
        if self.recorder is not None:
            self.recorder.close(each, **metadata)


def _live_view(host: str, port: int) -> LiveView | None:
    """The live view asked for (port -1: none). A port taken since the launcher checked it
    (`swarm_sim.nodes.ws_proxy.check_port`) costs the live view, not the run: one line says so."""
    if port < 0:
        return None
    try:
        return LiveView(port, host)
    except OSError as exc:
        print(f"[world] live view: cannot listen on {host}:{port} ({exc.strerror or exc}); the run goes on "
              "and is recorded, without a live view", file=sys.stderr, flush=True)
        return None
