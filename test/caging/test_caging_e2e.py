"""Caging on the ROS graph: one controller node per robot, the five message types on their
/caging/ topics in the bag in the order the algorithms require, the bag's metrics equal to the
batch run's, and the run over when the object is delivered (the scenario's
``sim.stop_when_finished``), at the batch run's tick (one tick later at worst)."""

from __future__ import annotations

import numpy as np
from graph_helpers import overrides, run_graph

from swarm_controllers.caging.codec import CAGING
from swarm_controllers.caging.metrics import polyline_length
from swarm_controllers.caging.protocol import MESSAGE_TYPES, Oriented, Positioned, Reached, Recruitment, Summon
from swarm_msgs_py.diagnostics import decode_diagnostics
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.replay import load_run
from swarm_sim.batch import run_batch
from swarm_sim.recording import read_bag
from swarm_sim.scenario import load_scenario

SETTINGS = ["arena.size=5.0", "transport.landmarks.extent=[2.0, 2.0]", "robots.count=6", "sim.duration=130"]
SEED = 3
"""Six robots on a 2 x 2 m grid; with this seed the whole protocol is over after ~122 s of sim,
before the 130 s the run may last."""
CAGING_FIELDS = ("search_time_s", "recruitment_time_s", "transport_time_s", "total_time_s", "planned_path_m",
                 "object_path_m", "trajectory_error_m", "trajectory_error_pct", "cage_held",
                 "max_path_deviation_m", "landmarks", "cage_size")


def test_caging_graph_run_records_the_protocol_and_equals_batch(tmp_path):
    bag = tmp_path / "bag"
    graph = run_graph(bag, "--scenario", "caging", "--seed", str(SEED), *overrides(SETTINGS), timeout=600)
    assert graph["stale_ticks"] == 0

    by_topic: dict[str, list] = {}
    for m in read_bag(bag):
        if m.topic.startswith("/caging/type"):
            _, statuses = decode_diagnostics(m.data)
            # what `ros2 topic echo` shows: msg<type, origin, destination, payload> as key/values
            for status in statuses:
                keys = [k for k, _ in status.values]
                assert keys[:4] == ["type", "stamp_ns", "origin", "destination"]
            by_topic.setdefault(m.topic, []).extend(CAGING.decode(m.data))
    assert sorted(by_topic) == sorted(CAGING.topics.values())  # all five types
    for cls in MESSAGE_TYPES:
        assert {type(m) for m in by_topic[CAGING.topics[cls]]} == {cls}
    messages = sorted((m for ms in by_topic.values() for m in ms), key=lambda m: m.stamp_ns)
    first = {cls: min(m.stamp_ns for m in messages if isinstance(m, cls)) for cls in MESSAGE_TYPES}
    assert first[Recruitment] < first[Summon] < first[Positioned] < first[Oriented] < first[Reached]
    recruiter = messages[0].origin
    assert all(m.origin == recruiter for m in messages if isinstance(m, (Recruitment, Summon)))
    summoned = [m.destination for m in messages if isinstance(m, Summon)]
    assert len(summoned) == 5 and recruiter not in summoned
    final = max(m.leg for m in messages if isinstance(m, Reached))
    assert isinstance(messages[-1], Reached) and messages[-1].leg == final

    trace = load_run(bag)
    assert set(trace.series) >= {"object", "robots"}
    batch = summarize(run_batch(load_scenario("caging", SETTINGS, seed=SEED)).trace)
    bagged = summarize(trace)
    for key in CAGING_FIELDS:
        assert graph[key] == bagged[key] == batch[key], key
    assert batch["transport_time_s"] is not None and batch["cage_held"] is True and batch["object_delivered"]
    # the run ended when the object was delivered, on the graph as in batch, and the bag says why
    assert batch["run_ended"] == graph["run_ended"] == bagged["run_ended"] == "finished"
    assert batch["sim_seconds"] < 130.0 and 0 <= graph["sim_seconds"] - batch["sim_seconds"] <= 0.1 + 1e-9
    assert graph["total_time_s"] <= graph["sim_seconds"] <= graph["total_time_s"] + 0.3
    assert polyline_length(np.array([v for _, v in trace.series["object"]])) > 0.5  # it was carried
