"""The shared topic names and their ROS types (each paper's protocol topics are in its codecs).

Robot topics are relative names (``odom``) so that a controller node started in namespace
``/robot_3`` resolves them to ``/robot_3/odom`` and remapping works; nodes that serve every
robot (the world, the recorder) use `robot_topic`. Global topics are absolute.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable
from typing import Any

from swarm_msgs_py.types import RobotId

# Relative names under a robot's namespace.
ODOM = "odom"
SCAN = "scan"
SENSE = "sense"
CMD_VEL = "cmd_vel"
STATUS = "status"
OBSERVATIONS = (ODOM, SCAN, SENSE)
"""Every tick the world publishes these to each robot: odometry, the scan and its task's sense
(every field of it in one message, `swarm_msgs_py.sensing`); a controller steps once it has all of
them stamped with the same tick."""

# Absolute names.
CLOCK = "/clock"
WORLD_EVENTS = "/world/events"
WORLD_ROBOT_STATS = "/world/robot_stats"
WORLD_MARKERS = "/world/markers"
DIAGNOSTICS = "/diagnostics"
"""Every node's rejected-message counts (`swarm_sim.inbound`), one status per node, on change."""
LOCKSTEP_ACK = "/lockstep/ack"
"""Servers answer each lockstep tick here: header.stamp = the tick, header.frame_id = the
server's channel (`swarm_sim.registry.ServerSpec.channel`)."""

ROBOT_TOPIC_TYPES: dict[str, str] = {
    ODOM: "nav_msgs/msg/Odometry",
    SCAN: "sensor_msgs/msg/LaserScan",
    SENSE: "diagnostic_msgs/msg/DiagnosticArray",
    CMD_VEL: "geometry_msgs/msg/TwistStamped",
    STATUS: "diagnostic_msgs/msg/DiagnosticArray",
}
"""Relative robot topic -> ROS type string."""

GLOBAL_TOPIC_TYPES: dict[str, str] = {
    CLOCK: "rosgraph_msgs/msg/Clock",
    WORLD_EVENTS: "diagnostic_msgs/msg/DiagnosticArray",
    WORLD_ROBOT_STATS: "diagnostic_msgs/msg/DiagnosticArray",
    WORLD_MARKERS: "visualization_msgs/msg/MarkerArray",
    LOCKSTEP_ACK: "std_msgs/msg/Header",
    DIAGNOSTICS: "diagnostic_msgs/msg/DiagnosticArray",
}
"""Absolute topic -> ROS type string."""


def type_string(topic: str) -> str:
    """ROS type string of a relative robot topic (``odom``), an absolute global topic
    (``/clock``) or an absolute robot topic (``/robot_3/odom``); ValueError if unknown."""
    if topic in ROBOT_TOPIC_TYPES:
        return ROBOT_TOPIC_TYPES[topic]
    return topic_type(topic)


def import_type(type_name: str) -> Any | None:
    """``"nav_msgs/msg/Odometry"`` -> the rclpy message class, None if it is not installed.

    Imports on call, so this module stays importable without ROS.
    """
    package, _, name = type_name.replace("/msg/", "/").partition("/")
    try:
        return getattr(importlib.import_module(f"{package}.msg"), name)
    except (ImportError, AttributeError):
        return None


def type_of(topic: str) -> Any:
    """The rclpy message class to create a publisher or (raw) subscription for `topic`."""
    type_name = type_string(topic)
    cls = import_type(type_name)
    if cls is None:
        raise ImportError(f"{topic}: message type {type_name} is not installed")
    return cls


def type_name(msg_class: Any) -> str:
    """rclpy message class -> ``"pkg/msg/Name"`` (what rosbag2 metadata wants)."""
    package = msg_class.__module__.split(".")[0]
    return f"{package}/msg/{msg_class.__name__}"


HEARD = "heard"


def heard(topic: str) -> str:
    """Where robots hear what other robots send on `topic` (``/nest/pheromones`` ->
    ``/nest/pheromones/heard``): the world relays robot-to-robot messages like a radio medium
    (`swarm_sim.nodes.world_node`), so each robot matches one relay instead of every other robot."""
    return f"{topic}/{HEARD}"


REFUSED = "refused"


def refused(topic: str) -> str:
    """The bag channel of the messages the run refused on `topic` (``/robot_1/cmd_vel`` ->
    ``/robot_1/cmd_vel/refused``): recorded as they came, apart, so analysis reads what the nodes
    took (a suffix: no reader that picks topics by their last name takes it for the topic)."""
    return f"{topic}/{REFUSED}"


def robot_topic(robot: RobotId, name: str) -> str:
    """``robot_topic("robot_3", ODOM)`` -> ``"/robot_3/odom"`` (any relative name)."""
    if not name or "/" in name:
        raise ValueError(f"robot topic {name!r}: expected a relative name such as {ODOM!r}")
    return f"/{robot}/{name}"


def split_robot_topic(topic: str) -> tuple[RobotId, str] | None:
    """``"/robot_3/odom"`` -> ``("robot_3", "odom")``; None for anything else."""
    parts = topic.split("/")
    if len(parts) == 3 and parts[0] == "" and parts[1] and parts[2] in ROBOT_TOPIC_TYPES:
        return parts[1], parts[2]
    return None


def topic_type(topic: str) -> str:
    """ROS type string of an absolute topic name; ValueError naming it if unknown."""
    if topic in GLOBAL_TOPIC_TYPES:
        return GLOBAL_TOPIC_TYPES[topic]
    split = split_robot_topic(topic)
    if split is None:
        raise ValueError(f"unknown topic {topic!r}")
    return ROBOT_TOPIC_TYPES[split[1]]


def all_topics(robots: Iterable[RobotId]) -> dict[str, str]:
    """Every topic of a run with `robots` -> its ROS type (what the recorder subscribes)."""
    out = dict(GLOBAL_TOPIC_TYPES)
    for robot in robots:
        for name, type_name in ROBOT_TOPIC_TYPES.items():
            out[robot_topic(robot, name)] = type_name
    return out
