"""The recorder writes each discovered topic's offered QoS while its publishers are there: a
controller that heard the run's end may leave before the world closes the bag (seen under load:
``/robot_0/status`` recorded with the add-time default depth 10 instead of the 1000 it was
published with)."""

from __future__ import annotations

from types import SimpleNamespace

import yaml
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from swarm_sim.nodes.recorder import Recorder

STATUS = ("/robot_0/status", "diagnostic_msgs/msg/DiagnosticArray")
EVENTS_OFFERED = QoSProfile(history=HistoryPolicy.UNKNOWN, depth=0, reliability=ReliabilityPolicy.RELIABLE,
                            durability=DurabilityPolicy.VOLATILE)
"""What the graph reports for a remote publisher: DDS discovery carries no history or depth."""


class FakeGraph:
    """The part of an rclpy node the recorder uses, with publishers that come and go."""

    def __init__(self) -> None:
        self.topics: list[tuple[str, list[str]]] = []
        self.publishers: dict[str, list] = {}
        self.callbacks: dict[str, object] = {}
        self.asked: list[str] = []

    def get_topic_names_and_types(self):
        return list(self.topics)

    def get_publishers_info_by_topic(self, topic):
        self.asked.append(topic)
        return list(self.publishers.get(topic, []))

    def create_subscription(self, msg_type, topic, callback, qos, raw=False):
        self.callbacks[topic] = callback


def publisher(type_name: str) -> SimpleNamespace:
    return SimpleNamespace(topic_type=type_name, qos_profile=EVENTS_OFFERED, topic_type_hash="RIHS01_ab")


def offered(bag) -> dict:
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    return {t["topic_metadata"]["name"]: t["topic_metadata"]["offered_qos_profiles"]
            for t in info["topics_with_message_count"]}


def recorder(tmp_path, graph: FakeGraph) -> Recorder:
    return Recorder(graph, tmp_path / "bag", {}, now_ns=lambda: 0)


def test_a_publisher_gone_at_the_end_keeps_the_profile_discovery_saw(tmp_path):
    graph = FakeGraph()
    graph.topics = [(STATUS[0], [STATUS[1]])]
    graph.publishers[STATUS[0]] = [publisher(STATUS[1])]
    rec = recorder(tmp_path, graph)
    rec.discover()
    graph.publishers.clear()  # the controller left when it heard the run's end
    rec.close()
    (profile,) = offered(tmp_path / "bag")[STATUS[0]]
    assert (profile["reliability"], profile["depth"], profile["history"]) == ("reliable", 1000, "keep_last")


def test_a_topic_found_through_a_subscriber_is_asked_again_at_its_first_message_only(tmp_path):
    """Discovery may list a topic before any publisher of it (its only endpoint the world's own
    subscription): the first message arriving asks the graph, a flood of them does not ask again."""
    graph = FakeGraph()
    graph.topics = [(STATUS[0], [STATUS[1]])]
    rec = recorder(tmp_path, graph)
    rec.discover()
    graph.publishers[STATUS[0]] = [publisher(STATUS[1])]
    for _ in range(50):
        graph.callbacks[STATUS[0]](b"\x00\x01\x00\x00")
    graph.publishers.clear()
    asked = graph.asked.count(STATUS[0])
    rec.close()
    assert asked == 2  # at discovery, at the first message
    (profile,) = offered(tmp_path / "bag")[STATUS[0]]
    assert profile["depth"] == 1000


def test_a_flood_of_a_foreign_type_asks_the_graph_once(tmp_path):
    graph = FakeGraph()
    graph.topics = [(STATUS[0], [STATUS[1]])]
    graph.publishers[STATUS[0]] = [publisher("std_msgs/msg/String")]  # not the run's type
    rec = recorder(tmp_path, graph)
    rec.discover()
    for _ in range(50):
        graph.callbacks[STATUS[0]](b"\x00\x01\x00\x00")
    assert graph.asked.count(STATUS[0]) == 2
    rec.close()


def test_a_topic_the_world_writes_itself_is_offered_once_its_publisher_is_up(tmp_path):
    """A robot's commands, which the world records itself: their offered QoS is asked at each
    discovery until a controller's publisher answers (one question per family), and kept when the
    controllers have left before the end."""
    graph = FakeGraph()
    rec = recorder(tmp_path, graph)
    commands = [f"/robot_{i}/cmd_vel" for i in range(3)]
    for topic in commands:
        rec.add(topic, "geometry_msgs/msg/TwistStamped")
    rec.discover()  # no controller yet
    assert len(graph.asked) == 1
    for topic in commands[1:]:  # robot_0's controller never comes
        graph.publishers[topic] = [SimpleNamespace(topic_type="geometry_msgs/msg/TwistStamped",
                                                   qos_profile=QoSProfile(history=HistoryPolicy.UNKNOWN, depth=0,
                                                                          reliability=ReliabilityPolicy.BEST_EFFORT),
                                                   topic_type_hash="RIHS01_cd")]
    for _ in range(3):
        rec.discover()
    asked = len(graph.asked)
    rec.discover()
    assert len(graph.asked) == asked  # offered: not asked again
    graph.publishers.clear()
    rec.close()
    for topic in commands:
        (profile,) = offered(tmp_path / "bag")[topic]
        assert (profile["reliability"], profile["depth"]) == ("best_effort", 10), topic
