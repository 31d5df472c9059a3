"""The graph across hosts (issue 26): network namespaces stand in for the machines (`netns`).

Host ``world`` runs swarm-run bound to its address (the world, its discovery server, any
servers), ``hosta`` and ``hostb`` the controllers (even and odd robots) from the commands swarm-run
prints, ``cli`` a stand-in for a stock ``ros2 topic echo``. Every test checks, while the run goes,
that each host's sockets are bound to that host's address only. Skipped without root.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from multihost import PAPERS, REPO, MultiHostRun, batch_differences, flags, node_env, protocol_messages, robots_of
from netns import Testbed, available, leftovers

from launch_py.dds import reserve_free_domain

from swarm_sim.analysis.replay import load_odometry

LOSSY = {"loss": 0.05, "delay": 0.020, "jitter": 0.010}
"""Both controller hosts' links, both ways: 5 % loss, 20 +- 10 ms delay (`netns.Testbed.netem`)."""


@pytest.fixture
def testbed(request):
    """The four hosts; ``@pytest.mark.parametrize("testbed", [True], indirect=True)``: shaped links."""
    why = available()
    if why is not None:
        pytest.skip(f"no network namespaces here: {why}")
    bed = Testbed(("world", "hosta", "hostb", "cli"), shaped=getattr(request, "param", False))
    try:
        yield bed
    finally:
        bed.close()
        assert leftovers() == []


shaped = pytest.mark.parametrize("testbed", [True], indirect=True, ids=["shaped"])
LEAVE_WITHIN = 5.0
"""Wall seconds within which every remote process has left after its run's end."""


def assert_left_with_the_run(run: MultiHostRun, ended: float) -> None:
    """Every controller host's process left by itself, exit 0, by the time swarm-run ended
    (`ended`, monotonic) or `LEAVE_WITHIN` seconds after, saying that the run completed."""
    for host, (code, after, line) in run.wait_controllers(ended, LEAVE_WITHIN).items():
        assert code == 0 and after < LEAVE_WITHIN and "the world ended the run (complete)" in line, (host, code, after, line)


def test_lockstep_across_hosts_equals_batch_and_a_ros2_echo_joins(testbed, tmp_path):
    robots, duration, seed = 8, 30.0, 11
    # At most 4x real time (it only adds waits): time for the echo to start and discover, on a busy machine.
    run = MultiHostRun(testbed, tmp_path, robots, *flags(duration, seed), "--tick-timeout", "20",
                       "--real-time-factor", "4")
    echo = run.echo("/robot_1/cmd_vel", 5, 60)  # robot_1's controller is on hostb
    run.wait_sim(duration / 2, 90)
    run.note_sockets()
    graph = run.finish(120)
    assert_left_with_the_run(run, time.monotonic())
    out, _ = echo.communicate(timeout=30)
    heard = json.loads(out.strip().splitlines()[-1])
    assert heard["type"] == "geometry_msgs/msg/TwistStamped", heard
    assert heard["publishers"] == ["/robot_1/controller"]
    assert len(heard["stamps"]) >= 5 and out.count("linear:") >= 5

    assert run.foreign_sockets() == []
    for host in ("world", "hosta", "hostb", "cli"):
        assert run.sockets[host], f"no socket seen on {host}"
    assert graph["run_ended"] == "complete" and graph["stale_ticks"] == 0
    assert set(graph["by_host"]) == {"hosta", "hostb"}
    assert graph["by_host"]["hosta"]["robots"] == 4
    assert batch_differences(run.bag, graph, robots, duration, seed) == []
    assert graph["resources_delivered"] > 0


LOSSY_RUN = {"robots": 8, "duration": 20.0, "seed": 11}
"""Each paper's run over lossy links: at most 1x real time (``--real-time-factor 1``), so that the
four runs, started together, are all under way when hostb is cut off (see `lossy_runs`; at the
cut's end they were at 4.4-5.5 s), and two thirds of each run come after the cut."""


@pytest.fixture(scope="module")
def lossy_runs(tmp_path_factory):
    """Every paper of `PAPERS` over lossy links at once: one shaped testbed, a run per paper on a
    ROS domain of its own, 5 % loss and 20 +- 10 ms delay on both controller hosts' links; once
    every run has recorded 4 s, hostb cut off for 3 s. The runs share the links, the partition and
    the two cores (four runs one after the other took 140 s; together ~50 s). Returns paper ->
    (run, its summary, sim time [s] at the cut's start, at its end, monotonic time it ended),
    the testbed gone (a module-scoped one would still hold its namespaces' names when the
    module's next test makes its own)."""
    why = available()
    if why is not None:
        pytest.skip(f"no network namespaces here: {why}")
    robots, duration, seed = LOSSY_RUN["robots"], LOSSY_RUN["duration"], LOSSY_RUN["seed"]
    reserved = [reserve_free_domain() for _ in list(PAPERS)[1:]]  # the session's domain, and one each more
    domains = [int(os.environ["ROS_DOMAIN_ID"]), *(d for d, _ in reserved)]
    bed = Testbed(("world", "hosta", "hostb", "cli"), shaped=True)
    try:
        for host in robots_of(robots):
            bed.netem(host, **LOSSY)
        runs = {paper: MultiHostRun(bed, tmp_path_factory.mktemp(paper), robots, *flags(duration, seed, *scenario),
                                    "--tick-timeout", "20", "--resend-period", "0.1", "--real-time-factor", "1",
                                    domain=domain)
                for (paper, scenario), domain in zip(PAPERS.items(), domains)}
        for run in runs.values():
            run.wait_sim(4.0, 240)
        before = {paper: run.sim_time() for paper, run in runs.items()}
        cut = threading.Thread(target=bed.partition, args=("hostb", 3.0))
        cut.start()
        while cut.is_alive():
            for run in runs.values():
                run.note_sockets()
            cut.join(0.5)
        after = {paper: run.sim_time() for paper, run in runs.items()}
        out = {}
        for paper, run in runs.items():
            graph = run.finish(240)
            out[paper] = (run, graph, before[paper], after[paper], time.monotonic())
        # The controllers leave by themselves (or not) before the testbed goes: it would kill them.
        deadline = max(ended for *_, ended in out.values()) + LEAVE_WITHIN
        while time.monotonic() < deadline and any(len(r.left) < len(r.controllers) for r in runs.values()):
            time.sleep(0.05)
    finally:  # the testbed goes before the tests: the next tests of the module make their own
        bed.close()
        for _, reservation in reserved:
            os.close(reservation)
    assert leftovers() == []
    return out


@pytest.mark.slow  # four runs of 20 s over 20 ms links, together: ~50 s
@pytest.mark.xdist_group("lossy")  # one worker makes the runs (`lossy_runs`) for all
@pytest.mark.parametrize("paper", list(PAPERS))
def test_lossy_links_lockstep_equals_batch(lossy_runs, paper):
    """5 % loss and 20 +- 10 ms delay on both controller hosts' links, and hostb cut off for 3 s
    mid-run, with each paper's server (MDBSA-D's center, the depot manager, DRTM's nest) or peer
    messages (caging) and its protocol: the barrier re-sends unanswered ticks and every node
    waits for its reliable messages to be acknowledged before answering a tick, so the run is
    the batch run of its seed."""
    run, graph, cut_at, cut_end, ended = lossy_runs[paper]
    robots, duration, seed = LOSSY_RUN["robots"], LOSSY_RUN["duration"], LOSSY_RUN["seed"]
    assert 4.0 <= cut_at and cut_end < duration, (cut_at, cut_end)  # the cut fell inside the run
    assert_left_with_the_run(run, ended)
    assert run.foreign_sockets() == []
    assert graph["run_ended"] == "complete" and graph["stale_ticks"] == 0
    assert graph["by_host"]["hostb"]["resent"] > 0  # the loss and the partition were felt ...
    assert batch_differences(run.bag, graph, robots, duration, seed, *PAPERS[paper]) == []  # ... and recovered from
    assert protocol_messages(run.bag, PAPERS[paper][0]) > 0  # the protocol went across the links


@pytest.mark.slow  # 14 s of sim at 1x real time, and the hosts' set-up
@shaped
def test_realtime_partition_stops_the_cut_off_robots(testbed, tmp_path):
    """Realtime at 1x over lossy links, hostb cut off for 3 s: its robots are stopped once their
    newest command is older than sim.command_timeout (0.5 s), hosta's drive on, the run completes,
    and the summary counts per host."""
    robots, duration, timeout = 8, 14.0, 0.5
    for host in robots_of(robots):
        testbed.netem(host, **LOSSY)
    run = MultiHostRun(testbed, tmp_path, robots, *flags(duration, 3), "--mode", "realtime",
                       "--real-time-factor", "1", "--set", f"sim.command_timeout={timeout}")
    run.wait_sim(5.0, 120)
    testbed.partition("hostb", 3.0)
    graph = run.finish(120)
    assert_left_with_the_run(run, time.monotonic())
    assert run.foreign_sockets() == []
    assert graph["run_ended"] == "complete" and graph["mode"] == "realtime"
    cut, kept = robots_of(robots)["hostb"], robots_of(robots)["hosta"]
    commands = graph["commands_by_robot"]
    odom = load_odometry(run.bag)
    dt = 0.1
    for robot in cut:
        stops = [(last / 1e9, at / 1e9, (end if end >= 0 else duration * 1e9) / 1e9)
                 for last, at, end in commands[robot]["stops"]]
        assert all(at - last <= timeout + dt + 1e-9 for last, at, _ in stops), stops  # stopped in time
        last, at, end = max(stops, key=lambda s: s[2] - s[1])  # the partition's stop
        assert end - at >= 3.0 - timeout - 1.0, stops  # a 3 s cut, less the timeout and the links' delay
        # The world really stood it still: its odometry does not move from the tick after the stop
        # until it drives again.
        rows = odom[robot]
        still = rows[(rows[:, 0] > at + 1e-9) & (rows[:, 0] < end - 1e-9)]
        assert len(still) >= 10 and np.allclose(np.diff(still[:, 1:], axis=0), 0.0, atol=1e-6), (robot, still)
    assert graph["by_host"]["hostb"]["stopped"] >= len(cut)
    assert sum(commands[r]["stopped_ticks"] for r in kept) < sum(commands[r]["stopped_ticks"] for r in cut)


WORLD_TIMEOUT = 4.0
"""The end tests' ``--world-timeout``: a remote process leaves once the world was silent this long."""


@shaped
def test_cut_off_longer_than_the_timeout_then_ctrl_c_every_remote_process_leaves(testbed, tmp_path):
    """hostb cut off longer than ``--world-timeout``: its controllers leave (world vanished, 5)
    within the timeout and a beat; then Ctrl-C on the world's host: hosta's leave (interrupted,
    130) within a few seconds."""
    robots = 4
    run = MultiHostRun(testbed, tmp_path, robots, *flags(600.0, 2), "--tick-timeout", "1", "--real-time-factor",
                       "4", "--world-timeout", f"{WORLD_TIMEOUT:g}")
    run.wait_sim(2.0, 90)
    cut = time.monotonic()
    testbed.netem("hostb", loss=1.0)
    try:
        while "hostb" not in run.left:
            assert time.monotonic() - cut < WORLD_TIMEOUT + LEAVE_WITHIN, "hostb's controllers outlived their world"
            time.sleep(0.1)
    finally:
        testbed.netem("hostb")
    assert run.launcher.poll() is None and "hosta" not in run.left  # the run goes on without hostb's robots
    stop = time.monotonic()
    os.kill(run.launcher.pid, signal.SIGINT)  # Ctrl-C in the world host's terminal
    left = run.wait_controllers(stop, LEAVE_WITHIN)
    code, vanished, line = left["hostb"]
    assert code == 5 and "the world vanished" in line, left
    assert WORLD_TIMEOUT - 1.0 < vanished + (stop - cut) < WORLD_TIMEOUT + LEAVE_WITHIN, left  # from the cut
    code, after, line = left["hosta"]
    assert code == 130 and after < LEAVE_WITHIN and "interrupted" in line, left
    assert run.launcher.wait(60) == 130
    print(f"\n[end times] cut off {WORLD_TIMEOUT:g} s timeout: hostb left {vanished + stop - cut:.1f} s after the cut; "
          f"Ctrl-C: hosta left {after:.1f} s after it")


def test_a_killed_world_its_remote_processes_leave_within_the_timeout(testbed, tmp_path):
    run = MultiHostRun(testbed, tmp_path, 4, *flags(600.0, 2), "--real-time-factor", "4",
                       "--world-timeout", f"{WORLD_TIMEOUT:g}")
    run.wait_sim(2.0, 90)
    killed = time.monotonic()
    os.kill(run.world_pid(), signal.SIGKILL)
    left = run.wait_controllers(killed, WORLD_TIMEOUT + LEAVE_WITHIN)
    for host, (code, after, line) in left.items():
        assert code == 5 and WORLD_TIMEOUT - 1.0 < after < WORLD_TIMEOUT + LEAVE_WITHIN, (host, left)
        assert "the world vanished: not heard for" in line, (host, line)
    assert run.launcher.wait(60) == 5
    print(f"\n[end times] world SIGKILL, {WORLD_TIMEOUT:g} s timeout: "
          + ", ".join(f"{h} left {a:.1f} s after" for h, (_, a, _) in left.items()))


def test_a_bind_on_a_link_without_carrier_is_refused_in_one_line(testbed):
    """hosta's switch port down (its eth0 up, no carrier): ``--bind`` there gets one line naming the
    interface, not the traceback of a participant Fast DDS cannot create; with the port up again
    the address is accepted."""
    subprocess.run(["ip", "-n", testbed.switch, "link", "set", "hosta", "down"], check=True, timeout=20)
    probe = [sys.executable, "-c", "from launch_py import hosts; print(hosts.bind_address('eth0'))"]
    run = [sys.executable, "-m", "launch_py.run", "--bind", "eth0", "--duration", "1"]
    try:
        done = testbed.popen("hosta", run, env=node_env(), cwd=REPO, stderr=subprocess.PIPE, text=True)
        _, err = done.communicate(timeout=60)
        assert done.returncode == 2 and err.strip().splitlines() == [
            "swarm-run: --bind eth0: interface eth0 is not running (down, or no carrier): DDS cannot bind its "
            "address until the link is up"], err
    finally:
        subprocess.run(["ip", "-n", testbed.switch, "link", "set", "hosta", "up"], check=True, timeout=20)
    deadline = time.monotonic() + 30
    while True:  # the kernel reports the carrier a moment later
        try:
            assert testbed.run("hosta", probe, timeout=60).strip() == testbed.address["hosta"]
            break
        except RuntimeError:
            assert time.monotonic() < deadline, "hosta's link not running 30 s after its port came up"
            time.sleep(0.1)
