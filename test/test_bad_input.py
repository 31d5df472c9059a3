"""Bad input from outside (issue 25, item 5): each gets one line naming the problem and a non-zero
exit, never a traceback, a hang or a write outside the output directory.

The command-line cases run the real entry points in subprocesses, bounded by a timeout (a hang
fails the test instead of stalling it); all but one are refused before a node starts.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from swarm_msgs_py import clock, diagnostics
from swarm_msgs_py.types import DropEvent
from swarm_sim.recording import BagWriter
from swarm_sim.scenario import load_scenario, scenario_to_dict

REPO = Path(__file__).resolve().parents[1]
HUGE = "9" * 5000
"""More digits than Python converts to an int (4300): int() raises a ValueError of its own."""


def run(module: str, *args: str, cwd: Path, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd, env={**os.environ, "PYTHONPATH": os.pathsep.join(
                              [str(REPO), os.environ.get("PYTHONPATH", "")])})


def assert_one_line(result: subprocess.CompletedProcess, code: int, *needles: str) -> None:
    """Exit `code`, no traceback, and the error is one line holding every needle."""
    assert result.returncode == code, (result.returncode, result.stdout[-2000:], result.stderr[-2000:])
    assert "Traceback" not in result.stderr and "Traceback" not in result.stdout, result.stderr[-3000:]
    lines = [line for line in result.stderr.splitlines() if any(n in line for n in needles)]
    assert lines and all(n in lines[0] for n in needles), result.stderr[-2000:]


def scenario_file(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(f"controller:\n  behaviour: cpfa\n{text}")
    return path


@pytest.mark.parametrize("module", ["swarm_sim.batch", "launch_py.run"])
def test_an_integer_of_5000_digits_in_a_scenario_or_a_flag(tmp_path, module):
    path = scenario_file(tmp_path, "big", f"seed: {HUGE}\n")
    assert_one_line(run(module, "--scenario", str(path), "--duration", "1", cwd=tmp_path), 2, "big.yaml",
                    "an integer of more than 4300 digits")
    assert_one_line(run(module, "--duration", "1", "--set", f"robots.count={HUGE}", cwd=tmp_path), 2,
                    "--set robots.count", "an integer of more than 4300 digits")


def test_an_integer_of_5000_digits_in_a_comparison_flag(tmp_path):
    result = run("swarm_sim.compare.cli", "queue", "--seeds", "1", "--duration", "1", "--out", str(tmp_path / "q"),
                 "--set", f"robots.count={HUGE}", cwd=tmp_path)
    assert_one_line(result, 2, "--set robots.count", "an integer of more than 4300 digits")


@pytest.mark.parametrize("text, named", [
    ("seed: " + "1" * 60 + "\n", "seed: expected an integer within"),
    ("robots:\n  max_linear_speed: 1e300\n", "robots.max_linear_speed"),
    ("robots:\n  max_linear_speed: 1000.0\n", "robots.max_linear_speed: must be positive and at most"),
    ("name: ../../x\n", "name: '../../x' is not a plain name"),
])
def test_numbers_no_run_can_hold_and_names_that_are_paths_are_refused(tmp_path, text, named):
    path = scenario_file(tmp_path, "odd", text)
    assert_one_line(run("swarm_sim.batch", "--scenario", str(path), "--duration", "1", cwd=tmp_path), 2, named)


def test_a_scenario_name_never_puts_the_bag_outside_out(tmp_path):
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    path = scenario_file(work, "escape", "name: ../../x\n")
    result = run("launch_py.run", "--scenario", str(path), "--duration", "1", "--out", str(work / "bags"), cwd=work)
    assert_one_line(result, 2, "is not a plain name")
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a", "b", "escape.yaml"]  # nothing written


@pytest.mark.parametrize("args, named", [
    (["--out", "/proc/x"], "cannot record to /proc/x/"),
    (["--bag", "/etc/hostname/x"], "/etc/hostname is not a directory"),
    (["--robots", "300", "--controller-processes", "0"], "make 301 DDS processes"),
])
def test_swarm_run_refuses_what_it_cannot_do_before_starting_anything(tmp_path, args, named):
    result = run("launch_py.run", "--duration", "1", *args, cwd=tmp_path)
    assert_one_line(result, 2, named)
    assert "[world]" not in result.stdout


def test_resume_on_a_results_file_that_is_not_ours(tmp_path):
    out = tmp_path / "q"
    out.mkdir()
    (out / "results.jsonl").write_bytes(b'\xff\xfe{"strategy": 1}\n')
    result = run("swarm_sim.compare.cli", "queue", "--seeds", "1", "--duration", "1", "--out", str(out),
                 "--resume", "--strategies", "queue_cpfa", cwd=tmp_path)
    assert_one_line(result, 2, "results.jsonl is not UTF-8 text")
    assert (out / "results.jsonl").read_bytes() == b'\xff\xfe{"strategy": 1}\n'  # nothing appended


def run_bag(path: Path, deliveries: int = 10) -> Path:
    """A small swarm-run-like bag: the scenario, ten deliveries at 1 s intervals, the clock."""
    scenario = load_scenario("cpfa", ["robots.count=2", "sim.duration=10"])
    meta = {"scenario": json.dumps(scenario_to_dict(scenario)), "sim_seconds": "10.0", "ended": "complete"}
    with BagWriter(path, metadata=meta, flush_seconds=1e-9) as w:  # a chunk per poll
        w.add_topic("/clock", "rosgraph_msgs/msg/Clock")
        w.add_topic("/world/events", "diagnostic_msgs/msg/DiagnosticArray")
        for k in range(deliveries):
            stamp = (k + 1) * 10**9
            w.write("/clock", stamp, clock.encode_clock(stamp))
            w.write("/world/events", stamp, diagnostics.encode_events(stamp, [
                DropEvent("robot_1", stamp, k, "depot", 0.1, 0.0)]))
            w.poll()
    return path


def test_a_fifo_as_metadata_yaml_is_refused_not_waited_on(tmp_path):
    bag = run_bag(tmp_path / "bag")
    (bag / "metadata.yaml").unlink()
    os.mkfifo(bag / "metadata.yaml")
    result = run("swarm_sim.analysis.cli", str(bag), "--no-plot", cwd=tmp_path, timeout=60)
    assert_one_line(result, 1, "metadata.yaml: not a regular file")


@pytest.mark.parametrize("damage", ["empty", "half"])
def test_a_bag_that_lost_data_never_analyses_as_complete(tmp_path, damage):
    bag = run_bag(tmp_path / "bag")
    for f in bag.glob("*.mcap"):
        size = f.stat().st_size
        os.truncate(f, 0 if damage == "empty" else size // 3)
    result = run("swarm_sim.analysis.cli", str(bag), "--no-plot", "--json", cwd=tmp_path)
    assert_one_line(result, 1, "the bag lost data", "bag_0.mcap")
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    assert summary["run_ended"] == "incomplete bag" and summary["bag_lost"]
    assert summary["resources_delivered"] < 10


def test_a_taken_discovery_port_is_one_line(tmp_path):
    import socket

    from launch_py import dds

    # reserved while the test lasts: a concurrent `--domain-id auto` run (another xdist worker's,
    # another suite's) cannot take the domain before the squatter binds its port
    domain, reservation = dds.reserve_free_domain()
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as squatter:  # anyone's, not a run's
            squatter.bind(("127.0.0.1", dds.discovery_port(domain)))
            result = run("launch_py.run", "--duration", "1", "--domain-id", str(domain), cwd=tmp_path)
    finally:
        os.close(reservation)
    assert_one_line(result, 2, f"domain {domain} is in use", f"port 127.0.0.1:{dds.discovery_port(domain)} is taken",
                    "--domain-id auto")
    assert "[world]" not in result.stdout


def test_a_scenario_the_world_cannot_build_is_one_line_and_no_bag(tmp_path):
    """Five 8 x 8 clusters cannot be placed in a 7 m arena: the file loads, the world refuses to
    build it. One line from the world (not its traceback), exit 2, no half-made bag. (This one
    starts the nodes: the world finds out only when it places the resources.)"""
    result = run("launch_py.run", "--scenario", "queue_qmt", "--robots", "6", "--duration", "1",
                 "--set", "arena.size=7.0", "--out", str(tmp_path / "bags"), cwd=tmp_path, timeout=180.0)
    assert_one_line(result, 2, "swarm-world: resources.clusters: cannot place 5 non-overlapping groups")
    assert "before recording anything" in result.stderr and "could not read the bag" not in result.stderr
    assert not any((tmp_path / "bags").glob("*/metadata.yaml"))


@pytest.mark.parametrize("args, needle", [
    (("--set", "robots.count=2", "--publish-shards", "5"), "swarm-world: publish_shards: expected 0-2"),
    (("--plain-twist", "robot_0"), "swarm-world: plain_twist: a plain Twist carries no tick"),
], ids=["more_shards_than_robots", "plain_twist_in_lockstep"])
def test_a_hand_started_world_refuses_options_that_cannot_run_in_one_line(tmp_path, args, needle):
    """swarm-world started by hand (swarm-run refuses these before starting anything): one line
    naming the option, exit 2, no traceback."""
    result = run("swarm_sim.nodes.world_node", *args, cwd=tmp_path)
    assert_one_line(result, 2, needle)
