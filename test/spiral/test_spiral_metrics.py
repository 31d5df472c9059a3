"""The MDBSA paper's per-minute foraging rate (Figs. 7 and 9) from a run's deliveries."""

from __future__ import annotations

from types import SimpleNamespace

from swarm_controllers.spiral.metrics import resources_per_robot_per_min
from swarm_msgs_py.types import NS_PER_S, DropEvent
from swarm_sim.analysis.metrics import summarize
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario


def trace(drop_times_s, seconds=180.0, robots=4):
    drops = [DropEvent("robot_0", round(t * NS_PER_S), k, "depot", 0.0, 0.0) for k, t in enumerate(drop_times_s)]
    return SimpleNamespace(sim_seconds=seconds, robots=tuple(f"robot_{k}" for k in range(robots)), drops=drops)


def test_whole_minutes_per_robot_a_drop_at_the_minute_counts_in_the_minute_it_ends():
    t = trace([0.1, 59.9, 60.0, 60.1, 119.0, 150.0, 180.0])
    assert resources_per_robot_per_min(t) == [[60.0, 0.75], [120.0, 0.5], [180.0, 0.5]]


def test_a_last_partial_minute_is_dropped_as_the_authors_do():
    assert resources_per_robot_per_min(trace([10.0, 130.0], seconds=150.0)) == [[60.0, 0.25], [120.0, 0.0]]
    assert resources_per_robot_per_min(trace([10.0], seconds=59.9)) == []
    assert resources_per_robot_per_min(trace([], robots=0)) == []


def test_registered_for_the_spiral_algorithms_and_sums_to_the_run():
    s = load_scenario("mdbsa_d", ["robots.count=4", "sim.duration=120"])
    summary = summarize(run_batch(s).trace)
    series = summary["resources_per_robot_per_min"]
    assert [t for t, _ in series] == [60.0, 120.0]
    assert sum(v for _, v in series) * 4 == summary["resources_delivered"]
    other = summarize(run_batch(load_scenario("cpfa", ["robots.count=2", "sim.duration=1"])).trace)
    assert "resources_per_robot_per_min" not in other  # a row carries its own paper's fields only
