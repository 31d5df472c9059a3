"""Who may publish on a run's topics, and the world's watch for anyone else (a foreign publisher).

A run knows its own nodes from the start: the world, one controller per robot (node
``controller`` in the robot's namespace), one node per registered server (`ServerSpec.node_name`),
and with ``--publish-shards K`` the K shards that publish the observations in the world's stead
(`swarm_sim.nodes.publish_shard.shard_node_name`, robots k::K).
`run_topics` lists every topic of the run with its type (from our own types, whatever else a
foreign publisher announces) and the nodes that publish it.

Our own messages carry the run's tag (`swarm_msgs_py.auth`), so on those topics a foreign
publisher's messages are refused and counted where they arrive. Observations, commands, ``/clock``
and the task's state topics are standard types that cannot carry a tag: there only the graph can
tell. `ForeignWatch` asks it (the world is the discovery server and sees every endpoint of the
run): a publisher on a run's topic whose node is none of the topic's publishers, or one more than
the topic has, is foreign. The world looks every wall second (every node that is none of the run's, by name; the
counts of commands, acks, the robots' messages and ``/clock``; the observation and state topics'
counts a few at a time, within `SWEEP_BUDGET`) and reports each at once (an error line, a ``foreign publisher``
count on ``/diagnostics``) and the run is *tainted* (``foreign_publishers`` in the bag's metadata
and the summary, `swarm-run` exit 6) when the topic carries no tag or the run has no key: what it
sent may have reached a core. The run goes on to its end either way, so its bag holds everything.

rclpy (Jazzy) hands a subscription no publisher GID with a message, so a message cannot be
traced to its publisher; the graph names publishers (node, namespace, GID) but learns a node's
name a little after its endpoints (``_NODE_NAME_UNKNOWN_`` meanwhile): such a publisher is
judged by the count alone until its name is known.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from swarm_msgs_py import auth, topics
from swarm_msgs_py.topics import CLOCK
from swarm_sim import registry
from swarm_sim.nodes.publish_shard import shard_node_name
from swarm_sim.outputs import MARKER_ARRAY, outputs_of
from swarm_sim.scenario import Scenario

WORLD = ("/", "world")
CONTROLLER = "controller"
UNKNOWN = "_NODE_NAME_UNKNOWN_"
"""The node name the graph gives an endpoint whose node it has not heard of yet."""


@dataclass
class RunTopic:
    type_name: str
    publishers: set[tuple[str, str]] = field(default_factory=set)
    """(namespace, node name) of every node of the run that publishes it."""

    @property
    def tagged(self) -> bool:
        """Whether its messages carry the run's tag (`swarm_msgs_py.auth`)."""
        return self.type_name in auth.SIGNED_TYPES


def run_topics(scenario: Scenario, shards: int = 0) -> dict[str, RunTopic]:
    """Every topic of a run: its type and the run's nodes that publish it (the observations: the
    world, or with `shards` robot i's shard, i mod `shards`)."""
    out: dict[str, RunTopic] = {}

    def add(topic: str, type_name: str, node: tuple[str, str]) -> None:
        out.setdefault(topic, RunTopic(type_name)).publishers.add(node)

    algorithm = registry.of(scenario)
    task = registry.task(algorithm.task)
    add(topics.CLOCK, topics.type_string(topics.CLOCK), WORLD)
    for topic in (topics.WORLD_EVENTS, topics.WORLD_ROBOT_STATS, topics.WORLD_MARKERS, topics.DIAGNOSTICS):
        add(topic, topics.type_string(topic), WORLD)
    for st in registry.resolve(task.state) if task.state else ():
        add(st.topic, st.type_name, WORLD)
    inbound, outbound = registry.robot_topics(algorithm)
    for i, robot in enumerate(scenario.robot_names):
        controller = (f"/{robot}", CONTROLLER)
        observer = ("/", shard_node_name(i % shards)) if shards else WORLD
        for name in topics.OBSERVATIONS:
            add(topics.robot_topic(robot, name), topics.ROBOT_TOPIC_TYPES[name], observer)
        for name in (topics.CMD_VEL, topics.STATUS):
            add(topics.robot_topic(robot, name), topics.ROBOT_TOPIC_TYPES[name], controller)
        add(topics.DIAGNOSTICS, topics.type_string(topics.DIAGNOSTICS), controller)
        for topic, family in outbound.items():
            add(topic, family.type_name, controller)
    for topic, family in registry.peer_topics(algorithm).items():
        add(topics.heard(topic), family.type_name, WORLD)
    for spec in algorithm.servers:
        server = ("/", spec.node_name)
        add(topics.LOCKSTEP_ACK, topics.type_string(topics.LOCKSTEP_ACK), server)
        add(topics.DIAGNOSTICS, topics.type_string(topics.DIAGNOSTICS), server)
        for topic, family in registry.server_topics(spec)[1].items():
            add(topic, family.type_name, server)
        outputs = outputs_of(spec)
        for st in outputs.state:
            add(st.topic, st.type_name, server)
        if outputs.markers is not None:
            add(outputs.markers.topic, MARKER_ARRAY, server)
    return out


@dataclass(frozen=True)
class Foreign:
    """A foreign publisher on a run's topic."""

    topic: str
    node: str
    """Its node's full name as the graph gives it (``?`` while unknown)."""
    gid: str
    tainting: bool
    """Whether what it sends can reach a core (the topic carries no tag, or the run has no key)."""

    def __str__(self) -> str:
        return f"{self.node} on {self.topic}"


def _name(info) -> tuple[str, str]:
    return info.node_namespace, info.node_name


def _full(namespace: str, name: str) -> str:
    return "?" if name == UNKNOWN else f"{namespace.rstrip('/')}/{name}"


SWEEP_BUDGET = 0.005
"""Wall seconds a `ForeignWatch.check` (one a wall second) may spend on the graph's per-topic
queries beyond its node pass: a count or a topic's publisher list walks the whole graph (~35 us in a
112-robot graph, ~0.5 ms with 1000 robots and 16,000 endpoints), so a fixed share of the topics
per check (a fifth, before issue 27) cost the 1000-robot world 0.4 s a wall second, and at
start-up, when every topic's count changes, seconds. Within the budget it judges the topics whose
count changed and counts the next of the others; the rotation through all of them takes ~5 s at 112
robots and minutes at 1000. Foreign nodes are found faster than that by name (`ForeignWatch.check`)."""


class ForeignWatch:
    """The world's check of the graph for foreign publishers on the run's topics (see the module
    docstring). A topic's publishers are looked at only when their count changed since it was
    last counted, or when a node that is none of the run's publishes on it."""

    def __init__(self, scenario: Scenario, publishers_info: Callable[[str], list],
                 count_publishers: Callable[[str], int], node_names: Callable[[], list] = lambda: [],
                 publishers_of_node: Callable[[str, str], list] = lambda name, namespace: [],
                 shards: int = 0) -> None:
        """`node_names()`: (name, namespace) of every node in the graph; `publishers_of_node(name,
        namespace)`: that node's (topic, types) (rclpy's names for both); `shards`: the run's
        publishing shards (`run_topics`)."""
        self.topics = run_topics(scenario, shards)
        self._info = publishers_info
        self._count = count_publishers
        self._node_names = node_names
        self._publishers_of_node = publishers_of_node
        self._ours = set().union(*(t.publishers for t in self.topics.values()))
        self.heard: dict[str, Callable[[], int]] = {}
        """Topic -> the matched publisher count of the world's own subscription to it (`hear`)."""
        self._sweep = [t for t in self.topics]
        self._cursor = 0
        self._counts: dict[str, int] = {}
        self._due: dict[str, None] = {}
        """Topics whose publishers are to be judged (their count changed), oldest first."""
        self._known: set[tuple[str, str]] = set()
        """(topic, GID) of every publisher judged so far (ours and foreign)."""
        self._unnamed: set[str] = set()
        """Topics that had a publisher of a node not named yet: looked at again next time."""
        self._judged: set[tuple[str, str, str]] = set()
        """(namespace, name, topic) of the suspect nodes' publishers judged so far."""
        self.found: list[Foreign] = []

    def hear(self, topic: str, matched: Callable[[], int]) -> None:
        """The world subscribes to `topic`: count its publishers every check from `matched`."""
        if topic in self.topics:
            self.heard[topic] = matched
            self._sweep = [t for t in self._sweep if t != topic]

    def check(self, budget: float = SWEEP_BUDGET) -> list[Foreign]:
        """The foreign publishers that appeared since the last check: every publisher of a node
        that is none of the run's (or that shares the name of one of them), and, within `budget`
        wall seconds, on the topics the world hears whose count changed, on the next of the others,
        and on the topics whose publishers' nodes were not all named yet (``math.inf``: all of
        them, once)."""
        new = self._by_node()
        for topic, matched in self.heard.items():
            self._recount(topic, matched())
        self._recount(CLOCK, self._count(CLOCK))
        for topic in self._unnamed:
            self._due[topic] = None
        self._unnamed = set()
        stop = time.perf_counter() + budget  # past it, one more of each (so each check moves on)
        judged = 0
        while self._due and (not judged or time.perf_counter() < stop):
            topic = next(iter(self._due))
            del self._due[topic]
            new += self._judge(topic, self.topics[topic])
            judged += 1
        n = len(self._sweep)
        for k in range(n):
            if k and time.perf_counter() >= stop:
                break
            topic = self._sweep[self._cursor]
            self._cursor = (self._cursor + 1) % n
            if self._recount(topic, self._count(topic)):
                del self._due[topic]
                new += self._judge(topic, self.topics[topic])
        self.found += new
        return new

    def _recount(self, topic: str, count: int) -> bool:
        """Note `topic`'s publisher count; True (and the topic due to be judged) if it changed to
        a non-zero count."""
        if count == self._counts.get(topic):
            return False
        self._counts[topic] = count
        if count:
            self._due[topic] = None
        return bool(count)

    def _by_node(self) -> list[Foreign]:
        """Publishers on the run's topics of nodes that are none of the run's, or that bear the
        name of one of the run's nodes twice: one node list, then a publisher list per such node
        (few), every check."""
        names = [(namespace, name) for name, namespace in self._node_names()]
        seen: set[tuple[str, str]] = set()
        suspects = []
        for node in names:
            if node not in self._ours or node in seen:
                suspects.append(node)
            seen.add(node)
        new: list[Foreign] = []
        for namespace, name in dict.fromkeys(suspects):
            try:
                published = self._publishers_of_node(name, namespace)
            except Exception:  # noqa: BLE001 - the node left between the two queries
                continue
            for topic, _ in published:
                if topic in self.topics and (namespace, name, topic) not in self._judged:
                    self._judged.add((namespace, name, topic))
                    self._due.pop(topic, None)
                    new += self._judge(topic, self.topics[topic])
        return new

    def _judge(self, topic: str, spec: RunTopic) -> list[Foreign]:
        infos = self._info(topic)
        if any(i.node_name == UNKNOWN for i in infos):
            self._unnamed.add(topic)
        ours = [i for i in infos if _name(i) in spec.publishers]
        strangers = [i for i in infos if _name(i) not in spec.publishers and i.node_name != UNKNOWN]
        surplus = len(infos) - len(spec.publishers)
        if surplus > len(strangers):  # more publishers than the run has, beyond those named strangers:
            seen: set[tuple[str, str]] = set()  # a second publisher under one of our names, or unnamed
            for i in ours + [i for i in infos if i.node_name == UNKNOWN]:
                if _name(i) in seen or i.node_name == UNKNOWN:
                    strangers.append(i)
                seen.add(_name(i))
        tainting = not spec.tagged or auth.key() is None
        out = []
        for i in strangers:
            gid = bytes(i.endpoint_gid).hex()
            if (topic, gid) in self._known:
                continue
            self._known.add((topic, gid))
            out.append(Foreign(topic, _full(i.node_namespace, i.node_name), gid, tainting))
        return out

    def ready(self, topic: str) -> set[str]:
        """The run's node names publishing `topic` now (the world starts when every server's
        node has its ack publisher: counting publishers let a foreign one stand in)."""
        return {name for ns, name in map(_name, self._info(topic)) if (ns, name) in self.topics[topic].publishers}
