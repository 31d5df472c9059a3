"""Base of the center and depot-manager nodes: a `swarm_sim.protocol.Server` core on the graph.

On each ``/clock`` tick k the node hands the core the messages stamped before k (from its
inbound topic), publishes the core's answers stamped k (one DiagnosticArray per topic), lets
the subclass publish state and markers, and acknowledges tick k on ``/lockstep/ack`` so the
world's lockstep barrier knows the answers are out. A repeated tick (the world re-sends
``/clock`` when an ack is late) is only acknowledged again. This is exactly what the batch
runner does in process, so graph and batch runs agree.

Inbound messages are untrusted (`swarm_sim.inbound`); what is dropped, here or by the core, is
counted on ``/diagnostics``. The node also hears the world's ``node_down`` events and, at the
next tick, tells its core which robots were declared dead (`Server.robot_lost`), so a dead
robot's dock, slots or region go to others.

The node creates its ack publisher only once it has matched every robot on its topics, so
the world, which waits for that publisher before the first tick, cannot start too early.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import defaultdict
from dataclasses import dataclass

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter

from swarm_msgs_py import ack, diagnostics, topics
from swarm_msgs_py import clock as clock_codec
from swarm_msgs_py.executor import make_executor
from swarm_msgs_py.params import declare_config
from swarm_msgs_py.qos import EVENTS, SENSOR_LOCKSTEP, STATE_LATCHED, family_qos
from swarm_sim import registry
from swarm_sim.inbound import Inbound, Reason, Rejections, merged, total
from swarm_sim.messaging import Mailbox
from swarm_sim.protocol import Server
from swarm_sim.scenario import DEFAULT_SCENARIO, Scenario, load_scenario
from swarm_sim.types import NodeDownEvent


@dataclass(frozen=True)
class ServerNodeConfig:
    scenario: str = DEFAULT_SCENARIO
    """Scenario name or YAML path (the same one the world loads)."""
    overrides: tuple[str, ...] = ()
    seed: int = 0
    startup_timeout: float = 60.0
    """Wall seconds to wait for the robots' publishers and subscribers before going on."""


class ServerNode(Node):
    """A registered server (`swarm_sim.registry.ServerSpec`) on the graph; subclasses name
    their `CHANNEL` and may publish state and markers."""

    CHANNEL = ""
    """The server's channel, as its registry record names it."""

    def __init__(self, name: str, config: ServerNodeConfig | None = None, **kwargs) -> None:
        super().__init__(
            name, parameter_overrides=[Parameter("use_sim_time", value=True)], **kwargs,
        )
        self.config = cfg = declare_config(self, ServerNodeConfig, config)
        self.scenario: Scenario = load_scenario(cfg.scenario, cfg.overrides, seed=cfg.seed)
        specs = [s for s in registry.of(self.scenario).servers if s.channel == self.CHANNEL]
        if not specs:
            raise ValueError(f"{self.scenario.controller.behaviour} registers no {self.CHANNEL!r} server")
        self.server: Server = registry.resolve(specs[0].core)(self.scenario)
        self.mailbox = Mailbox()
        self.rejections = Rejections()
        self.inbound = Inbound(self.scenario.robot_names, self.scenario.dt_ns, self.rejections,
                               self.get_logger().warning)
        self._published_rejections = 0
        """Messages dropped so far, as last published on ``/diagnostics``."""
        self.lost: list[str] = []
        """Robots the world declared dead, not yet told to the core."""
        self._done = -1
        inbound, outbound = registry.server_topics(specs[0])
        self._inbound = [
            self.create_subscription(
                topics.import_type(f.type_name), t,
                lambda data, t=t, f=f: self.inbound.post_all(t, f, data, self.mailbox.post), EVENTS, raw=True,
            )
            for t, f in inbound.items()
        ]
        self._outbound = {t: (f, self.create_publisher(topics.import_type(f.type_name), t, family_qos(f, t)))
                          for t, f in outbound.items()}
        self._topic_of = {cls: t for t, f in outbound.items() for cls, ft in f.topics.items() if ft == t}
        self.create_subscription(topics.type_of(topics.CLOCK), topics.CLOCK, self._on_clock,
                                 SENSOR_LOCKSTEP, raw=True)
        self.create_subscription(topics.type_of(topics.WORLD_EVENTS), topics.WORLD_EVENTS, self._on_world_events,
                                 EVENTS, raw=True)
        self._diagnostics_pub = self.create_publisher(
            topics.type_of(topics.DIAGNOSTICS), topics.DIAGNOSTICS, STATE_LATCHED)
        self._ack_pub = None

    def publish_state(self, stamp_ns: int) -> None:
        """Subclasses publish the core's state and markers after each tick."""

    def wait_for_robots(self, executor) -> None:
        """Spin until every robot's publisher and subscribers are matched, then announce
        readiness by creating the ack publisher."""
        robots = self.scenario.robots.count
        deadline = time.monotonic() + self.config.startup_timeout
        while time.monotonic() < deadline and (
            any(sub.get_publisher_count() < robots for sub in self._inbound)
            or any(pub.get_subscription_count() < robots for _, pub in self._outbound.values())
        ):
            executor.spin_once(timeout_sec=0.1)
        self._ack_pub = self.create_publisher(
            topics.type_of(topics.LOCKSTEP_ACK), topics.LOCKSTEP_ACK, SENSOR_LOCKSTEP
        )

    def _on_world_events(self, data: bytes) -> None:
        try:
            _, events = diagnostics.decode_events(data)
        except ValueError as exc:
            self.inbound.reject(topics.WORLD_EVENTS, Reason.MALFORMED, str(exc)[:200])
            return
        for e in events:
            if isinstance(e, NodeDownEvent) and e.kind == "robot":
                if e.node in self.inbound.robots:
                    self.lost.append(e.node)
                else:
                    self.inbound.reject(topics.WORLD_EVENTS, Reason.UNKNOWN_ROBOT, f"node_down for {e.node[:40]!r}")

    def _on_clock(self, data: bytes) -> None:
        if self._ack_pub is None:
            return
        try:
            stamp = clock_codec.decode_clock(data)
        except ValueError as exc:
            self.inbound.reject(topics.CLOCK, Reason.MALFORMED, str(exc)[:200])
            return
        if stamp > self._done:
            self.inbound.now_ns = self.inbound.released_ns = stamp
            for robot in self.lost:
                if hasattr(self.server, "robot_lost"):
                    self.server.robot_lost(robot, stamp)
                self.get_logger().warning(f"{robot} was declared dead: freed what it held")
            self.lost = []
            out = self.server.step(stamp, self.mailbox.take_before(stamp))
            by_topic: dict[str, list] = defaultdict(list)
            for m in out:
                by_topic[self._topic_of[type(m)]].append(m)
            for topic, messages in by_topic.items():
                family, pub = self._outbound[topic]
                for data in family.encode(stamp, messages):
                    pub.publish(data)
            self.publish_state(stamp)
            core = getattr(self.server, "rejections", None)
            if (dropped := total(self.rejections, core)) != self._published_rejections:
                self._published_rejections = dropped
                self._diagnostics_pub.publish(diagnostics.encode_rejections(
                    stamp, self.get_fully_qualified_name(), merged(self.rejections, core)))
            self._done = stamp
        if stamp == self._done:
            self._ack_pub.publish(ack.encode_ack(self.CHANNEL, stamp))


def parse_args(prog: str, argv: list[str]) -> tuple[ServerNodeConfig, list[str]]:
    parser = argparse.ArgumentParser(prog=prog)
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO)
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--seed", type=int, default=0)
    args, ros_args = parser.parse_known_args(argv)
    return ServerNodeConfig(args.scenario, tuple(args.overrides), args.seed), ros_args


def run_server(node_class: type[ServerNode], prog: str, argv: list[str] | None = None) -> int:
    """A server node's `main`: one node in its own process, spun until shut down."""
    config, ros_args = parse_args(prog, sys.argv[1:] if argv is None else argv)
    rclpy.init(args=[prog, *ros_args])
    node = None
    try:
        node = node_class(config)
        executor = make_executor()
        executor.add_node(node)
        node.wait_for_robots(executor)
        while rclpy.ok():
            executor.spin_once(timeout_sec=0.5)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
