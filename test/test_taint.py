"""The world's watch for foreign publishers, on a graph of plain data: it finds a foreign node by
name at once, a surplus publisher under one of the run's names within a rotation of the counts,
and keeps to its time budget however big the graph."""

from __future__ import annotations

import math
from collections import defaultdict
from types import SimpleNamespace

from swarm_sim.nodes.taint import ForeignWatch
from swarm_sim.scenario import load_scenario


class Graph:
    """Publishers as (namespace, name, topic, gid); `queries` counts the per-topic walks."""

    def __init__(self) -> None:
        self.publishers: list[tuple[str, str, str, str]] = []
        self.queries = 0

    def add(self, namespace: str, name: str, topic: str) -> None:
        self.publishers.append((namespace, name, topic, f"{len(self.publishers):032x}"))

    def info(self, topic: str) -> list:
        self.queries += 1
        return [SimpleNamespace(node_namespace=ns, node_name=n, endpoint_gid=bytes.fromhex(g))
                for ns, n, t, g in self.publishers if t == topic]

    def count(self, topic: str) -> int:
        self.queries += 1
        return sum(t == topic for *_, t, _ in self.publishers)

    def nodes(self) -> list[tuple[str, str]]:
        return [(n, ns) for ns, n, *_ in self.publishers]  # rclpy's order: (name, namespace)

    def of_node(self, name: str, namespace: str) -> list:
        topics = defaultdict(list)
        for ns, n, t, _ in self.publishers:
            if (ns, n) == (namespace, name):
                topics[t].append("type")
        return list(topics.items())


def run_graph(robots: int, shards: int = 0) -> tuple[Graph, ForeignWatch]:
    scenario = load_scenario("cpfa", robots__count=robots)
    graph = Graph()
    watch = ForeignWatch(scenario, graph.info, graph.count, graph.nodes, graph.of_node, shards)
    for topic, spec in watch.topics.items():
        for namespace, name in spec.publishers:
            graph.add(namespace, name, topic)
    return graph, watch


def test_a_foreign_node_is_found_at_the_next_check_whatever_the_budget():
    graph, watch = run_graph(16)
    assert watch.check(budget=math.inf) == []
    graph.add("/", "hostile", "/robot_3/odom")
    found = watch.check(budget=0.0)
    assert [(f.topic, f.node, f.tainting) for f in found] == [("/robot_3/odom", "/hostile", True)]
    assert watch.check(budget=0.0) == []  # reported once


def test_publishing_shards_are_the_run_s_own_on_their_robots_observations_only():
    graph, watch = run_graph(16, shards=3)
    assert watch.topics["/robot_4/odom"].publishers == {("/", "publish_shard_1")}  # robots k::K
    assert watch.check(budget=math.inf) == []  # every shard publishing its robots' observations
    graph.add("/", "world", "/robot_4/scan")  # the world no longer publishes them
    graph.add("/", "publish_shard_0", "/robot_4/sense")  # nor another shard
    found = watch.check(budget=math.inf)
    assert sorted((f.topic, f.node) for f in found) == [("/robot_4/scan", "/world"),
                                                         ("/robot_4/sense", "/publish_shard_0")]


def test_a_second_publisher_under_a_run_name_is_found_within_a_rotation():
    graph, watch = run_graph(16)
    watch.check(budget=math.inf)
    graph.add("/", "world", "/robot_5/scan")  # our world's name, twice on one topic
    found = []
    for _ in range(len(watch.topics)):  # each check counts at least one topic
        found += watch.check(budget=0.0)
        if found:
            break
    assert [f.topic for f in found] == ["/robot_5/scan"]


def test_a_check_keeps_to_its_budget_a_full_one_covers_every_topic():
    graph, watch = run_graph(112)
    graph.queries = 0
    watch.check(budget=math.inf)
    full = graph.queries
    assert full >= len(watch.topics) - len(watch.heard)
    graph.queries = 0
    watch.check(budget=0.0)
    assert graph.queries <= 3  # /clock, and one swept topic past the budget
