"""A stand-in for a stock ``ros2 topic echo TOPIC`` (ros2cli is not installed here): what it does,
with plain rclpy, in a process whose environment a user's ``ros2`` would get from
``python -m launch_py.hosts env`` (docs/across_hosts.md).

``echo.py TOPIC COUNT TIMEOUT``: like ``ros2 topic echo``, learn the topic's type from the ROS
graph (which needs the discovery server's super-client view), match the publishers' reliability,
print COUNT messages as ``ros2 topic echo`` does (the fields, then ``---``), then one JSON line:
the type, the publishers' nodes and the messages' stamps. Gives up after TIMEOUT wall seconds.
"""

from __future__ import annotations

import json
import sys
import time


def _fields(msg: object, indent: str = "") -> list[str]:
    lines = []
    for name in msg.get_fields_and_field_types():
        value = getattr(msg, name)
        if hasattr(value, "get_fields_and_field_types"):
            lines += [f"{indent}{name}:", *_fields(value, indent + "  ")]
        else:
            lines.append(f"{indent}{name}: {value!r}")
    return lines


def main(topic: str, count: int, timeout: float) -> int:
    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    from swarm_msgs_py.topics import import_type

    rclpy.init()
    node = rclpy.create_node("echo_standin", start_parameter_services=False)
    deadline = time.monotonic() + timeout
    found: dict = {}
    publishers: list = []
    while not publishers and time.monotonic() < deadline:  # as a user starts it once the run is up
        rclpy.spin_once(node, timeout_sec=0.2)
        found = dict(node.get_topic_names_and_types())
        publishers = node.get_publishers_info_by_topic(topic) if topic in found else []
    if not publishers:
        print(json.dumps({"error": f"no publisher of {topic} in the graph after {timeout} s", "topics": sorted(found)}), flush=True)
        return 1
    type_name = found[topic][0]
    best_effort = any(p.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT for p in publishers)
    qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT if best_effort else ReliabilityPolicy.RELIABLE)
    stamps: list[int] = []

    def on_message(msg: object) -> None:
        print("\n".join(_fields(msg)) + "\n---", flush=True)
        header = getattr(msg, "header", None)
        stamps.append(header.stamp.sec * 10**9 + header.stamp.nanosec if header is not None else -1)

    node.create_subscription(import_type(type_name), topic, on_message, qos)
    while len(stamps) < count and time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.2)
    # The publishers' node names come with the ROS graph's own announcements, which can trail
    # the endpoints (as `ros2 topic info -v` shows them unknown until then).
    while any(p.node_name == "_NODE_NAME_UNKNOWN_" for p in publishers) and time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.2)
        publishers = node.get_publishers_info_by_topic(topic) or publishers
    print(json.dumps({"type": type_name, "stamps": stamps,
                      "publishers": sorted(f"{p.node_namespace.rstrip('/')}/{p.node_name}" for p in publishers)}),
          flush=True)
    return 0 if len(stamps) >= count else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], int(sys.argv[2]), float(sys.argv[3])))
