"""Graph lockstep == in-process batch for one seed: identical trajectories and metrics."""

from __future__ import annotations

import numpy as np
import pytest
from graph_helpers import SMALL_ARENA, launch, overrides, run_graph  # noqa: F401 - launch: a fixture

from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.replay import load_odometry
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario

ROBOTS, DURATION, SEED = 8, 30.0, 11

COMPARED = ("resources_delivered", "collision_time_s_by_robot", "contact_time_s_by_robot", "oae_by_robot", "trips_by_robot",
            "clamped_commands", "stale_ticks")


def test_graph_lockstep_equals_batch(tmp_path):
    bag = tmp_path / "graph"
    graph = run_graph(bag, "--robots", str(ROBOTS), "--duration", str(DURATION), "--seed", str(SEED),
                      *overrides(SMALL_ARENA))
    scenario = load_scenario("cpfa", SMALL_ARENA, robots__count=ROBOTS, sim__duration=DURATION, seed=SEED)
    batch = run_batch(scenario, record_poses=True)
    expected = summarize(batch.trace)

    odom = load_odometry(bag)
    assert len(odom) == ROBOTS
    for i, (robot, rows) in enumerate(odom.items()):
        np.testing.assert_array_equal(rows[:, 1:], batch.poses[:, i, :], err_msg=robot)
    for key in COMPARED:
        assert graph[key] == expected[key], key
    assert graph["resources_delivered"] > 0


@pytest.mark.alone  # a hundred DDS processes (test/conftest.py)
def test_graph_with_a_process_per_robot_equals_batch_at_112_robots(tmp_path):
    """Issue 27's scale: 112 robot processes (the CPFA scenario's swarm, its arena), 10 s: every
    odometry sample the bag holds is the batch run's pose, and the metrics agree."""
    robots, duration, seed = 112, 10.0, 5
    bag = tmp_path / "graph"
    graph = run_graph(bag, "--robots", str(robots), "--duration", str(duration), "--seed", str(seed),
                      "--controller-processes", "0")
    scenario = load_scenario("cpfa", robots__count=robots, sim__duration=duration, seed=seed)
    batch = run_batch(scenario, record_poses=True)
    expected = summarize(batch.trace)
    odom = load_odometry(bag)
    assert len(odom) == robots
    for i, (robot, rows) in enumerate(odom.items()):
        np.testing.assert_array_equal(rows[:, 1:], batch.poses[:, i, :], err_msg=robot)
    for key in COMPARED:
        assert graph[key] == expected[key], key
    assert graph["stale_ticks"] == 0 and graph["dead_nodes"] == []


def test_graph_with_publishing_shards_equals_batch(launch):
    """``--publish-shards 2``: the observations go out through two shard processes fed by shared
    memory, and the bag's trajectories are still the batch run's; the shards are the run's own
    publishers (not tainted, exit 0) and gone with the run (no check that waits for them to be seen
    alive: a short run may end first)."""
    robots, duration, seed = 5, 8.0, 7
    run = launch("--robots", str(robots), "--duration", str(duration), "--seed", str(seed), "--publish-shards", "2",
                 *overrides(SMALL_ARENA))
    code, graph, err = run.finish()
    assert code == 0, err[-3000:]
    assert "Traceback" not in err and graph["foreign_publishers"] == []
    assert run.alive() == []
    scenario = load_scenario("cpfa", SMALL_ARENA, robots__count=robots, sim__duration=duration, seed=seed)
    batch = run_batch(scenario, record_poses=True)
    odom = load_odometry(run.bag)
    assert len(odom) == robots
    for i, (robot, rows) in enumerate(odom.items()):
        np.testing.assert_array_equal(rows[:, 1:], batch.poses[:, i, :], err_msg=robot)
    expected = summarize(batch.trace)
    for key in COMPARED:
        assert graph[key] == expected[key], key
