"""End-to-end: the real graph (world node + controller nodes over DDS) records a bag whose
contents we check: topics, message counts, deliveries; once with all controllers in one
process and once with one process per robot."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from graph_helpers import SMALL_ARENA, overrides, run_graph

from swarm_msgs_py import topics
from swarm_sim.analysis.replay import load_run
from swarm_sim.recording import bag_info, read_bag

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
    assert not info.truncated and len(info.files) == 1  # one file per run, as ros2 bag record
    counts = info.message_counts
    assert counts[topics.CLOCK] == TICKS + 1
    for i in range(ROBOTS):
        for name in ("odom", "scan", "sense"):
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


def test_realtime_mode_runs_near_its_target_factor(tmp_path):
    summary = run_graph(tmp_path / "rt", "--robots", "4", "--duration", "10", "--mode", "realtime",
                        "--real-time-factor", "4", *overrides(SMALL_ARENA))
    assert summary["mode"] == "realtime" and summary["sim_seconds"] == 10.0
    assert 2.0 <= summary["real_time_factor"] <= 4.4, summary


def test_ctrl_c_stops_everything_and_leaves_a_valid_bag(tmp_path):
    bag = tmp_path / "interrupted"
    # Long enough that the run cannot end by itself before the Ctrl-C, even on a loaded machine; paced
    # at 2x real time so that the bag stays small while the test waits (unpaced, 4 robots on a busy
    # machine ran 6680 s of sim, a 27 MB bag, before an unfinished bag's clock could be read).
    cmd = [sys.executable, "-m", "launch_py.run", "--bag", str(bag), "--robots", "4", "--duration", "36000",
           "--real-time-factor", "2", "--domain-id", os.environ["ROS_DOMAIN_ID"], *overrides(SMALL_ARENA)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            cwd=Path(__file__).resolve().parents[1])
    try:
        deadline = time.monotonic() + 120
        while not (bag / "metadata.yaml").exists() or _recorded_clock(bag) < 3.0:
            assert proc.poll() is None and time.monotonic() < deadline, "the run did not start"
            time.sleep(0.5)
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=90)
    finally:
        if proc.poll() is None:  # SIGTERM makes the launcher stop its children too
            proc.terminate()
            try:
                proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
    assert proc.returncode == 130, out  # interrupted: the run is not complete
    info = bag_info(bag)
    assert not info.truncated and info.message_counts["/clock"] > 20
    trace = load_run(bag)
    assert 2.0 <= trace.sim_seconds < 36000 and trace.wall_seconds > 0
    assert "interrupted" in out
    # nothing of the run is left behind
    leftover = subprocess.run(["pgrep", "-f", str(bag)], capture_output=True, text=True).stdout
    assert leftover.strip() == ""


def _recorded_clock(bag) -> float:
    try:
        return bag_info(bag).end_ns / 1e9
    except Exception:
        return 0.0
