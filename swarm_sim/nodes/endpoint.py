"""A node's end of the message families: what robots and servers share on the graph.

A robot's controller node and a server node both load the scenario from the same config
(`EndpointConfig`), hear some message families' topics and send on others
(`swarm_sim.registry.robot_topics` / `server_topics`). `Endpoint` is that plumbing, once:

- the node's guard (`inbound`, a `swarm_sim.inbound.Inbound` with the run's `Bounds`): every
  subscription of the node, this one's and the node's own (observations, ``/clock``, world
  events), decodes through it;
- one subscription per inbound topic, whose messages are decoded and checked
  (`swarm_sim.inbound.Inbound`: within the size cap, tagged by this run when it has a key
  (`swarm_msgs_py.auth`) and not a copy of one already taken, decodable, naming robots of this
  run, coordinates within the arena, stamped for a tick the node can take) and posted to a `swarm_sim.messaging.Mailbox`; `take(k)` releases those stamped
  before tick k in the fixed delivery order, exactly what the batch runner hands the core;
- one publisher per outbound topic and the topic map (message class -> topic): `send` publishes
  a core's answers of a tick grouped by topic, one encoded batch per topic, tagged;
- `RejectionReport`: the messages dropped, by the node or by its core, on ``/diagnostics``
  whenever the count grew (the world node reports its own drops the same way).

A node creates its `Endpoint` before its other subscriptions: in a wait set where both are
ready, rclpy runs the earlier subscription first.

Across lossy links (``SWARMFORAGE_ACK_WAIT`` set, as `launch_py.hosts` does) a lockstep node waits, after
sending a tick's messages, until every reader has acknowledged them (`wait_acked`) before it
answers the tick: the lockstep barrier re-sends a lost tick or command, but a lost reliable
message comes again only by DDS's retransmission, which could otherwise arrive after the tick
that needs it (measured: MDBSA's center, 5 % loss, the run left the batch run's path).
"""

from __future__ import annotations

import argparse
import os
from collections import defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from rclpy.duration import Duration
from rclpy.node import Node

from swarm_msgs_py import auth, diagnostics, topics
from swarm_sim.inbound import Bounds, Inbound, Rejections, merged, total
from swarm_sim.cli import number
from swarm_sim.messaging import Mailbox
from swarm_sim.nodes.qos import EVENTS, STATE_LATCHED, family_qos
from swarm_sim.nodes.run_watch import WORLD_TIMEOUT
from swarm_sim.scenario import Scenario

ACK_WAIT_ENV = "SWARMFORAGE_ACK_WAIT"
"""Wall seconds a node waits for its reliable messages of a tick to be acknowledged before it
answers the tick (unset or 0: it does not wait; loopback loses nothing). Off by default on one
host: measured A/B, 112 robots, MDBSA-D, 30 s of sim, 3 alternating pairs on the shared 2-core
machine (swarm-run's writers then heartbeat every 10 ms): 16.9 s off, 18.0 s on (+7 %, pairs
+14 / 0 / +7 %), above the 3 % that would make it the default. The limit it cures stays: a
hostile flood that overflows the receivers' socket buffers can delay a reliable message past
its tick (the run then differs from batch, reported); set it to ride such floods out."""


def ack_wait() -> float:
    """`ACK_WAIT_ENV` of this process [s] (0 if unset or not a positive number)."""
    try:
        value = float(os.environ.get(ACK_WAIT_ENV, "0"))
    except ValueError:
        return 0.0
    return value if 0.0 < value < float("inf") else 0.0


def wait_acked(publishers: Iterable[Any], seconds: float) -> bool:
    """Until every reader of `publishers` acknowledged what they sent, `seconds` at most each
    (nothing if `seconds` is 0); False if one timed out."""
    if seconds <= 0.0:
        return True
    timeout = Duration(nanoseconds=int(seconds * 1e9))
    return all([pub.wait_for_all_acked(timeout) for pub in publishers])


@dataclass(frozen=True)
class EndpointConfig:
    """The parameters of a controller or server node (`swarm_sim.nodes.params.declare_config`)."""

    scenario: str = ""
    """Scenario name or YAML path (the same one the world loads; '': the default scenario)."""
    overrides: tuple[str, ...] = ()
    seed: int = 0
    startup_timeout: float = 60.0
    """Wall seconds to wait for the node's peers on its topics to be matched before going on."""
    mode: str = "lockstep"
    """The world's mode (`lockstep` or `realtime`): in lockstep a server takes ``/clock`` ticks
    strictly one after another (`swarm_sim.nodes.server_node`)."""
    world_timeout: float = WORLD_TIMEOUT
    """Wall seconds without a word from the world after which the node's process leaves
    (`swarm_sim.nodes.run_watch`: a liveness guard, not simulation logic)."""


def add_endpoint_arguments(parser: argparse.ArgumentParser) -> None:
    """``--scenario``, ``--set KEY=VALUE`` (repeatable) and ``--seed`` (`endpoint_config`)."""
    parser.add_argument("--scenario", default="", help="scenario name or YAML path (default: the default scenario)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a scenario field (repeatable; the value is YAML)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--mode", choices=("lockstep", "realtime"), default="lockstep",
                        help="lockstep (the world waits for every node each tick) or realtime")
    parser.add_argument("--world-timeout", type=number(float, 0, 86400, open_low=True), default=WORLD_TIMEOUT,
                        metavar="S", help="leave once the world has been silent this many wall seconds (killed, "
                        f"or unreachable that long; default {WORLD_TIMEOUT:g})")


def endpoint_config(args: argparse.Namespace) -> EndpointConfig:
    return EndpointConfig(args.scenario, tuple(args.overrides), args.seed, mode=args.mode,
                          world_timeout=args.world_timeout)


class RejectionReport:
    """A node's messages dropped so far (its own `rejections` and its core's, merged) on
    ``/diagnostics``, latched, published only when the count grew (counts only grow)."""

    def __init__(self, node: Node, rejections: Rejections) -> None:
        self._node = node
        self.rejections = rejections
        self._published = 0
        self._pub = node.create_publisher(topics.type_of(topics.DIAGNOSTICS), topics.DIAGNOSTICS, STATE_LATCHED)

    def publish(self, stamp_ns: int, core: object = None) -> None:
        """`core`: the node's core, whose own ``rejections`` (if any) are merged in."""
        theirs = getattr(core, "rejections", None)
        if (dropped := total(self.rejections, theirs)) != self._published:
            self._published = dropped
            self._pub.publish(auth.sign(diagnostics.encode_rejections(
                stamp_ns, self._node.get_fully_qualified_name(), merged(self.rejections, theirs))))


class Endpoint:
    """A node's family topics (see the module docstring): `inbound` and `outbound` map each
    topic to its message family."""

    def __init__(self, node: Node, scenario: Scenario, inbound: Mapping[str, Any], outbound: Mapping[str, Any]) -> None:
        self._name = node.get_fully_qualified_name()
        self.mailbox = Mailbox()
        self.rejections = Rejections()
        self.inbound = Inbound(scenario.robot_names, scenario.dt_ns, self.rejections, node.get_logger().warning,
                               Bounds.of(scenario))
        """The node's guard: every subscription of the node decodes through it."""
        self.inbound.unique = auth.key() is not None
        self.subscriptions = {
            topic: node.create_subscription(
                topics.import_type(family.type_name), topic,
                lambda data, t=topic, f=family, d=auth.verified(family.decode):
                    self.inbound.post_all(t, f, data, self.mailbox.post, d),
                EVENTS, raw=True,
            )
            for topic, family in inbound.items()
        }
        self.publishers = {t: (f, node.create_publisher(topics.import_type(f.type_name), t, family_qos(f, t)))
                           for t, f in outbound.items()}
        self.topic_of = {cls: t for t, f in outbound.items() for cls, ft in f.topics.items() if ft == t}
        """Message class -> the topic this node sends it on."""
        self.report = RejectionReport(node, self.rejections)
        self.ack_wait = ack_wait() if getattr(node, "config", EndpointConfig()).mode == "lockstep" else 0.0
        """Lockstep: wall seconds `send` waits for its messages to be acknowledged (`ACK_WAIT_ENV`;
        realtime waits for nothing)."""

    def take(self, stamp_ns: int) -> tuple[object, ...]:
        """Tick `stamp_ns` begins: the messages stamped before it, in delivery order."""
        self.inbound.now_ns = self.inbound.released_ns = stamp_ns
        self.inbound.forget_before(stamp_ns - 2 * self.inbound.dt_ns)
        return self.mailbox.take_before(stamp_ns)

    def send(self, stamp_ns: int, messages: Iterable[object]) -> None:
        """A core's messages of tick `stamp_ns`, on the topics of their families."""
        by_topic: dict[str, list] = defaultdict(list)
        for message in messages:
            topic = self.topic_of.get(type(message))
            if topic is None:
                raise TypeError(f"{self._name}: this algorithm sends no {type(message).__name__}")
            by_topic[topic].append(message)
        for topic, group in by_topic.items():
            family, pub = self.publishers[topic]
            for data in family.encode(stamp_ns, group):
                pub.publish(auth.sign(data))
        wait_acked([self.publishers[t][1] for t in by_topic], self.ack_wait)

    def unmatched(self, peers: int) -> list[str]:
        """Topics with fewer than `peers` nodes on their other end (publishers of what this node
        hears, subscribers of what it sends)."""
        missing = [t for t, sub in self.subscriptions.items() if sub.get_publisher_count() < peers]
        return missing + [t for t, (_, pub) in self.publishers.items() if pub.get_subscription_count() < peers]

