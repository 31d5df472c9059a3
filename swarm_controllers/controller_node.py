"""A controller node: one robot's behaviour under the robot's namespace.

The node caches the tick's observation messages (odometry, scan and the world task's sense
topics, `swarm_msgs_py.sensing`) by stamp; when all of them carry the same stamp it builds the
`Observation`, hands it the messages
from other nodes stamped earlier (see `swarm_sim.messaging`), steps the behaviour, publishes
the behaviour's outgoing messages, its status when it changed, and finally the command stamped
with the tick it answers. The tick drives all work; there are no timers.

``swarm-controllers --robots robot_0 robot_1 ...`` hosts several such nodes in one process.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from dataclasses import dataclass

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter

from swarm_controllers.api import Behaviour, behaviour_rng
from swarm_msgs_py import diagnostics, odometry, scan, topics, twist
from swarm_msgs_py.executor import make_executor
from swarm_msgs_py.params import declare_config
from swarm_msgs_py.qos import EVENTS, SENSOR_LOCKSTEP, family_qos
from swarm_msgs_py.records import post_all
from swarm_sim import registry
from swarm_sim.messaging import Mailbox
from swarm_sim.scenario import DEFAULT_SCENARIO, load_scenario
from swarm_sim.types import Observation, robot_index


@dataclass(frozen=True)
class ControllerConfig:
    scenario: str = DEFAULT_SCENARIO
    """Scenario name or YAML path (the same one the world loads)."""
    overrides: tuple[str, ...] = ()
    seed: int = 0


class ControllerNode(Node):
    def __init__(self, robot: str, config: ControllerConfig | None = None, **kwargs) -> None:
        robot_index(robot)  # refuse names that are not robot ids
        super().__init__(
            "controller", namespace=robot, start_parameter_services=False, enable_rosout=False,
            parameter_overrides=[Parameter("use_sim_time", value=True)], **kwargs,
        )
        self.robot = robot
        self.config = cfg = declare_config(self, ControllerConfig, config)
        self.scenario = load_scenario(cfg.scenario, cfg.overrides, seed=cfg.seed)
        self.behaviour: Behaviour = registry.make_behaviour(self.scenario, robot, behaviour_rng(cfg.seed, robot))
        algorithm = registry.of(self.scenario)
        self.sensing = registry.resolve(registry.task(algorithm.task).sensing)
        self.mailbox = Mailbox()
        self._latest: dict[str, tuple[int, object]] = {}
        self._last_status: tuple | None = None
        self._answered_stamp = -1
        self._answer = b""
        decoders = {
            topics.ODOM: (topics.ROBOT_TOPIC_TYPES[topics.ODOM], odometry.decode_odometry),
            topics.SCAN: (topics.ROBOT_TOPIC_TYPES[topics.SCAN], scan.decode_scan),
            **{t.name: (t.type_name, t.decode) for t in self.sensing.topics},
        }
        self._expected = len(decoders)
        # Subscribe to other nodes' messages first: in a wait set where both are ready,
        # rclpy runs the earlier subscription first.
        inbound, outbound = registry.robot_topics(algorithm)
        for topic, family in inbound.items():
            self.create_subscription(
                topics.import_type(family.type_name), topic,
                lambda data, f=family: post_all(f, data, self.mailbox.post, self.get_logger().warning),
                EVENTS, raw=True,
            )
        self._outbound = {t: (f, self.create_publisher(topics.import_type(f.type_name), t, family_qos(f, t)))
                          for t, f in outbound.items()}
        self._topic_of = {cls: t for t, f in outbound.items() for cls, ft in f.topics.items() if ft == t}
        """Message class -> the topic this robot sends it on."""
        for name, (type_name, decode) in decoders.items():
            self.create_subscription(
                topics.import_type(type_name), name,
                lambda data, n=name, d=decode: self._on_observation(n, d(data)), SENSOR_LOCKSTEP, raw=True,
            )
        self._cmd_pub = self.create_publisher(topics.type_of(topics.CMD_VEL), topics.CMD_VEL, SENSOR_LOCKSTEP)
        self._status_pub = self.create_publisher(topics.type_of(topics.STATUS), topics.STATUS, EVENTS)

    def _on_observation(self, name: str, decoded: tuple) -> None:
        stamp = decoded[0]
        if stamp == self._answered_stamp:  # the world re-sent a tick: our answer was late or lost
            self._cmd_pub.publish(self._answer)
            return
        self._latest[name] = decoded
        if len(self._latest) == self._expected and all(v[0] == stamp for v in self._latest.values()):
            self._tick(stamp)

    def _tick(self, stamp_ns: int) -> None:
        _, pose, v, w = self._latest[topics.ODOM]
        sensed = self.sensing.sense(**{t.field: self._latest[t.name][1] for t in self.sensing.topics})
        obs = Observation(
            robot=self.robot, stamp_ns=stamp_ns, pose=pose, linear_velocity=v, angular_velocity=w,
            ranges=self._latest[topics.SCAN][1], sensed=sensed, messages=self.mailbox.take_before(stamp_ns),
        )
        command = self.behaviour.step(obs)
        by_topic: dict[str, list] = defaultdict(list)
        for message in command.messages:
            topic = self._topic_of.get(type(message))
            if topic is None:
                raise TypeError(f"{self.robot}: this algorithm sends no {type(message).__name__}")
            by_topic[topic].append(message)
        for topic, messages in by_topic.items():
            family, pub = self._outbound[topic]
            for data in family.encode(stamp_ns, messages):
                pub.publish(data)
        status = self.behaviour.status(stamp_ns)
        key = (status.state, status.obstacle_avoidance_events, status.trips, status.extra)
        if key != self._last_status:
            self._last_status = key
            self._status_pub.publish(diagnostics.encode_status(status))
        self._answer = twist.encode_twist(self.robot, stamp_ns, command.linear, command.angular)
        self._answered_stamp = stamp_ns
        self._cmd_pub.publish(self._answer)


def parse_args(argv: list[str]) -> tuple[list[str], ControllerConfig, list[str]]:
    parser = argparse.ArgumentParser(prog="swarm-controllers", description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", required=True, help="robot ids, e.g. robot_0 robot_1")
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO)
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--seed", type=int, default=0)
    args, ros_args = parser.parse_known_args(argv)
    return args.robots, ControllerConfig(args.scenario, tuple(args.overrides), args.seed), ros_args


def main(argv: list[str] | None = None) -> int:
    robots, config, ros_args = parse_args(sys.argv[1:] if argv is None else argv)
    rclpy.init(args=["swarm-controllers", *ros_args])
    nodes: list[ControllerNode] = []
    try:
        executor = make_executor()
        for robot in robots:
            nodes.append(ControllerNode(robot, config))
            executor.add_node(nodes[-1])
        # spin_once in a loop: the EventsExecutor's spin() does not dispatch in this rclpy build.
        while rclpy.ok():
            executor.spin_once(timeout_sec=0.5)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        for node in nodes:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
