"""The run's recorder, inside the world node: the world's own bytes plus every other topic.

Like ``ros2 bag record -a``: the world writes what it publishes (and the commands and acks it
receives) as the very bytes on the wire, and `discover` subscribes to every topic other nodes
publish, recording each message stamped with the sim time at which it arrives. A run's topic is
recorded with the run's own type (and that type's hash in metadata.yaml), whatever a foreign
publisher announces; what the run refuses goes to the topic's refused channel
(`swarm_msgs_py.topics.refused`), so analysis reads only what the run took. Latched topics
(servers' state and markers) are subscribed transient-local, so their last message is recorded
even if it was published before the recorder subscribed. With a `LiveView` every topic and
message also goes to the Foxglove clients, as the same bytes.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Collection, Mapping
from pathlib import Path

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy

from swarm_msgs_py import topics
from swarm_sim.nodes.live_view import LiveView
from swarm_sim.nodes.qos import EVENTS, RECORD_LATCHED, published_depth, rosbag2_profile
from swarm_sim.recording import BagWriter

_ROBOT_NAMESPACE = re.compile(r"^/robot_\d+/")


class Recorder:
    """Records into one bag directory (None: no bag) and feeds `live` (None: no live view);
    `now_ns` gives the sim time to stamp messages with."""

    def __init__(self, node: Node, path: Path | None, metadata: dict[str, str], now_ns: Callable[[], int],
                 live: LiveView | None = None, types: Mapping[str, str] | None = None,
                 accept: Callable[[str, bytes], bool | None] | None = None) -> None:
        """`types`: the run's topics' own types, recorded whatever type a foreign publisher on
        one announces; `accept(topic, data)`: whether a discovered topic's message is the run's
        (False: recorded on the topic's refused channel, `swarm_msgs_py.topics.refused`; None:
        not recorded)."""
        self._node = node
        self._types = dict(types or {})
        self._accept = accept
        self._recorded_types: dict[str, str] = {}
        self._now_ns = now_ns
        self.bag = BagWriter(path, metadata=metadata) if path is not None else None
        self.live = live
        self.known: set[str] = set()
        """Topics recorded already (by the world itself or by discovery)."""
        self.skipped: set[str] = set()
        """Topics discovery leaves out (the world's relay of robots' messages: copies of topics
        recorded already)."""
        self._latched: set[str] = set()
        self._offered: set[str] = set()
        """Topics whose offered QoS a publisher of theirs has reported (`_offer`)."""
        self._heard: set[str] = set()
        """Discovered topics a message has arrived on."""
        self._own: dict[str, list[str]] = {}
        """Family (`_ROBOT_NAMESPACE`) -> the topics the world writes itself whose offered QoS no
        publisher has reported yet (a robot's commands: its controller publishes them)."""
        self._asked = 0
        self.closed = False

    def add(self, topic: str, type_name: str, latched: bool = False) -> None:
        """A topic the world writes itself."""
        self.known.add(topic)
        self._add(topic, type_name, latched)
        self._own.setdefault(_ROBOT_NAMESPACE.sub("/robot_*/", topic, count=1), []).append(topic)

    def _offer_own(self) -> None:
        """The offered QoS of the topics the world writes itself, once a publisher of theirs is up
        (asked again at the run's end, when it may have left): one question per family and call,
        of its members in turn, so a robot that never connects holds up nothing and 1000 robots
        cost one question a family."""
        if self.bag is None:
            return
        self._asked += 1
        for family, members in list(self._own.items()):
            infos = self._node.get_publishers_info_by_topic(members[self._asked % len(members)])
            for topic in members:  # the same code made every member's publisher: the same QoS
                self._offer(topic, infos)
            if members[0] in self._offered:
                del self._own[family]

    def _add(self, topic: str, type_name: str, latched: bool) -> None:
        self._recorded_types[topic] = type_name
        if latched:
            self._latched.add(topic)
        if self.bag is not None:
            self.bag.add_topic(topic, type_name, "latched" if latched else "reliable")
        if self.live is not None:
            self.live.add(topic, type_name, latched)

    def write_refused(self, topic: str, data: bytes) -> None:
        """A message the run refused on `topic`, on its refused channel (same type)."""
        channel = topics.refused(topic)
        if channel not in self._recorded_types:
            self._add(channel, self._recorded_types.get(topic) or self._types.get(topic, ""), False)
        self.write(channel, data)

    def _discovered(self, topic: str, data: bytes) -> None:
        if topic not in self._heard:  # its first message: a publisher is there to ask now (once:
            self._heard.add(topic)  # a flood of a foreign type must not walk the graph per message)
            if topic not in self._offered:
                self._offer(topic, self._node.get_publishers_info_by_topic(topic))
        verdict = True if self._accept is None else self._accept(topic, data)
        if verdict:
            self.write(topic, data)
        elif verdict is not None:  # None: not to be recorded at all
            self.write_refused(topic, data)

    def write(self, topic: str, data: bytes) -> None:
        now = self._now_ns()
        if self.bag is not None:
            self.bag.write(topic, now, data)
        if self.live is not None:
            self.live.write(topic, now, data)

    def write_all(self, items: list[tuple[str, bytes]]) -> None:
        """`write` for many (topic, data), stamped alike."""
        now = self._now_ns()
        if self.bag is not None:
            self.bag.write_all(now, items)
        if self.live is not None:
            for topic, data in items:
                self.live.write(topic, now, data)

    def discover(self, on_new: Callable[[str], None] = lambda topic: None) -> None:
        """Subscribe to every topic not recorded yet; `on_new(topic)` is told of each one. Also
        writes the offered QoS of the world's own topics whose publishers have come up."""
        self._offer_own()
        node = self._node
        for topic, types in node.get_topic_names_and_types():
            if topic in self.known or topic in self.skipped or not types:
                continue
            self.known.add(topic)
            on_new(topic)
            type_name = self._types.get(topic, types[0])  # ours, whatever a foreign publisher says
            msg_type = topics.import_type(type_name)
            if msg_type is None:
                continue
            publishers = node.get_publishers_info_by_topic(topic)
            latched = any(info.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for info in publishers)
            self._add(topic, type_name, latched)
            self._offer(topic, publishers)  # while its publishers are there (at the end they may be gone)
            node.create_subscription(
                msg_type, topic, lambda data, t=topic: self._discovered(t, data),
                RECORD_LATCHED if latched else EVENTS, raw=True,
            )

    def _offer(self, topic: str, publishers: list) -> None:
        """Write `topic`'s offered QoS (one profile per publisher, as the graph reports it) and
        type description hash into the bag, as ``ros2 bag record`` does; no publisher of the
        topic's recorded type: what was written before stays. Asked when discovery finds the topic
        (its only endpoint may be a subscriber then), at its first message and at the run's end."""
        recorded = self._recorded_types.get(topic)
        infos = [i for i in publishers if i.topic_type == recorded]  # a foreign type's publisher is not the topic's
        if self.bag is None or not infos:
            return
        self._offered.add(topic)
        depth = published_depth(topic, topic in self._latched)
        profiles = []
        for info in infos:
            profile = rosbag2_profile(info.qos_profile, depth)
            if profile not in profiles:
                profiles.append(profile)
        self.bag.set_offered_qos(topic, profiles, str(infos[0].topic_type_hash))

    def record_offered_qos(self, each: Collection[str] = ()) -> None:
        """`_offer` for every topic, at the run's end: topics whose publishers have left (a
        controller that heard the run's end) keep what discovery wrote, topics the world writes
        itself without one keep the profile they were added with. The robots' topics of one name
        (``/robot_<i>/odom``, ...) have publishers made by the same code with the same QoS, so the
        graph is asked for one of them for all (each question walks the whole graph: with 1000
        robots, asking for each of ~8,000 topics took minutes at the run's end); a topic in `each`
        (one where a foreign publisher was found) is asked for itself."""
        if self.bag is None:
            return
        answers: dict[str, list] = {}
        for topic in sorted(self.known):
            family = topic if topic in each else _ROBOT_NAMESPACE.sub("/robot_*/", topic, count=1)
            try:
                infos = answers.get(family) or self._node.get_publishers_info_by_topic(topic)
            except Exception:  # noqa: BLE001 - the graph is gone (shutdown): keep the defaults
                return
            answers[family] = infos
            self._offer(topic, infos)

    def poll(self) -> None:
        """Flush and split on time (call it while spinning, even when the run is stalled)."""
        if self.bag is not None:
            self.bag.poll()

    def close(self, each: Collection[str] = (), **metadata: str) -> None:
        """Write the run's totals into the metadata and finish the bag (idempotent); `each`: as
        `record_offered_qos`."""
        if not self.closed:
            self.closed = True
            if self.live is not None:
                self.live.close()
            if self.bag is not None:
                self.record_offered_qos(each)
                self.bag.set_metadata(**metadata)
                self.bag.close()
