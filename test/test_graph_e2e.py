"""End-to-end: the real graph (world node + controller nodes over DDS) records a bag whose
contents we check: topics, message counts, deliveries; once with all controllers in one
process and once with one process per robot."""

from __future__ import annotations

import pytest

from graph_helpers import SMALL_ARENA, overrides, run_graph
from swarm_msgs_py import topics
from swarm_sim.bag import bag_info, read_bag
from swarm_sim.analysis import load_run

ROBOTS = 8
DURATION = 40.0
TICKS = 400


@pytest.mark.parametrize("processes", [1, 0], ids=["one-process", "process-per-robot"])
def test_graph_run_records_a_complete_bag(tmp_path, processes):
    bag = tmp_path / "run"
    summary = run_graph(
        bag, "--robots", str(ROBOTS), "--duration", str(DURATION), "--seed", "3",
        "--controller-processes", str(processes), *overrides(SMALL_ARENA),
    )
    assert summary["robots"] == ROBOTS and summary["sim_seconds"] == DURATION
    assert summary["stale_ticks"] == 0, summary
    assert summary["resources_delivered"] > 0, summary

    info = bag_info(bag)
    assert not info.truncated
    counts = info.message_counts
    assert counts[topics.CLOCK] == TICKS + 1
    for i in range(ROBOTS):
        for name in ("odom", "scan", "resources", "gripper"):
            assert counts[f"/robot_{i}/{name}"] == TICKS + 1, name
        assert counts[f"/robot_{i}/cmd_vel"] == TICKS
        assert counts[f"/robot_{i}/status"] >= 1
    assert counts[topics.WORLD_ROBOT_STATS] >= DURATION
    assert topics.WORLD_MARKERS in counts

    # the bag alone gives the same numbers the run reported
    trace = load_run(bag)
    assert len(trace.drops) == summary["resources_delivered"]
    assert {d.zone for d in trace.drops} == {"depot"}
    stamps = [m.stamp_ns for m in read_bag(bag) if m.topic == "/robot_0/cmd_vel"]
    assert stamps == sorted(stamps)
