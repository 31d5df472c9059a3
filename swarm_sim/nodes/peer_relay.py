"""The world's relay of what robots send each other, like a radio medium.

Robots never match each other directly (N relays, not N x N matches): each robot publishes its
peer families' messages (`swarm_sim.registry.peer_topics`) on their topics, and the world
republishes them on ``heard(topic)``, which every robot hears. A message is checked
(`swarm_sim.inbound`: within the size cap, tagged by this run, decodable, naming robots of this
run, coordinates within the arena, stamped for a tick the world can take), recorded as sent (on
the topic's refused channel if it failed, `swarm_msgs_py.topics.refused`) and relayed just before the next tick's observations. Lockstep order makes this
exact: a robot publishes its messages of tick k before its command k, so they are here before
the barrier lets tick k+1 out, and they leave before its observations, from the same sender, in
order.
"""

from __future__ import annotations

from rclpy.node import Node

from swarm_msgs_py import auth, topics
from swarm_sim import registry
from swarm_sim.inbound import Inbound
from swarm_sim.nodes.endpoint import ack_wait, wait_acked
from swarm_sim.nodes.qos import EVENTS
from swarm_sim.nodes.world_recording import WorldRecording


class PeerRelay:
    def __init__(self, node: Node, algorithm: registry.Algorithm, inbound: Inbound, recording: WorldRecording) -> None:
        self._inbound = inbound
        self._recording = recording
        self._relays = {}
        """Peer topic -> publisher on ``heard(topic)``."""
        self._relayed: list[tuple[str, bytes]] = []
        """What arrived since the last tick went out, in order."""
        self.ack_wait = ack_wait() if node.config.mode == "lockstep" else 0.0
        """Lockstep: wall seconds `flush` waits for the robots to acknowledge what it relayed."""
        self.subscriptions = {}
        """Peer topic -> the world's subscription to it."""
        for topic, family in registry.peer_topics(algorithm).items():
            msg_type = topics.import_type(family.type_name)
            recording.add(topic, family.type_name)
            recording.skip(topics.heard(topic))  # the relay's copies: recorded once, as sent
            self._relays[topic] = node.create_publisher(msg_type, topics.heard(topic), EVENTS)
            self.subscriptions[topic] = node.create_subscription(
                msg_type, topic, lambda data, t=topic, f=family: self._on_peer(t, f, data), EVENTS, raw=True)

    def _on_peer(self, topic: str, family, data: bytes) -> None:
        taken = self._take(topic, family, data)
        self._recording.write_taken(topic, data, taken)
        if taken:
            self._relayed.append((topic, data))

    def _take(self, topic: str, family, data: bytes) -> bool:
        messages = self._inbound.decode(topic, auth.verified(family.decode), data, self._inbound.bounds.message_bytes)
        return messages is not None and all([self._inbound.admit(topic, m) for m in messages])  # a list: all counted

    def flush(self, *, send: bool = True) -> None:
        """Relay what robots sent at the last tick (`send=False`: drop it, the run is over)."""
        if send:
            for topic, data in self._relayed:
                self._relays[topic].publish(data)
            if self._relayed:  # across lossy links: heard by every robot before the tick (`endpoint.wait_acked`)
                wait_acked({self._relays[t] for t, _ in self._relayed}, self.ack_wait)
        self._relayed = []
