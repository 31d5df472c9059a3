"""Base of the center and depot-manager nodes: a `swarm_sim.protocol.Server` core on the graph.

On each ``/clock`` tick k the node hands the core the messages stamped before k (from its
inbound topic), publishes the core's answers stamped k (one DiagnosticArray per topic), lets
the subclass publish state and markers, and acknowledges tick k on ``/lockstep/ack`` so the
world's lockstep barrier knows the answers are out. A repeated tick (the world re-sends
``/clock`` when an ack is late) is only acknowledged again. This is exactly what the batch
runner does in process, so graph and batch runs agree.

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

from swarm_msgs_py import ack, protocol, topics
from swarm_msgs_py import clock as clock_codec
from swarm_msgs_py.executor import make_executor
from swarm_msgs_py.params import declare_config
from swarm_msgs_py.qos import EVENTS, SENSOR_LOCKSTEP
from swarm_sim.messaging import Mailbox
from swarm_sim.protocol import Server
from swarm_sim.scenario import DEFAULT_SCENARIO, Scenario, load_scenario


@dataclass(frozen=True)
class ServerNodeConfig:
    scenario: str = DEFAULT_SCENARIO
    """Scenario name or YAML path (the same one the world loads)."""
    overrides: tuple[str, ...] = ()
    seed: int = 0
    startup_timeout: float = 60.0
    """Wall seconds to wait for the robots' publishers and subscribers before going on."""


class ServerNode(Node):
    CHANNEL = ""
    INBOUND = ""
    """The topic robots send this server's messages on."""
    OUTBOUND: tuple[str, ...] = ()
    """The topics the server's answers go out on."""

    def __init__(self, name: str, config: ServerNodeConfig | None = None, **kwargs) -> None:
        super().__init__(
            name, start_parameter_services=False,
            parameter_overrides=[Parameter("use_sim_time", value=True)], **kwargs,
        )
        self.config = cfg = declare_config(self, ServerNodeConfig, config)
        self.scenario: Scenario = load_scenario(cfg.scenario, cfg.overrides, seed=cfg.seed)
        self.server: Server = self.make_server(self.scenario)
        self.mailbox = Mailbox()
        self._done = -1
        self._inbound = self.create_subscription(
            topics.type_of(self.INBOUND), self.INBOUND, self._on_message, EVENTS, raw=True
        )
        self._outbound = {t: self.create_publisher(topics.type_of(t), t, EVENTS) for t in self.OUTBOUND}
        self.create_subscription(topics.type_of(topics.CLOCK), topics.CLOCK, self._on_clock,
                                 SENSOR_LOCKSTEP, raw=True)
        self._ack_pub = None

    def make_server(self, scenario: Scenario) -> Server:
        raise NotImplementedError

    def publish_state(self, stamp_ns: int) -> None:
        """Subclasses publish the core's state and markers after each tick."""

    def wait_for_robots(self, executor) -> None:
        """Spin until every robot's publisher and subscribers are matched, then announce
        readiness by creating the ack publisher."""
        robots = self.scenario.robots.count
        deadline = time.monotonic() + self.config.startup_timeout
        while time.monotonic() < deadline and (
            self._inbound.get_publisher_count() < robots
            or any(p.get_subscription_count() < robots for p in self._outbound.values())
        ):
            executor.spin_once(timeout_sec=0.1)
        self._ack_pub = self.create_publisher(
            topics.type_of(topics.LOCKSTEP_ACK), topics.LOCKSTEP_ACK, SENSOR_LOCKSTEP
        )

    def _on_message(self, data: bytes) -> None:
        protocol.post_all(data, self.mailbox.post, self.get_logger().warning)

    def _on_clock(self, data: bytes) -> None:
        if self._ack_pub is None:
            return
        stamp = clock_codec.decode_clock(data)
        if stamp > self._done:
            out = self.server.step(stamp, self.mailbox.take_before(stamp))
            by_topic: dict[str, list] = defaultdict(list)
            for m in out:
                by_topic[protocol.topic_of(m)].append(m)
            for topic, messages in by_topic.items():
                self._outbound[topic].publish(protocol.encode_messages(stamp, messages))
            self.publish_state(stamp)
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
