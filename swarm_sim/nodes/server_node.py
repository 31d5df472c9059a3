"""The server node: any registered server (`swarm_sim.registry.ServerSpec`) on the graph.

``swarm-server --channel depot --scenario queue_qmt ...`` runs the server the scenario's
algorithm registers on that channel, built from its registry record alone: its core, its message
family (`swarm_sim.nodes.endpoint.Endpoint`) and its declared outputs
(`swarm_sim.outputs.ServerOutputs`: state topics and markers, reliable +
transient-local). The node is named as the record says (``depot_manager``, ``center``, ...).

On each ``/clock`` tick k the node hands the core the messages stamped before k, publishes the
core's answers stamped k (one DiagnosticArray per topic), then the core's state values that
changed and, when due, its markers, and acknowledges tick k on ``/lockstep/ack`` so the world's
lockstep barrier knows the answers are out. A repeated tick (the world re-sends ``/clock`` when
an ack is late) is only acknowledged again; in lockstep a tick other than the next one (a forged
``/clock`` from the future) is refused and counted, so nothing on the bus moves the server off
the run's schedule. This is exactly what the batch runner does in process, so graph and batch
runs agree.

Inbound messages are untrusted (`swarm_sim.inbound`); what is dropped, here or by the core, is
counted on ``/diagnostics``. The node also hears the world's ``node_down`` events and, at the
next tick, tells its core which robots were declared dead (`Server.robot_lost`), so a dead
robot's dock, slots or region go to others.

The node creates its ack publisher only once it has matched every robot on its topics, so
the world, which waits for that publisher before the first tick, cannot start too early.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter

from swarm_msgs_py import ack, auth, diagnostics, topics
from swarm_msgs_py import clock as clock_codec
from swarm_msgs_py.types import NS_PER_S, NodeDownEvent
from swarm_sim import registry
from swarm_sim.cli import first_paragraph
from swarm_sim.inbound import Reason
from swarm_sim.nodes import markers
from swarm_sim.nodes.endpoint import Endpoint, EndpointConfig, add_endpoint_arguments, endpoint_config, wait_acked
from swarm_sim.nodes.executor import make_executor
from swarm_sim.nodes.params import declare_config
from swarm_sim.nodes.qos import EVENTS, SENSOR_LOCKSTEP, STATE_LATCHED
from swarm_sim.nodes.run_watch import RunWatch
from swarm_sim.outputs import MARKER_ARRAY, StateWatch, outputs_of
from swarm_sim.protocol import Drawing, Lines, Server
from swarm_sim.scenario import Scenario, load_scenario

CLOCK_BYTES = 64
"""Cap on a ``/clock`` message [bytes] (ours are 12)."""

ServerNodeConfig = EndpointConfig
"""A server node's parameters: scenario, overrides, seed and how long it waits for the robots."""


def encode_drawing(drawing: Drawing, stamp_ns: int) -> bytes:
    """A server's drawing as a MarkerArray, every marker stamped `stamp_ns`."""
    out = []
    for d in drawing:
        if isinstance(d, Lines):
            out += markers.line_markers(d.ns, d.lines, d.color, d.width, stamp_ns)
        else:
            out += markers.point_markers(d.ns, d.id, d.points, d.color, d.size, stamp_ns, cubes=d.cubes)
    return markers.serialize_markers(out)


class ServerNode(Node):
    """The server of `channel` (see the module docstring)."""

    def __init__(self, channel: str, config: ServerNodeConfig | None = None, **kwargs) -> None:
        self.spec = spec = registry.server(channel)
        super().__init__(spec.node_name, parameter_overrides=[Parameter("use_sim_time", value=True)], **kwargs)
        self.config = cfg = declare_config(self, ServerNodeConfig, config)
        self.scenario: Scenario = load_scenario(cfg.scenario, cfg.overrides, seed=cfg.seed)
        if spec not in registry.of(self.scenario).servers:
            raise ValueError(f"{self.scenario.controller.behaviour} registers no {channel!r} server")
        self.server: Server = registry.resolve(spec.core)(self.scenario)
        self.endpoint = Endpoint(self, self.scenario, *registry.server_topics(spec))
        self.lost: list[str] = []
        """Robots the world declared dead, not yet told to the core."""
        self._done = -1
        self._decode_events = auth.verified(diagnostics.decode_events)
        self.create_subscription(topics.type_of(topics.CLOCK), topics.CLOCK, self._on_clock,
                                 SENSOR_LOCKSTEP, raw=True)
        self.create_subscription(topics.type_of(topics.WORLD_EVENTS), topics.WORLD_EVENTS, self._on_world_events,
                                 EVENTS, raw=True)
        self._ack_pub = None
        self.watch = RunWatch(self, self.endpoint.inbound, cfg.world_timeout)
        """The world's ``/world/run``: ticks are acknowledged only while it is current; the
        process leaves when it ends (`swarm_sim.nodes.run_watch`)."""
        outputs = outputs_of(spec)
        self._state = StateWatch(outputs.state)
        self._state_pubs = {st.topic: self.create_publisher(topics.import_type(st.type_name), st.topic, STATE_LATCHED)
                            for st in outputs.state}
        self._markers = outputs.markers
        self._markers_pub = None
        self._markers_at = -1
        """When the markers were last drawn [ns] (-1: never)."""
        if self._markers is not None:
            self._markers_pub = self.create_publisher(topics.import_type(MARKER_ARRAY), self._markers.topic,
                                                      STATE_LATCHED)
            if self._markers.period is None:  # a static drawing, once
                self._draw(0)

    def wait_for_robots(self, executor) -> None:
        """Spin until every robot's publisher and subscribers are matched, then announce
        readiness by creating the ack publisher."""
        robots = self.scenario.robots.count
        deadline = time.monotonic() + self.config.startup_timeout
        while time.monotonic() < deadline and self.endpoint.unmatched(robots) and self.watch.verdict() is None:
            executor.spin_once(timeout_sec=0.1)
        self._ack_pub = self.create_publisher(
            topics.type_of(topics.LOCKSTEP_ACK), topics.LOCKSTEP_ACK, SENSOR_LOCKSTEP
        )

    def _on_world_events(self, data: bytes) -> None:
        inbound = self.endpoint.inbound
        decoded = inbound.decode(topics.WORLD_EVENTS, self._decode_events, data, inbound.bounds.message_bytes)
        if decoded is None:
            return
        for e in decoded[1]:
            if isinstance(e, NodeDownEvent) and e.kind == "robot":
                if e.node in inbound.robots:
                    self.lost.append(e.node)
                else:
                    inbound.reject(topics.WORLD_EVENTS, Reason.UNKNOWN_ROBOT, f"node_down for {e.node[:40]!r}")

    def _on_clock(self, data: bytes) -> None:
        if self._ack_pub is None or not self.watch.current():  # not ready, or not our world's tick
            return
        inbound = self.endpoint.inbound
        stamp = inbound.decode(topics.CLOCK, clock_codec.decode_clock, data, CLOCK_BYTES)
        if stamp is None:
            return
        if stamp > self._done:
            if not self._on_schedule(stamp):
                inbound.reject(topics.CLOCK, Reason.WRONG_TICK, f"tick {stamp} ns after tick {self._done} ns")
                return
            messages = self.endpoint.take(stamp)
            for robot in self.lost:
                if hasattr(self.server, "robot_lost"):
                    self.server.robot_lost(robot, stamp)
                self.get_logger().warning(f"{robot} was declared dead: freed what it held")
            self.lost = []
            self.endpoint.send(stamp, self.server.step(stamp, messages))
            self._publish_state(stamp)
            wait_acked(self._state_pubs.values(), self.endpoint.ack_wait)  # across lossy links (`endpoint`)
            self.endpoint.report.publish(stamp, self.server)
            self._done = stamp
        if stamp == self._done:
            self._ack_pub.publish(auth.sign(ack.encode_ack(self.spec.channel, stamp)))

    def _on_schedule(self, stamp: int) -> bool:
        """Whether tick `stamp` (after the last one done) is the run's next: in lockstep exactly
        the tick after the last (the world never publishes tick k+1 before this node acknowledged
        k or it was declared stale, and re-sends k until then), so a forged ``/clock`` from the
        future is refused and the node stays on the run's schedule; free-running, any later
        tick of the run (a lost sample is not re-sent)."""
        b = self.endpoint.inbound.bounds
        if self.config.mode == "lockstep":
            return stamp == (0 if self._done < 0 else self._done + b.dt_ns)
        return stamp <= b.end_ns and stamp % b.dt_ns == 0

    def _publish_state(self, stamp_ns: int) -> None:
        """The state values that changed, then the markers if they are due."""
        if not self._state_pubs:
            return
        changed = self._state.changed(self.server.state())
        for st, value in changed:
            self._state_pubs[st.topic].publish(auth.sign_if(st.type_name, st.encode(stamp_ns, value)))
        period = self._markers.period if self._markers is not None else None
        if changed and period is not None and (self._markers_at < 0 or stamp_ns - self._markers_at >= period * NS_PER_S):
            self._draw(stamp_ns)

    def _draw(self, stamp_ns: int) -> None:
        self._markers_at = stamp_ns
        self._markers_pub.publish(encode_drawing(self._markers.draw(self.server, stamp_ns), stamp_ns))


def parse_args(argv: list[str]) -> tuple[str, ServerNodeConfig, list[str]]:
    parser = argparse.ArgumentParser(prog="swarm-server", description=first_paragraph(__doc__))
    parser.add_argument("--channel", required=True, help="the server's channel, e.g. depot, center, nest")
    add_endpoint_arguments(parser)
    args, ros_args = parser.parse_known_args(argv)
    return args.channel, endpoint_config(args), ros_args


def main(argv: list[str] | None = None) -> int:
    """One server node in its own process, spun until its run ends (the exit code and one line
    saying why, `swarm_sim.nodes.run_watch`) or it is stopped (0)."""
    channel, config, ros_args = parse_args(sys.argv[1:] if argv is None else argv)
    auth.load_from_environment()  # the run's key, when the launcher handed one down
    rclpy.init(args=["swarm-server", *ros_args])
    node = executor = None
    verdict = None
    try:
        node = ServerNode(channel, config)
        executor = make_executor()
        executor.add_node(node)
        node.wait_for_robots(executor)
        while rclpy.ok() and (verdict := node.watch.verdict()) is None:
            executor.spin_once(timeout_sec=0.5)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # the run is over: a Ctrl-C now only cuts the teardown
        if executor is not None:  # first, and destroyed (`make_executor`)
            executor.shutdown()
            executor = None
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    if verdict is None:
        return 0
    print(f"[server {channel}] {verdict[1]}: leaving (exit {verdict[0]})", file=sys.stderr, flush=True)
    return verdict[0]


if __name__ == "__main__":
    sys.exit(main())
